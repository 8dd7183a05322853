#!/usr/bin/python3
"""The exact and the multilevel basis as meshes grow (docs/results.md, "Large meshes").

For each mesh, in one run: `specdeform basis` with each eigensolver (wall time and peak memory,
the first 20 eigenvalues against the exact ones) and `specdeform deform` of the mesh's scene with
each, from the file to the written result, no basis cached (wall time, peak memory, the frame's
time, the RMS distance between the two results over the bounding-box diagonal). The Lanczos
baseline joins the basis runs on meshes of at most --lanczos-below vertices.

Usage: scripts/scaling.py OUT_STEM MESH=SCENE [MESH=SCENE ...] [--lanczos-below N]
Writes OUT_STEM.json, OUT_STEM.md and OUT_STEM.svg (time and memory against n).
"""
import argparse
import json
import pathlib
import subprocess
import sys
import tempfile

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
BIN = ROOT / "build" / "bin" / "specdeform"
sys.path.insert(0, str(ROOT / "build" / "python"))
import specdeform  # noqa: E402


def timed(args):
    """Runs the program under GNU time: (stdout, wall seconds, peak resident GB)."""
    with tempfile.NamedTemporaryFile("r") as t:
        out = subprocess.run(["/usr/bin/time", "-f", "%e %M", "-o", t.name, str(BIN), *args],
                             check=True, capture_output=True, text=True).stdout
        seconds, kb = t.read().split()[-2:]
    return out, float(seconds), int(kb) / 2**20


def row(mesh, scene, solvers, work):
    V, _ = specdeform.read_mesh(mesh)
    diagonal = np.linalg.norm(V.max(0) - V.min(0))
    r = {"mesh": pathlib.Path(mesh).name, "vertices": len(V)}
    for s in solvers:
        out, seconds, gb = timed(["basis", mesh, "-m", "100", "--eigensolver", s, "--json"])
        j = json.loads(out)
        r[s] = {"basis_s": seconds, "basis_gb": gb, "eigenvalues": j["eigenvalues"][:20],
                "max_residual": j["max_residual"]}
    for s in ("krylov", "multilevel"):
        result = work / f"{s}.obj"
        out, seconds, gb = timed(["deform", mesh, "--scene", scene, "--eigensolver", s,
                                  "--json", "-o", str(result)])
        j = json.loads(out)
        r[s].update({"deform_s": seconds, "deform_gb": gb, "frame_ms": 1e3 * j["timings"]["frame"]["total"],
                     "setup_s": {k: j["timings"][k] for k in ("basis", "reduced_system",
                                                              "detail_factorization", "selection")}})
        r[s]["result"] = specdeform.read_mesh(result)[0]
    exact, approx = np.array(r["krylov"]["eigenvalues"]), np.array(r["multilevel"]["eigenvalues"])
    r["eigenvalue_error"] = float(np.max(np.abs(approx[1:] / exact[1:] - 1)))
    d = np.linalg.norm(r["krylov"].pop("result") - r["multilevel"].pop("result"), axis=1)
    r["rms_difference"] = float(np.sqrt(np.mean(d**2)) / diagonal)
    return r


def markdown(rows):
    lines = ["| mesh | n | basis exact | basis multilevel | ratio | memory exact | memory multilevel "
             "| eigenvalues 2-20 | deform exact | deform multilevel | ratio | frame (exact, multilevel) "
             "| RMS difference |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        e, m = r["krylov"], r["multilevel"]
        lines.append(
            f"| {r['mesh']} | {r['vertices']:,} | {e['basis_s']:.1f} s | {m['basis_s']:.1f} s "
            f"| {m['basis_s'] / e['basis_s']:.2f} | {e['basis_gb']:.2f} GB | {m['basis_gb']:.2f} GB "
            f"| {100 * r['eigenvalue_error']:.1f}% | {e['deform_s']:.1f} s | {m['deform_s']:.1f} s "
            f"| {m['deform_s'] / e['deform_s']:.2f} | {e['frame_ms']:.0f}, {m['frame_ms']:.0f} ms "
            f"| {100 * r['rms_difference']:.3f}% |")
    lanczos = [r for r in rows if "lanczos" in r]
    if lanczos:
        lines += ["", "| mesh | n | Lanczos basis | exact (block Krylov) | multilevel |", "|---|---|---|---|---|"]
        lines += [f"| {r['mesh']} | {r['vertices']:,} | {r['lanczos']['basis_s']:.1f} s "
                  f"| {r['krylov']['basis_s']:.1f} s | {r['multilevel']['basis_s']:.1f} s |"
                  for r in lanczos]
    return "\n".join(lines) + "\n"


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    n = [r["vertices"] for r in rows]
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    for s, label in (("krylov", "exact"), ("multilevel", "multilevel")):
        a.loglog(n, [r[s]["basis_s"] for r in rows], "o-", label=f"basis, {label}")
        a.loglog(n, [r[s]["deform_s"] for r in rows], "s--", label=f"file to result, {label}")
        b.loglog(n, [r[s]["basis_gb"] for r in rows], "o-", label=f"basis, {label}")
    a.set(xlabel="vertices", ylabel="seconds", title="time (m = 100)")
    b.set(xlabel="vertices", ylabel="GB", title="peak memory of `basis`")
    a.legend(fontsize=8)
    b.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out")
    p.add_argument("meshes", nargs="+", help="MESH=SCENE")
    p.add_argument("--lanczos-below", type=int, default=0)
    a = p.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for item in a.meshes:
            mesh, scene = item.split("=")
            n = len(specdeform.read_mesh(mesh)[0])
            solvers = ["krylov", "multilevel"] + (["lanczos"] if n <= a.lanczos_below else [])
            rows.append(row(mesh, scene, solvers, pathlib.Path(work)))
            print(markdown(rows[-1:]).splitlines()[-1], flush=True)
    out = pathlib.Path(a.out)
    out.with_suffix(".json").write_text(json.dumps(rows, indent=1) + "\n")
    out.with_suffix(".md").write_text(markdown(rows))
    plot(rows, out.with_suffix(".svg"))


if __name__ == "__main__":
    main()
