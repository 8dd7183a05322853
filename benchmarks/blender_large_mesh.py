"""The add-on on a large mesh in one Blender process: Bind's time (an empty basis cache, the
default solver choice) and an update's time against Blender's own floor, writing the same
coordinates and re-evaluating (foreach_set, Mesh.update(), view_layer.update()), and the floor's
variants (a shape key; no Mesh.update(), only a tag).

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


def median_ms(step, count):
    times = []
    for k in range(count):
        start = time.perf_counter()
        step(k)
        times.append(1e3 * (time.perf_counter() - start))
    return statistics.median(times)


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

    update = median_ms(lambda k: support.move(empty, translation(k)), args.updates)
    solve, write = b.status["solve_ms"], b.status["write_ms"]
    co = np.ascontiguousarray(b.positions).ravel()

    def floor(_):
        mesh.vertices.foreach_set("co", co)
        mesh.update()
        bpy.context.view_layer.update()

    def tag_only(_):
        mesh.vertices.foreach_set("co", co)
        mesh.update_tag()
        bpy.context.view_layer.update()

    floor_ms = median_ms(floor, args.updates)
    tag_ms = median_ms(tag_only, args.updates)
    print(f"update {update:.0f} ms (solve {solve:.0f} ms, write {write:.0f} ms); Blender's floor "
          f"(foreach_set, update(), re-evaluation) {floor_ms:.0f} ms, with update_tag() "
          f"{tag_ms:.0f} ms; ours {update - floor_ms:.0f} ms")
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
