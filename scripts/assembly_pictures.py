"""The pictures of docs/results.md, "Assemblies": a ring around a bumpy bar that bends under it
(the bar's end turned by 0.8 rad about z), deformed with the free ring following the bar and kept
in place; each mesh written to OUT and a render job for web/e2e/render.mjs.

    PYTHONPATH=build/python /usr/bin/python3 scripts/assembly_pictures.py OUT PNG_DIR
"""
import json
import sys
from pathlib import Path

import numpy as np

import specdeform


def main(out: Path, pictures: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    Vb, Fb = specdeform.bumpy_bar(cells_per_unit=12)
    Vr, Fr = specdeform.torus(0.8, 0.07, 64, 12)
    Vr = Vr @ np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]], float).T  # axis along x
    Vr[:, 0] += 3.0
    V = np.vstack([Vb, Vr])
    F = np.vstack([Fb, Fr + len(Vb)])
    handle = np.flatnonzero(Vb[:, 0] > 3.6)
    fixed = np.flatnonzero(Vb[:, 0] < 0.4)
    c, s = np.cos(0.8), np.sin(0.8)
    T = np.eye(4)
    T[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
    T[:3, 3] = np.array([4.0, 0, 0]) - T[:3, :3] @ [4.0, 0, 0]
    specdeform.write_mesh(str(out / "ring_input.obj"), V, F)
    jobs = [{"mesh": str(out / "ring_input.obj"), "png": str(pictures / "assembly_ring_input.png"),
             "view": [0.3, -0.5, 1]}]
    for mode in ("follow", "keep"):
        d = specdeform.SpectralDeformer(V, F, 100, unconstrained=mode)
        d.set_selection([handle], fixed)
        X = d.solve([T])
        path = out / f"ring_{mode}.obj"
        specdeform.write_mesh(str(path), X, F)
        jobs.append({"mesh": str(path), "png": str(pictures / f"assembly_ring_{mode}.png"),
                     "view": [0.3, -0.5, 1]})
    (out / "jobs.json").write_text(json.dumps(jobs))


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
