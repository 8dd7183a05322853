"""How the file's normals follow a deformation: follow, recompute and rotate (mesh_file.h),
against the exact answer, on a hard-edged machined part and on a smooth character as Blender
exports them (tests/files/export_assets.py).

The deformation is an analytic bend phi (the long axis curled through 90 degrees), so the
exact normal of every corner is known: a smooth surface's normal n is carried to
J^-T n / |J^-T n|, J the Jacobian of phi at the corner's vertex (central differences). Each mode
writes the bent positions phi(V) with its normals (MeshFile.write); reported per mode: the mean
and largest angle (degrees) between each face corner's written normal and its exact one, over the
corners whose normal row is theirs (used at one position), over those at hard edges (a position
with several normals), and over rows shared by several positions (a deduplicating exporter's:
one row cannot follow corners turned apart; beside it the best a single row can do), and the
largest change of a normal when nothing moved.

    PYTHONPATH=build/python /usr/bin/python3 benchmarks/normals.py ASSETS_DIR [--markdown FILE]

ASSETS_DIR: where tests/files/export_assets.py wrote cad_part.obj/.glb and spot.obj/.glb.
"""

import argparse
import json
import pathlib
import tempfile

import numpy as np

import specdeform


def unit(a):
    return a / np.linalg.norm(a, axis=-1, keepdims=True)


def bend(V):
    """phi: the longest axis curled through 90 degrees about a line beside the shape."""
    lo, hi = V.min(0), V.max(0)
    a = int(np.argmax(hi - lo))
    b = (a + 1) % 3
    length = hi[a] - lo[a]
    radius = length / (np.pi / 2)

    def phi(X):
        t = (X[:, a] - lo[a]) / radius
        r = radius - (X[:, b] - lo[b])
        Y = X.copy()
        Y[:, a] = lo[a] + r * np.sin(t)
        Y[:, b] = lo[b] + radius - r * np.cos(t)
        return Y
    return phi


def exact_normals(phi, P, N, h):
    """J^-T n at each point, J by central differences."""
    J = np.empty((len(P), 3, 3))
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        J[:, :, k] = (phi(P + e) - phi(P - e)) / (2 * h)
    return unit(np.linalg.solve(np.transpose(J, (0, 2, 1)), N[..., None])[..., 0])


def corner_kinds(file, N0):
    """Per corner: at a hard edge (its position has normals more than a degree apart), and on a
    shared normal (one row used at several positions: exporters merge equal normals, Blender's
    OBJ writer on flat and cylindrical parts; one row cannot follow corners turned apart)."""
    position = file.info.file_to_vertex[file.corners]
    rows = file.corner_normal
    normals_at, positions_of = {}, {}
    for p, n in zip(position, rows):
        normals_at.setdefault(p, set()).add(n)
        positions_of.setdefault(n, set()).add(p)
    crease = {p: min((float(N0[a] @ N0[b]) for a in ns for b in ns), default=1.0)
              for p, ns in normals_at.items()}
    hard = np.array([crease[p] < np.cos(np.radians(1)) for p in position])
    shared = np.array([len(positions_of[n]) > 1 for n in rows])
    return hard, shared


def angles(a, b):
    return np.degrees(np.arccos(np.clip(np.sum(unit(a) * unit(b), 1), -1, 1)))


def stats(error):
    return None if error.size == 0 else [float(error.mean()), float(error.max())]


def measure(path: pathlib.Path, work: pathlib.Path):
    V, F, file = specdeform.read_mesh(path, keep=True)
    phi = bend(V)
    rest = file.info.file_vertices
    diagonal = np.linalg.norm(rest.max(0) - rest.min(0))
    with_normal = file.corner_normal >= 0
    corners = file.corners[with_normal]
    rows = file.corner_normal[with_normal]
    N0 = unit(np.array(file.normals))
    truth = exact_normals(phi, rest[corners], N0[rows], 1e-5 * diagonal)
    hard, shared = (k[with_normal] for k in corner_kinds(file, N0))
    # The best one row can do: the mean of its corners' exact normals.
    best = np.zeros_like(N0)
    np.add.at(best, rows, truth)
    floor = angles(best[rows], truth)
    out_rows = []
    for mode in ("follow", "recompute", "rotate"):
        out = work / f"{path.stem}-{mode}{path.suffix}"
        file.write(out, phi(V), normals=mode)
        written = np.array(specdeform.read_mesh(out, keep=True)[2].normals)[rows]
        error = angles(written, truth)
        same = work / f"{path.stem}-{mode}-same{path.suffix}"
        file.write(same, V, normals=mode)
        drift = angles(np.array(specdeform.read_mesh(same, keep=True)[2].normals), N0)
        out_rows.append({"file": path.name, "mode": mode, "corners": int(len(rows)),
                         "own": stats(error[~shared]), "hard": stats(error[hard & ~shared]),
                         "shared": stats(error[shared]), "shared_floor": stats(floor[shared]),
                         "p95": float(np.percentile(error[~shared], 95)) if (~shared).any() else None,
                         "nothing_moved_max": float(drift.max())})
    return out_rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("assets")
    parser.add_argument("--markdown")
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for name in ("cad_part.obj", "cad_part.glb", "spot.obj", "spot.glb"):
            rows += measure(pathlib.Path(args.assets) / name, pathlib.Path(work))
    fmt = lambda s: "-" if s is None else f"{s[0]:.3f}° / {s[1]:.2f}°"
    table = ("| file | normals | corners of their own normal: mean / largest error | 95% | at hard "
             "edges | on shared normals (the best one row can do) | nothing moved: largest "
             "change |\n|---|---|---|---|---|---|---|\n")
    for r in rows:
        p95 = "-" if r["p95"] is None else f"{r['p95']:.2f}°"
        shared = "-" if r["shared"] is None else f"{fmt(r['shared'])} ({fmt(r['shared_floor'])})"
        table += (f"| {r['file']} | {r['mode']} | {fmt(r['own'])} | {p95} | {fmt(r['hard'])} | "
                  f"{shared} | {r['nothing_moved_max']:.4f}° |\n")
    print(json.dumps(rows, indent=1))
    print(table)
    if args.markdown:
        pathlib.Path(args.markdown).write_text(table)


if __name__ == "__main__":
    main()
