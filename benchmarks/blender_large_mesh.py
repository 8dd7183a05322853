"""The add-on on a large mesh in one Blender process: Bind's time (an empty basis cache, the
default solver choice) and an update's time against Blender's own floor, writing the same
coordinates and re-evaluating (foreach_set, Mesh.update(), view_layer.update()), and the floor's
variants (a shape key; no Mesh.update(), only a tag). Updates are timed in full (a render's,
as `blender -b` always solves) and as a drag in the window solves them (Quick drags: the
details as displacements, then once in full when the target rests). Each update is followed by
the floor for its coordinates: "ours" is the median of the differences of these pairs, so that
the machine's drifts fall on both sides.

    specdeform subdivide armadillo.obj -l 2 -o /tmp/arm692k.obj
    SPECDEFORM_BLENDER_DIR=build/blender blender -b --factory-startup \
        --python benchmarks/blender_large_mesh.py -- /tmp/arm692k.obj [--updates 11]
The handle is the top tenth along y, the fixed region the bottom tenth; the target translates.
"""

import argparse
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


def timed_ms(step, k):
    start = time.perf_counter()
    step(k)
    return 1e3 * (time.perf_counter() - start)


def median_ms(step, count):
    return statistics.median(timed_ms(step, k) for k in range(count))


def paired_ms(step, floor, count):
    """Medians of step's time, of the floor's right after it, and of their differences."""
    pairs = [(timed_ms(step, k), timed_ms(floor, k)) for k in range(count)]
    return tuple(statistics.median(x) for x in
                 ([u for u, _ in pairs], [f for _, f in pairs], [u - f for u, f in pairs]))


def translation(k):
    T = np.eye(4)
    T[:3, 3] = (0, 0.01 * (k + 1), 0.005 * (k + 1))
    return T


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("mesh")
    parser.add_argument("--updates", type=int, default=11)
    args = parser.parse_args(sys.argv[sys.argv.index("--") + 1:])
    V, F = specdeform.read_mesh(args.mesh)
    y = V[:, 1]
    low, high = y.min() + 0.1 * np.ptp(y), y.max() - 0.1 * np.ptp(y)
    support.fresh_file()
    handle, fixed = np.flatnonzero(y > high), np.flatnonzero(y < low)
    obj, empty = support.add_object("large", V, F, handle, fixed)
    mesh = obj.data
    with tempfile.TemporaryDirectory() as cache:
        os.environ["XDG_CACHE_HOME"] = cache
        start = time.perf_counter()
        support.bind(obj)
        bind_s = time.perf_counter() - start
        b = support.binding.binding(obj)
        start = time.perf_counter()
        b.deformer.wait_for_detail()  # the frames add displacements until then
        detail_s = time.perf_counter() - start
    print(f"{len(V)} vertices: bind {bind_s:.1f} s (basis {b.status['basis_s']:.1f} s, "
          f"{b.status['basis']}); the transfer's details {detail_s:.1f} s later")

    binding = support.binding

    def floor(_):
        mesh.vertices.foreach_set("co", np.ascontiguousarray(b.positions).ravel())
        mesh.update()
        bpy.context.view_layer.update()

    def tag_only(_):
        mesh.vertices.foreach_set("co", np.ascontiguousarray(b.positions).ravel())
        mesh.update_tag()
        bpy.context.view_layer.update()

    update, floor_ms, ours = paired_ms(lambda k: support.move(empty, translation(k)), floor,
                                       args.updates)
    solve, write = b.status["solve_ms"], b.status["write_ms"]
    must_be_final, binding._must_be_final = binding._must_be_final, lambda: False  # the window
    drag, drag_floor, drag_ours = paired_ms(
        lambda k: support.move(empty, translation(args.updates + k)), floor, args.updates)
    assert b.status["quick"]
    drag_solve, drag_write = b.status["solve_ms"], b.status["write_ms"]
    start = time.perf_counter()
    binding.finish(obj)  # what the timer does once the target rests
    rest_ms = 1e3 * (time.perf_counter() - start)
    binding._must_be_final = must_be_final
    tag_ms = median_ms(tag_only, args.updates)
    print(f"update in full {update:.0f} ms (solve {solve:.0f} ms, write {write:.0f} ms); "
          f"Blender's floor (foreach_set, update(), re-evaluation) {floor_ms:.0f} ms, with "
          f"update_tag() {tag_ms:.0f} ms; ours {ours:.0f} ms")
    print(f"a quick drag's update {drag:.0f} ms (solve {drag_solve:.0f} ms, write "
          f"{drag_write:.0f} ms), the floor beside it {drag_floor:.0f} ms: ours {drag_ours:.0f} ms; "
          f"in full once it rests {rest_ms:.0f} ms")
    co = np.ascontiguousarray(b.positions).ravel()
    assert bpy.ops.specdeform.unbind() == {"FINISHED"}
    obj.shape_key_add(name="Basis")
    key = obj.shape_key_add(name="pose")
    key.value = 1.0

    def shape_key(_):
        key.data.foreach_set("co", co)
        mesh.update()
        bpy.context.view_layer.update()

    print(f"a shape key written instead: {median_ms(shape_key, args.updates):.0f} ms")


main()
