"""How long the add-on holds Blender's window on a large bound file: opened, saved (a copy), then
Edit Mode entered and left, then the target moved five times as soon as the mesh is bound again
(a Bind's first moves), in a window (Xvfb), against the same steps without the add-on
(BASELINE=1: Blender's own cost, its draws of the mesh included). A 20 ms timer records the gaps
between its ticks (the longest time the window could not answer), and each of the add-on's
main-thread steps is timed.
The file is made by blender_large_mesh.py's scene (bound, the target moved, saved):

    SPECDEFORM_BLENDER_DIR=build/blender blender -b --factory-startup \\
        --python benchmarks/blender_window.py -- /tmp/arm692k.obj --make /tmp/large.blend
    [BASELINE=1] SPECDEFORM_BLENDER_DIR=build/blender xvfb-run -a -s "-screen 0 1280x800x24" \\
        blender --factory-startup --python benchmarks/blender_window.py -- /tmp/large.blend
Prints one JSON line: the marks (seconds since the file was opened), the longest gap in each
phase, the add-on's longest step, the pose after binding again against the saved one, the save's
seconds, each first move's update (`first_moves_s`: the move and the scene's evaluation, ours
included).
"""

import json
import os
import sys
import time

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "tests", "blender"))
import support  # noqa: E402

import bpy  # noqa: E402
import numpy as np  # noqa: E402
import specdeform  # noqa: E402

BASELINE = bool(os.environ.get("BASELINE"))
args = sys.argv[sys.argv.index("--") + 1:]


def make(mesh, path):
    """The large scene bound, its target moved, saved at `path` (the pose beside it, .npy)."""
    V, F = specdeform.read_mesh(mesh)
    y = V[:, 1]
    low, high = y.min() + 0.1 * np.ptp(y), y.max() - 0.1 * np.ptp(y)
    support.fresh_file()
    obj, empty = support.add_object("large", V, F, np.flatnonzero(y > high),
                                    np.flatnonzero(y < low))
    support.bind(obj)
    T = np.eye(4)
    T[:3, 3] = (0, 0.1, 0.05)
    support.move(empty, T)
    bpy.ops.wm.save_as_mainfile(filepath=path)
    np.save(path + ".npy", support.evaluated(obj))


if "--make" in args:
    make(args[0], args[args.index("--make") + 1])
    sys.exit(0)

from specdeform_blender import binding, editing, tasks  # noqa: E402

if not BASELINE:
    support.specdeform_blender.register()
path = args[0]
phase, gaps, steps, marks = ["start"], [], [], []
last = [time.perf_counter()]


def probe():
    now = time.perf_counter()
    gaps.append((phase[0], now - last[0]))
    last[0] = now
    return 0.02


def timed(function, label):
    def wrapper(*a):
        start = time.perf_counter()
        result = function(*a)
        steps.append((phase[0], label(*a), time.perf_counter() - start))
        return result
    return wrapper


tasks.Task.step = timed(tasks.Task.step, lambda task: task.text().split(" · ")[0])
editing.show_rest = timed(editing.show_rest, lambda *_: "Edit Mode: the rest shown")
binding._finish_later = timed(binding._finish_later, lambda _: "the full details")


def mark(what):
    marks.append((what, time.perf_counter()))


def obj():
    return bpy.data.objects.get("large")


def settled(seconds=12):
    """Until the add-on's binds are done (BASELINE: the same seconds as they take)."""
    start = time.perf_counter()
    while tasks._tasks or (BASELINE and time.perf_counter() - start < seconds):
        yield 0.1


def pose_error():
    return float(np.abs(support.evaluated(obj()) - np.load(path + ".npy")).max())


def mode(name):
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == "VIEW_3D")
    with bpy.context.temp_override(window=win, area=area, active_object=obj(), object=obj()):
        start = time.perf_counter()
        bpy.ops.object.mode_set(mode=name)
        return time.perf_counter() - start


def script():
    out = {}
    yield 1.0
    phase[0] = "open"
    mark("open")
    bpy.ops.wm.open_mainfile(filepath=path)
    mark("opened")
    bpy.app.timers.register(probe, persistent=True)
    last[0] = time.perf_counter()
    phase[0] = "binding again after opening"
    yield from settled()
    mark("bound again")
    if not BASELINE:
        out["pose_error_bound"] = pose_error()
        b = binding.binding(obj())
        while not b.exact:
            yield 0.1
        mark("full details")
        out["pose_error_full"] = pose_error()
    yield 1.0
    phase[0] = "saving"
    start = time.perf_counter()
    bpy.ops.wm.save_as_mainfile(filepath=path + ".saved.blend", copy=True)
    out["save_s"] = time.perf_counter() - start
    yield 1.0
    phase[0] = "entering Edit Mode"
    out["enter_edit_s"] = mode("EDIT")
    yield 1.0
    phase[0] = "leaving Edit Mode"
    out["leave_edit_s"] = mode("OBJECT")
    mark("left Edit Mode")
    phase[0] = "binding again after Edit Mode"
    yield 0.5
    yield from settled()
    mark("bound again after Edit Mode")
    phase[0] = "moving after Bind"
    out["first_moves_s"] = []
    for k in range(5):
        start = time.perf_counter()
        bpy.data.objects["large-target"].location.y += 0.02
        bpy.context.view_layer.update()
        out["first_moves_s"].append(round(time.perf_counter() - start, 3))
        yield 0.3
    yield 0.5
    out["marks"] = [(w, round(t - marks[0][1], 2)) for w, t in marks]
    out["longest_gap_s"] = {p: round(max(g for q, g in gaps if q == p), 3)
                            for p in dict.fromkeys(p for p, _ in gaps)}
    ours = [s for s in steps if s[1] != "Edit Mode: the rest shown"]
    out["longest_step"] = max(ours, key=lambda s: s[2], default=None)
    out["rest_shown_s"] = [round(s[2], 3) for s in steps if s[1] == "Edit Mode: the rest shown"]
    print("blender_window", json.dumps(out), flush=True)
    bpy.ops.wm.quit_blender()


support.run_in_window(script, first_interval=2.0)
