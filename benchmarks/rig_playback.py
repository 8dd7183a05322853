"""Rigs after a bend, played (issue 53; docs/results.md, "Rigs"). Debian's Blender writes a skinned
figure that walks (shape keys keyed too) and a "horse" that gallops by its shape keys
(tests/files/export_rig.py); the command line bends their tops (moved 0.1 of the diagonal, turned
30 degrees, the bottom fixed) with the rig followed (the default) and kept (--morph-targets keep
--joints keep), and the evaluator of the tests (tests/python/gltf_pose.py) plays them.

Measures, for each output:
  - targets: at vertices the bend turns by 10 degrees or more whose delta is at least 0.5% of the
    diagonal, |d_out - R d_in| / |d_in| (R fitted to the welded vertex's one-ring), 95th
    percentile and largest;
  - joints: how far each joint's bind position is from where the handle's motion takes it (the
    head's, which drives the handle) or from where it was (joints whose vertices are all fixed),
    in % of the diagonal;
  - the walk: each joint's skinning matrix at 13 times against its input motion relative to its
    parent, moved to its new place (the largest residual; 0 for a rig kept, whose joints did not
    move: there the head's joint is what is off).
and draws the walk and the gallop, input and both outputs, at four times.

    /usr/bin/python3 benchmarks/rig_playback.py --cli build/bin/specdeform \
        [--files DIR] [--json docs/results/rigs.json] [--pictures docs/results/pictures]
"""

import argparse
import json
import pathlib
import subprocess
import sys
import tempfile

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "python"))
from gltf_pose import Gltf, ring_rotations  # noqa: E402

TIMES = [0.0, 0.33, 0.67, 1.0]


def export(out):
    subprocess.run(["blender", "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                    str(ROOT / "tests" / "files" / "export_rig.py"), "--", str(out)],
                   check=True, capture_output=True, timeout=600)


def positions(g, prim=0):
    return g.accessor(g.json["meshes"][0]["primitives"][prim]["attributes"]["POSITION"])


def bend(cli, src, out, work, options):
    g = Gltf(src)
    x = positions(g)
    diagonal = float(np.linalg.norm(x.max(0) - x.min(0)))
    handle, fixed = np.flatnonzero(x[:, 1] >= 1.8), np.flatnonzero(x[:, 1] <= 1.3)
    centre = x[handle].mean(0)
    scene = {"handles": [{"vertices": handle.tolist(),
                          "transform": {"translate": [0.1 * diagonal, 0, 0],
                                        "center": centre.tolist(),
                                        "rotate": {"axis": [0, 0, 1], "degrees": 30}}}],
             "fixed": fixed.tolist()}
    (work / "scene.json").write_text(json.dumps(scene))
    subprocess.run([cli, "deform", str(src), "--scene", str(work / "scene.json"), "-o", str(out),
                    *options], check=True, capture_output=True, timeout=600)
    a = np.radians(30)
    R = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, centre + [0.1 * diagonal, 0, 0] - R @ centre
    return T, diagonal


def target_errors(src, out, diagonal):
    a, b = Gltf(src), Gltf(out)
    prim_a, prim_b = a.json["meshes"][0]["primitives"][0], b.json["meshes"][0]["primitives"][0]
    R, angle = ring_rotations(positions(a), positions(b),
                              a.accessor(prim_a["indices"]).astype(int).reshape(-1, 3))
    errors = []
    for ta, tb in zip(prim_a["targets"], prim_b["targets"]):
        d_in, d_out = a.accessor(ta["POSITION"]), b.accessor(tb["POSITION"])
        big = np.linalg.norm(d_in, axis=1)
        sel = (angle >= 10) & (big >= 0.005 * diagonal)
        gap = np.linalg.norm(d_out - np.einsum("vij,vj->vi", R, d_in), axis=1)
        errors.extend((gap[sel] / big[sel]).tolist())
    return {"vertices": len(errors), "p95": float(np.percentile(errors, 95)),
            "largest": float(np.max(errors))}


def joint_errors(src, out, T, diagonal):
    a, b = Gltf(src), Gltf(out)
    joints = a.json["skins"][0]["joints"]
    _, ibm_a = a.skin_matrices(0)
    _, ibm_b = b.skin_matrices(0)
    out_ = {}
    for k, j in enumerate(joints):
        name = a.json["nodes"][j]["name"]
        before, after = np.linalg.inv(ibm_a[k])[:3, 3], np.linalg.inv(ibm_b[k])[:3, 3]
        expected = T[:3, :3] @ before + T[:3, 3] if name == "head" else before
        if name in ("head", "root", "spine"):
            out_[name] = float(100 * np.linalg.norm(after - expected) / diagonal)
    return out_


def walk_residual(src, out):
    """The walk as played, against each joint's input motion relative to its parent moved to the
    joint's new place: the largest entry of S'_j(t) - S'_p(t) T_j D_p(t)^-1 D_j(t) T_j^-1 over
    the joints and 13 times (S' the output's skinning matrices, D the input's, T_j = B'_j B_j^-1
    from the files' inverse bind matrices)."""
    a, b = Gltf(src), Gltf(out)
    joints = a.json["skins"][0]["joints"]
    parent = {joints.index(c): k for k, j in enumerate(joints)
              for c in a.json["nodes"][j].get("children", []) if c in joints}
    T = np.linalg.inv(b.skin_matrices(0)[1]) @ a.skin_matrices(0)[1]
    worst = 0.0
    for time in np.linspace(0, 1, 13):
        D, _ = a.skin_matrices(0, a.channels(0), time)
        S, _ = b.skin_matrices(0, b.channels(0), time)
        for k in range(len(joints)):
            p = parent.get(k)
            S_p, D_p = (S[p], D[p]) if p is not None else (np.eye(4), np.eye(4))
            expected = S_p @ T[k] @ np.linalg.inv(D_p) @ D[k] @ np.linalg.inv(T[k])
            worst = max(worst, float(np.abs(S[k] - expected).max()))
    return worst


def draw(ax, g, node, keys, time, title, light=np.array([0.3, 0.5, 1.0]), yaw=55.0):
    from matplotlib.collections import PolyCollection
    c, s = np.cos(np.radians(yaw)), np.sin(np.radians(yaw))
    x = g.posed(node, keys, time) @ np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]]).T
    tri = g.accessor(g.json["meshes"][0]["primitives"][0]["indices"]).astype(int).reshape(-1, 3)
    p = x[tri]
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True) + 1e-30
    facing = n[:, 2] > 0
    order = np.argsort(p[facing][:, :, 2].mean(1))
    shade = np.clip(n[facing] @ (light / np.linalg.norm(light)), 0.15, 1.0)[order]
    colour = np.outer(shade, [0.85, 0.7, 0.55])
    ax.add_collection(PolyCollection(p[facing][order][:, :, :2], facecolors=colour,
                                     edgecolors=colour, linewidths=0.3))
    ax.set_xlim(-0.9, 1.1)
    ax.set_ylim(-0.1, 2.4)
    ax.set_aspect("equal")
    ax.axis("off")
    ax.set_title(title, fontsize=8)


