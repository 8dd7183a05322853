"""The add-on against Blender's Laplacian Deform modifier (1 and 20 iterations), in one Blender
process on the same meshes, anchors and target moves: bind time, update time (the median of
setting the target's matrix, view_layer.update() and reading the evaluated mesh), the smallest
ring ratio (bars), the largest handle miss and, given `specdeform compare -o` results
(DIR/rotations_<scene>/, as scripts/reproduce.sh writes them), the RMS distance to converged
SR-ARAP.

    blender -b --factory-startup --python benchmarks/blender_vs_laplacian_deform.py -- \
        [--updates 5] [--reference DIR] [--markdown F] [--json F]
Environment: SPECDEFORM_BLENDER_DIR (build/blender), SPECDEFORM_SHARED_DIR (../shared). Laplacian
Deform gets the standard setup: a Hook modifier moves the handle by the target, the modifier's
anchors are the handle and the fixed vertices. The add-on computes its basis (an empty cache).
"""

import argparse
import json
import os
import statistics
import sys
import tempfile
import time

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "tests", "blender"))
import support  # noqa: E402

import bpy  # noqa: E402
import numpy as np  # noqa: E402
import specdeform  # noqa: E402
from mathutils import Matrix  # noqa: E402


def scenes(shared):
    base = os.path.join(shared, "meshes", "scenes")
    for name in ("bar-twist", "bar-bend"):
        path = os.path.join(base, name)
        yield name, specdeform.read_scene(path + ".sel", path + ".off", path + ".def"), True
    hand = os.path.join(here, "..", "docs", "results", "scenes", "armadillo-hand.json")
    armadillo = os.path.join(shared, "meshes", "models", "armadillo.obj")
    yield "armadillo hand", specdeform.read_scene(hand, armadillo), False


def sr_arap(reference, name, s):
    """Converged SR-ARAP from `specdeform compare -o` (file order), in the scene's numbering."""
    path = os.path.join(reference or "", "rotations_" + name.replace("-", "_").replace(" ", "_"),
                        "SR_ARAP__CGAL___converged.obj")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        V = np.array([line.split()[1:4] for line in f if line.startswith("v ")], np.float64)
    return V[s.info.vertex_to_file]


def moves(T, count):
    """`count` target matrices from near the identity to T (T last)."""
    full = Matrix(np.asarray(T).tolist())
    return [Matrix.Identity(4).lerp(full, (k + 1) / count) for k in range(count)]


def time_updates(obj, empty, matrices):
    times = []
    for m in matrices:
        start = time.perf_counter()
        support.move(empty, m)
        support.evaluated(obj)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def ours(s, updates):
    obj, empty = support.add_object("specdeform", s.V, s.F, s.handles[0], s.fixed)
    start = time.perf_counter()
    assert bpy.ops.specdeform.bind() == {"FINISHED"}
    bind = time.perf_counter() - start
    update = time_updates(obj, empty, moves(s.transforms[0], updates))
    return obj, bind, update


def laplacian_deform(s, updates, iterations):
    obj, empty = support.add_object(f"laplacian-{iterations}", s.V, s.F, s.handles[0], s.fixed)
    anchors = np.union1d(s.handles[0], s.fixed)
    obj.vertex_groups.new(name="anchors").add([int(i) for i in anchors], 1.0, "REPLACE")
    hook = obj.modifiers.new("Hook", "HOOK")
    hook.object = empty
    hook.vertex_indices_set([int(i) for i in s.handles[0]])
    lap = obj.modifiers.new("LaplacianDeform", "LAPLACIANDEFORM")
    lap.vertex_group, lap.iterations = "anchors", iterations
    start = time.perf_counter()
    with bpy.context.temp_override(object=obj, active_object=obj):
        bpy.ops.object.laplaciandeform_bind(modifier=lap.name)
    support.evaluated(obj)  # the modifier binds at its next evaluation
    bind = time.perf_counter() - start
    update = time_updates(obj, empty, moves(s.transforms[0], updates))
    return obj, bind, update


def measure(name, s, bar, updates, reference):
    support.fresh_file()
    rest = s.V.astype(np.float32)
    diagonal = support.diagonal(rest)
    handle_target = support.apply_transform(s.transforms[0], rest[s.handles[0]])
    sr = sr_arap(reference, name, s)
    rows = []
    runs = [("specdeform add-on", lambda: ours(s, updates))] + [
        (f"Laplacian Deform, {i} iteration{'s' * (i > 1)}",
         lambda i=i: laplacian_deform(s, updates, i)) for i in (1, 20)]
    for method, run in runs:
        obj, bind, update = run()
        X = support.evaluated(obj)
        miss = np.linalg.norm(X[s.handles[0]] - handle_target, axis=1).max() / diagonal
        ring = float(support.ring_ratios(rest, X).min()) if bar else None
        rms = None if sr is None else float(np.sqrt(((X - sr) ** 2).sum(axis=1).mean()) / diagonal)
        rows.append({"scene": name, "vertices": len(s.V), "method": method, "bind_s": bind,
                     "update_ms": 1e3 * update, "ring": ring, "handle_miss": miss,
                     "rms_to_sr_arap": rms})
        print(rows[-1], flush=True)
    for row in rows:
        row["update_vs_ours"] = row["update_ms"] / rows[0]["update_ms"]
    return rows


def markdown(rows):
    lines = ["| scene | method | bind (s) | update (ms) | update / add-on's | smallest ring "
             "radius / original | handle miss (% of diagonal) | vs converged SR-ARAP: RMS (%) |",
             "|---|---|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        ring = "-" if r["ring"] is None else f"{r['ring']:.3f}"
        rms = "-" if r["rms_to_sr_arap"] is None else f"{100 * r['rms_to_sr_arap']:.2f}"
        lines.append(f"| {r['scene']} ({r['vertices']:,} vertices) | {r['method']} | "
                     f"{r['bind_s']:.2f} | {r['update_ms']:.1f} | {r['update_vs_ours']:.1f} | "
                     f"{ring} | {100 * r['handle_miss']:.2f} | {rms} |")
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--updates", type=int, default=5)
    parser.add_argument("--reference")
    parser.add_argument("--markdown")
    parser.add_argument("--json")
    args = parser.parse_args(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
    shared = support.shared_dir()
    if shared is None:
        sys.exit("../shared/meshes is missing (set SPECDEFORM_SHARED_DIR)")
    rows = []
    with tempfile.TemporaryDirectory() as cache:
        os.environ["XDG_CACHE_HOME"] = cache
        for name, s, bar in scenes(shared):
            rows += measure(name, s, bar, args.updates, args.reference)
    table = markdown(rows)
    print(table)
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write(table)
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"blender": bpy.app.version_string, "rows": rows}, f, indent=1)


main()
