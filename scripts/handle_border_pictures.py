"""The pictures of docs/results.md, "Folds at a turning handle": the camelhead's snout (the
benchmarks' handle: 5% of the diagonal around the topmost vertex along the longest axis, the
lowest 10% fixed) turned by 75 degrees about the shortest axis and moved by 0.12 diagonals,
solved by `specdeform compare` (ours, the hard spatial reference, converged SR-ARAP); writes the
scene, the meshes and a render job for web/e2e/render.mjs (whole views, then close-ups).

    PYTHONPATH=build/python /usr/bin/python3 scripts/handle_border_pictures.py MESH OUT PNG_DIR
"""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

import specdeform


def main(mesh: Path, out: Path, pictures: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    V, _ = specdeform.read_mesh(str(mesh))
    extent = V.max(0) - V.min(0)
    axes = np.argsort(-extent)
    diagonal = np.linalg.norm(extent)
    top = int(np.argmax(V[:, axes[0]]))
    handle = np.flatnonzero(np.linalg.norm(V - V[top], axis=1) <= 0.05 * diagonal)
    lowest = np.argsort(V[:, axes[0]])[: len(V) // 10]
    fixed = sorted(set(lowest.tolist()) - set(handle.tolist()))
    move, axis = [0.0] * 3, [0.0] * 3
    move[axes[1]], axis[axes[2]] = 0.12 * diagonal, 1.0
    scene = {"mesh": str(mesh.resolve()), "fixed": fixed, "handles": [{
        "vertices": handle.tolist(),
        "transform": {"rotate": {"axis": axis, "degrees": 75}, "translate": move}}]}
    (out / "scene.json").write_text(json.dumps(scene))
    subprocess.run(["build/bin/specdeform", "compare", "--scene", str(out / "scene.json"), "-o",
                    str(out / "meshes"), "--markdown", str(out / "compare.md")], check=True,
                   stdout=subprocess.DEVNULL)
    meshes = {"input": mesh, "default": out / "meshes/ARAP__spectral.obj",
              "spatial": out / "meshes/linear__all_vertices__hard__eq__14_.obj",
              "srarap": out / "meshes/SR_ARAP__CGAL___converged.obj"}
    X, _ = specdeform.read_mesh(str(meshes["default"]))
    snout = X[handle].mean(0).tolist()
    stem = f"handle_border_{mesh.stem}"
    jobs = [{"mesh": str(m), "png": str(pictures / f"{stem}_{k}.png"), "view": [1, 0.3, 0.6]}
            for k, m in meshes.items()]
    jobs += [{"mesh": str(m), "png": str(pictures / f"{stem}_{k}_close.png"), "view": [1, 0.3, 0.6],
              "zoom": 3.0, "target": snout} for k, m in meshes.items() if k != "input"]
    (out / "jobs.json").write_text(json.dumps(jobs))


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]), Path(sys.argv[3]))