def pictures(files, folder, name, node_of):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = [("input", files[0]), ("bent, rig kept", files[1]), ("bent, rig followed", files[2])]
    fig, axes = plt.subplots(len(rows), len(TIMES), figsize=(2.0 * len(TIMES), 2.4 * len(rows)))
    for r, (label, path) in enumerate(rows):
        g = Gltf(path)
        keys = {}
        for k in range(len(g.json.get("animations", []))):
            keys.update(g.channels(k))
        for c, time in enumerate(TIMES):
            draw(axes[r][c], g, node_of(g), keys, time, f"{label}, t = {time:.2f} s")
    fig.tight_layout()
    fig.savefig(folder / f"rig_{name}.png", dpi=90)
    plt.close(fig)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--cli", default=str(ROOT / "build" / "bin" / "specdeform"))
    p.add_argument("--files", type=pathlib.Path, help="export_rig.py's output (default: made)")
    p.add_argument("--json", type=pathlib.Path)
    p.add_argument("--pictures", type=pathlib.Path)
    args = p.parse_args()
    work = pathlib.Path(tempfile.mkdtemp(prefix="rigs-"))
    files = args.files or work
    if args.files is None:
        export(files)
    result = {}
    made = {}
    for name in ("horse", "figure"):
        src = files / f"{name}.glb"
        outputs = {}
        for mode, options in (("kept", ["--morph-targets", "keep", "--joints", "keep"]),
                              ("followed", [])):
            out = work / f"{name}-{mode}.glb"
            T, diagonal = bend(args.cli, src, out, work, options)
            r = {"targets": target_errors(src, out, diagonal)}
            if name == "figure":
                r["joints_percent_of_diagonal"] = joint_errors(src, out, T, diagonal)
                r["walk_residual"] = walk_residual(src, out)
            outputs[mode] = r
            made[(name, mode)] = out
        result[name] = outputs
    print(json.dumps(result, indent=1))
    if args.json:
        args.json.write_text(json.dumps(result, indent=1) + "\n")
    if args.pictures:
        skinned = lambda g: next(n for n, x in enumerate(g.json["nodes"]) if "mesh" in x)  # noqa
        for name, label in (("figure", "walk"), ("horse", "gallop")):
            pictures([files / f"{name}.glb", made[(name, "kept")], made[(name, "followed")]],
                     args.pictures, label, skinned)


if __name__ == "__main__":
    main()
