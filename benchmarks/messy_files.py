"""Messy files through what a user does (docs/results.md, "Messy meshes"): for each file,
`info --json --basis`; an identity scene (the vertices within 0.15 diagonals of the highest one
along the longest axis moved by `translate 0`, the lowest tenth fixed) through `deform` with
default options, --solver spatial, --energy linear, --detail frames and --laplacian
intrinsic-delaunay, each output compared byte for byte with the input; a bend of the same handle
(0.1 and 0.05 diagonals, 30 degrees about z) with default options: its exit code, the handle's
largest distance to its target over the diagonal, its seconds. One markdown row per file.

    PYTHONPATH=build/python /usr/bin/python3 benchmarks/messy_files.py build/bin/specdeform FILE...

tests/files/export_messy.py writes such files with Debian's Blender.
"""

import json
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

import specdeform

OPTIONS = [[], ["--solver", "spatial"], ["--energy", "linear"], ["--detail", "frames"],
           ["--laplacian", "intrinsic-delaunay"]]


def row(cli: str, path: pathlib.Path, work: pathlib.Path) -> str:
    V, F, info = specdeform.read_mesh(path, return_info=True)
    extent = V.max(axis=0) - V.min(axis=0)
    axis = int(np.argmax(extent))
    diagonal = float(np.linalg.norm(extent))
    top = int(np.argmax(V[:, axis]))
    handle = np.flatnonzero(np.linalg.norm(V - V[top], axis=1) <= 0.15 * diagonal)

    def scene(transform, tag):
        out = work / f"{path.name}.{tag}.json"
        out.write_text(json.dumps({
            "handles": [{"around": {"vertex": int(info.vertex_to_file[top]), "radius": 0.15},
                         "transform": transform}],
            "fixed": {"lowest": 0.1, "axis": "xyz"[axis]}}))
        return out

    report = subprocess.run([cli, "info", str(path), "--json", "--basis"], capture_output=True,
                            text=True)
    verdict = json.loads(report.stdout)["deform"]["ok"] if report.returncode == 0 else "exit"
    identity = scene({"translate": [0, 0, 0]}, "identity")
    same = 0
    for options in OPTIONS:
        out = work / ("identity" + path.suffix)
        out.unlink(missing_ok=True)
        run = subprocess.run([cli, "deform", str(path), "--scene", str(identity), "-o", str(out)]
                             + options, capture_output=True)
        same += run.returncode == 0 and out.read_bytes() == path.read_bytes()
    bend = scene({"translate": [0.1 * diagonal, 0.05 * diagonal, 0],
                  "rotate": {"axis": [0, 0, 1], "degrees": 30}}, "bend")
    out = work / ("bend" + path.suffix)
    start = time.perf_counter()
    run = subprocess.run([cli, "deform", str(path), "--scene", str(bend), "-o", str(out)],
                         capture_output=True)
    seconds = time.perf_counter() - start
    miss = float("nan")
    if run.returncode == 0:
        T = specdeform.read_scene(bend, path).transforms[0]
        W, _ = specdeform.read_mesh(out)
        miss = np.abs(W[handle] - (V[handle] @ T[:3, :3].T + T[:3, 3])).max() / diagonal
    return (f"| {path.name} | {len(V)} | {verdict} | {same}/{len(OPTIONS)} | {run.returncode} | "
            f"{miss:.1e} | {seconds:.1f} |")


def main() -> None:
    cli, files = sys.argv[1], [pathlib.Path(f) for f in sys.argv[2:]]
    print("| file | vertices | info --basis: deform ok | identity byte for byte | bend exit | "
          "handle miss | s |\n|---|---:|---|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as work:
        for path in files:
            print(row(cli, path, pathlib.Path(work)), flush=True)


if __name__ == "__main__":
    main()
