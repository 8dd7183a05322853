"""The add-on in a window (Blender under Xvfb, events simulated): Bind from the panel runs while the
window keeps handling events, its progress in the panel, and Esc cancels it within 0.5 s, the mesh
as it was; a reopened file's bound mesh is bound again in the background showing its saved pose,
and Esc cancels that too, the panel saying how to resume; Bind resumes it at the saved pose.
Undo gives back an Unbind and an Edit Mode edit, the mesh bound again from its rest.

    xvfb-run -a blender --factory-startup --enable-event-simulate --python window_test.py
Environment: SPECDEFORM_BLENDER_DIR, SPECDEFORM_PYTHON_DIR. Exits 1 on a failed check.
"""

import os
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import support  # noqa: E402

import bmesh  # noqa: E402
import bpy  # noqa: E402
import numpy as np  # noqa: E402
import specdeform  # noqa: E402
from specdeform_blender import binding, tasks  # noqa: E402

ESC_S = 0.5  # the bar: Esc gives the window back within this, in every stage
cache = tempfile.mkdtemp()
os.environ["XDG_CACHE_HOME"] = cache
path = os.path.join(cache, "bar.blend")


def window_context(obj):
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == "VIEW_3D")
    region = next(r for r in area.regions if r.type == "WINDOW")
    return bpy.context.temp_override(window=win, area=area, region=region, screen=win.screen,
                                     active_object=obj, object=obj)


def esc():
    """Esc pressed and released; returns the time it took the running binds to end."""
    win = bpy.context.window_manager.windows[0]
    start = time.perf_counter()
    win.event_simulate(type="ESC", value="PRESS")
    win.event_simulate(type="ESC", value="RELEASE")
    while tasks._tasks and time.perf_counter() - start < 10:
        yield 0.01
    return time.perf_counter() - start


def until(condition, seconds=240):
    start = time.perf_counter()
    while not condition():
        assert time.perf_counter() - start < seconds, "timed out"
        yield 0.01


def frames_settle():
    """Until Blender's frames take under 50 ms again: its first draws of a mesh just opened
    take 0.3-0.7 s each in software GL beside the worker's two threads (Blender's, not the
    add-on's: Esc waits for the frame being drawn)."""
    fast, last = 0, time.perf_counter()
    while fast < 5:
        yield 0.01
        now = time.perf_counter()
        fast, last = fast + 1 if now - last < 0.05 else 0, now


def stage(obj):
    task = tasks.running(obj)
    return task.text() if task else ""


def bar():
    return bpy.data.objects["bar"]  # looked up again: an undo replaces the objects


def bound_again(shown, diagonal):
    """Bound again in the background after an undo, the mesh showing `shown` meanwhile and
    after."""
    assert tasks.running(bar()) is not None, "not bound again in the background"
    yield from until(lambda: binding.binding(bar()) is not None and binding.binding(bar()).exact)
    assert np.abs(support.evaluated(bar()) - shown).max() <= 1e-6 * diagonal


def check_undo(rest, pose, diagonal):
    """Blender's Undo in the window: Unbind undone, and Edit Mode's edit undone back to the step
    of entering it (whose edit mesh Blender saved showing the pose): each time the mesh is bound
    again in the background from its rest, at the pose undone to; the target moved back gives
    the rest."""
    with window_context(bar()):
        bpy.ops.ed.undo_push(message="posed")
        assert bpy.ops.specdeform.unbind("EXEC_DEFAULT", True) == {"FINISHED"}
    assert np.abs(support.evaluated(bar()) - rest).max() <= 1e-6 * diagonal
    with window_context(bar()):
        assert bpy.ops.ed.undo() == {"FINISHED"}
    assert bar().specdeform.bound, "Unbind not undone"
    yield from bound_again(pose, diagonal)

    with window_context(bar()):
        assert bpy.ops.object.mode_set("EXEC_DEFAULT", True, mode="EDIT") == {"FINISHED"}
        assert bpy.ops.mesh.select_all(action="SELECT") == {"FINISHED"}
        assert bpy.ops.transform.translate("EXEC_DEFAULT", True, value=(0, 0, 0.3)) == {
            "FINISHED"}
        assert bpy.ops.ed.undo() == {"FINISHED"}
    yield 0.2
    bm = bmesh.from_edit_mesh(bar().data)
    edit = np.array([v.co for v in bm.verts], np.float32)
    assert bar().mode == "EDIT" and np.abs(edit - rest).max() <= 1e-6 * diagonal, "not the rest"
    with window_context(bar()):
        assert bpy.ops.object.mode_set(mode="OBJECT") == {"FINISHED"}
    yield 0.2
    yield from bound_again(pose, diagonal)
    support.move(bpy.data.objects["bar-target"], np.eye(4))
    assert np.abs(support.evaluated(bar()) - rest).max() <= 1e-6 * diagonal, "not from the rest"
    print("Undo in the window: Unbind and an Edit Mode edit undone, bound again from the rest")


