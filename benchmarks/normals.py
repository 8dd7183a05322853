"""How the file's normals follow a deformation: follow, recompute and rotate (mesh_file.h) on a
hard-edged machined part and on a smooth character, both as Blender exports them
(tests/files/export_assets.py), bent by the same scene as the file tests (tests/python/test_files.py).

For each corner of a face that names a normal, the shading angle is the angle between the normal
and the face's own normal. Written back after the bend, a normal that looks right keeps each
corner's shading angle (a flat side stays flat: 0 before and after; a smooth vertex's normal stays
as far from each face around it as it was). Reported per mode: the mean and the largest change of
the corners' shading angles (degrees), the same over the corners of hard edges only (a normal a
side has alone), and the change of the file's normals with nothing moved.

    PYTHONPATH=build/python /usr/bin/python3 benchmarks/normals.py ASSETS_DIR [--markdown FILE]

ASSETS_DIR: where tests/files/export_assets.py wrote cad_part.obj and spot.obj.
"""

import argparse
import json
import pathlib
import subprocess
import sys
import tempfile

import numpy as np

import specdeform

HERE = pathlib.Path(__file__).resolve().parent


def obj_faces(text):
    """Each face's corners as (v, vn) pairs, 0-based (vn -1: none)."""
    faces, v_count, vn_count = [], 0, 0
    for line in text.split("\n"):
        if line.startswith("v "):
            v_count += 1
        elif line.startswith("vn "):
            vn_count += 1
        elif line.startswith("f "):
            corners = []
            for c in line.split()[1:]:
                parts = c.split("/")
                v = int(parts[0])
                n = int(parts[2]) if len(parts) > 2 and parts[2] else 0
                corners.append((v - 1 if v > 0 else v_count + v,
                                n - 1 if n > 0 else (vn_count + n if n < 0 else -1)))
            faces.append(corners)
    return faces


def numbers(text, key):
    return np.array([[float(x) for x in line.split()[1:4]] for line in text.split("\n")
                     if line.startswith(key + " ")])


def shading_angles(positions, normals, faces):
    """Per corner with a normal: the angle (degrees) between it and its face's normal (Newell)."""
    out = []
    for corners in faces:
        p = positions[[v for v, _ in corners]]
        n = np.cross(p - p.mean(0), np.roll(p, -1, 0) - p.mean(0)).sum(0)
        n /= np.linalg.norm(n)
        for _, k in corners:
            if k >= 0:
                out.append(np.degrees(np.arccos(np.clip(normals[k] @ n, -1, 1))))
    return np.array(out)


def hard_corners(faces, normal_count):
    """Corners whose normal is shared by several positions: the flat sides of hard edges (a
    cap); a smooth vertex has a normal of its own."""
    users = [[] for _ in range(normal_count)]
    for corners in faces:
        for v, k in corners:
            if k >= 0:
                users[k].append(v)
    mask = []
    for corners in faces:
        for v, k in corners:
            if k >= 0:
                mask.append(len(set(users[k])) > 1)  # shared by several positions: a flat side
    return np.array(mask)


def measure(path: pathlib.Path, cli: str, work: pathlib.Path):
    text = path.read_text()
    faces = obj_faces(text)
    rest = numbers(text, "v")
    normals0 = numbers(text, "vn")
    before = shading_angles(rest, normals0, faces)
    hard = hard_corners(faces, len(normals0))
    sys.path.insert(0, str(HERE.parent / "tests" / "python"))
    from test_files import scene_for  # the file tests' bend

    V, F, file = specdeform.read_mesh(path, keep=True)
    scene = scene_for(V, F, file.info, work)
    rows = []
    for mode in ("follow", "recompute", "rotate"):
        out = work / f"{path.stem}-{mode}.obj"
        subprocess.run([cli, "deform", str(path), "--scene", str(scene), "-o", str(out),
                        "--normals", mode], check=True, capture_output=True)
        moved = out.read_text()
        after = shading_angles(numbers(moved, "v"), numbers(moved, "vn"), faces)
        change = np.abs(after - before)
        same = work / f"{path.stem}-{mode}-same.obj"
        file.write(same, V, normals=mode)
        identity = numbers(same.read_text(), "vn")
        drift = np.degrees(np.arccos(np.clip(np.sum(identity * normals0, 1), -1, 1)))
        rows.append({"file": path.name, "mode": mode,
                     "mean_change_deg": float(change.mean()), "max_change_deg": float(change.max()),
                     "flat_sides_max_deg": float(change[hard].max()) if hard.any() else None,
                     "nothing_moved_max_deg": float(drift.max())})
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("assets")
    parser.add_argument("--cli", default=str(HERE.parent / "build" / "bin" / "specdeform"))
    parser.add_argument("--markdown")
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for name in ("cad_part.obj", "spot.obj"):
            rows += measure(pathlib.Path(args.assets) / name, args.cli, pathlib.Path(work))
    table = ("| file | normals | mean change of the shading angle | largest | largest on flat "
             "sides | nothing moved: largest change |\n|---|---|---|---|---|---|\n")
    for r in rows:
        flat = "-" if r["flat_sides_max_deg"] is None else f"{r['flat_sides_max_deg']:.3f}°"
        table += (f"| {r['file']} | {r['mode']} | {r['mean_change_deg']:.3f}° | "
                  f"{r['max_change_deg']:.2f}° | {flat} | {r['nothing_moved_max_deg']:.3f}° |\n")
    print(json.dumps(rows, indent=1))
    print(table)
    if args.markdown:
        pathlib.Path(args.markdown).write_text(table)


if __name__ == "__main__":
    main()