def script():
    yield 0.5
    support.specdeform_blender.register()
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    V, F = specdeform.bumpy_bar(cells_per_unit=60)
    handle, fixed = np.flatnonzero(V[:, 0] > 3.6), np.flatnonzero(V[:, 0] < 0.4)
    obj, empty = support.add_object("bar", V, F, handle, fixed)
    rest = support.evaluated(obj)
    diagonal = support.diagonal(rest)
    yield from frames_settle()

    # Bind from the panel, cancelled while the basis is computed.
    with window_context(obj):
        assert bpy.ops.specdeform.bind("INVOKE_DEFAULT") == {"RUNNING_MODAL"}
    yield from until(lambda: stage(obj).startswith("Binding: basis:"))
    yield from frames_settle()
    lines = " ".join(support.panel_lines(obj))
    assert "Binding: basis:" in lines and "(Esc cancels)" in lines, lines
    took = yield from esc()
    print(f"Esc during Bind's basis: {1e3 * took:.0f} ms")
    assert took <= ESC_S and not obj.specdeform.bound and binding.binding(obj) is None
    assert np.array_equal(support.evaluated(obj), rest)
    yield from until(lambda: not binding.jobs, 60)

    # Bind to the end, posed, saved.
    with window_context(obj):
        bpy.ops.specdeform.bind("INVOKE_DEFAULT")
    yield from until(lambda: binding.binding(obj) is not None)
    T = np.eye(4)
    T[:3, 3] = (0, 0.5, 0.3)
    support.move(empty, T)
    yield from until(lambda: binding.binding(obj).exact)
    pose = support.evaluated(obj)
    bpy.ops.wm.save_as_mainfile(filepath=path)

    # Reopened: bound again in the background, the saved pose shown meanwhile; Esc cancels it
    # (the basis computed again: the cache emptied, so that the window's first draws of the
    # reopened mesh, Blender's own, are over before Esc).
    for name in os.listdir(os.path.join(cache, "specdeform")):
        os.remove(os.path.join(cache, "specdeform", name))
    bpy.ops.wm.open_mainfile(filepath=path)
    obj = bpy.data.objects["bar"]
    assert tasks.running(obj) is not None, "not bound again in the background"
    yield from until(lambda: stage(obj).startswith("Binding: basis:"))
    assert np.abs(support.evaluated(obj) - pose).max() <= 1e-6 * diagonal
    yield from frames_settle()
    assert stage(obj).startswith("Binding: basis:"), "bound again before the check"
    took = yield from esc()
    print(f"Esc while a reopened file is bound again: {1e3 * took:.0f} ms")
    assert took <= ESC_S and binding.binding(obj) is None
    line = support.panel_lines(obj)[0]
    assert line.startswith("Binding again cancelled: the mesh shows its saved pose"), line
    assert np.abs(support.evaluated(obj) - pose).max() <= 1e-6 * diagonal

    # Bind resumes, at the saved pose.
    with window_context(obj):
        bpy.ops.specdeform.bind("INVOKE_DEFAULT")
    yield from until(lambda: binding.binding(obj) is not None and binding.binding(obj).exact)
    assert np.abs(support.evaluated(obj) - pose).max() <= 1e-6 * diagonal
    yield from check_undo(rest, pose, diagonal)
    print("passed")
    bpy.ops.wm.quit_blender()


support.run_in_window(script)
