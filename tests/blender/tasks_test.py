"""Binds in steps (tasks.py, preparing.py), headless, driven as the window's timer drives them:
a bound mesh bound again (a reopened file) never holds Blender's thread long, shows its saved pose
until it is posed again, and comes back at that pose; a cancel in every stage ends the bind at
once, leaves the mesh as shown and says so, and its worker stops; Edit Mode entered while a mesh
is bound again shows the rest and leaving it binds from the edited rest; an Undo while a Bind
runs.

    blender -b --factory-startup --python-exit-code 1 --python tasks_test.py
Environment: SPECDEFORM_BLENDER_DIR, SPECDEFORM_PYTHON_DIR.
"""

import os
import re
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import support  # noqa: E402

import bmesh  # noqa: E402
import bpy  # noqa: E402
import numpy as np  # noqa: E402
import specdeform  # noqa: E402
from specdeform_blender import binding, handlers, preparing, tasks  # noqa: E402

tasks.in_window = lambda: True  # binds run as tasks, as in a window
CANCEL_S = 0.5  # the bar: a cancel gives Blender back within this


def drive(task, shown, diagonal):
    """Runs the task as the timer does, one round of steps at a time: until it poses the mesh,
    the mesh shows `shown`. Returns the longest round (seconds)."""
    longest = 0.0
    while not task.finished:
        start = time.perf_counter()
        tasks._tick()
        longest = max(longest, time.perf_counter() - start)
        if not task.finished:
            assert np.abs(support.evaluated(task_object(task)) - shown).max() <= 1e-6 * diagonal
            time.sleep(tasks.TICK_S)
    return longest


def task_object(task):
    return bpy.data.objects[task.name]


def workers_stop():
    """The cancelled binds' threads end (at their next report or stage)."""
    deadline = time.perf_counter() + 60
    while binding.jobs and time.perf_counter() < deadline:
        time.sleep(0.05)
    assert not binding.jobs, "a cancelled bind's worker still runs"


def check_bound_again(obj, pose, diagonal):
    """A bound mesh without its binding (as a reopened file's, saved during a quick drag) is bound
    again in steps."""
    obj.specdeform.saved_full = False
    binding.forget(obj)
    handlers.follow_targets(bpy.context.scene, bpy.context.evaluated_depsgraph_get())
    task = tasks.running(obj)
    assert task is not None and not task.finished, "not bound again as a task"
    must_be_final, binding._must_be_final = binding._must_be_final, lambda: False  # a window's
    longest = drive(task, pose, diagonal)
    binding._must_be_final = must_be_final
    print(f"bound again in steps: the longest round {1e3 * longest:.0f} ms")
    assert task.error is None and binding.binding(obj) is not None, task.error
    assert np.abs(support.evaluated(obj) - pose).max() <= 1e-6 * diagonal, "not the same pose"
    # The saved pose stays shown until the full details are ready, then solved again: the same.
    assert not binding.binding(obj).exact
    binding.finish(obj)
    assert binding.binding(obj).exact
    assert np.abs(support.evaluated(obj) - pose).max() <= 1e-6 * diagonal, "solved again"
    obj.specdeform.saved_full = True


def stage(task):
    """The task's stage: its line without the percentages and seconds."""
    return re.split(r" \d| ·", task.text().removeprefix("Binding: "))[0]


def check_cancel_everywhere(obj, pose, diagonal):
    """Cancelled in each of its stages in turn: the bind ends at once, the mesh keeps its pose,
    the panel says it (and how to resume), the worker stops; Bind then resumes it. The basis is
    not in the cache (Modes changed), so the basis's stages are cancelled too."""
    obj.specdeform.modes = 60
    cancelled = []
    while True:
        binding.forget(obj)
        binding.problems.pop(obj.name_full, None)
        task = tasks.start(obj, handlers._bound_again)
        while not task.finished and stage(task) in cancelled:
            tasks._tick()
            time.sleep(0.002)
        if task.finished:
            break
        cancelled.append(stage(task))
        start = time.perf_counter()
        tasks.cancel(obj)
        took = time.perf_counter() - start
        print(f"cancelled in '{cancelled[-1]}': {1e3 * took:.1f} ms")
        assert took <= CANCEL_S and task.finished and tasks.running(obj) is None
        assert binding.binding(obj) is None
        assert np.abs(support.evaluated(obj) - pose).max() <= 1e-6 * diagonal
        line = support.panel_lines(obj)[0]
        assert line.startswith("Binding again cancelled: the mesh shows its saved pose"), line
        workers_stop()
        # A basis cancelled while computed is not cached. (Once a bind got past its basis, as
        # one cancelled while posing may, the basis is saved and the next bind loads it.)
        if cancelled[-1].startswith("basis:") and cancelled[-1] != "basis: loading the basis":
            assert not any("-m60-" in f for f in os.listdir(support.library.cache_dir()))
    for expected in ("reading the vertex groups", "basis:",
                     "building the deformer"):
        assert any(c.startswith(expected) for c in cancelled), (expected, cancelled)
    # After a cancel, Bind resumes: from the saved rest, posed again.
    obj.specdeform.modes = 100
    binding.forget(obj)
    tasks.start(obj, handlers._bound_again).cancel()
    support.bind(obj)
    assert np.abs(support.evaluated(obj) - pose).max() <= 1e-6 * diagonal


def check_edit_mode(obj, rest, pose, diagonal):
    """Edit Mode entered while the mesh is bound again: the bind stops and the edit mesh shows the
    rest; leaving it binds again from the rest as edited (unchanged here) and poses it."""
    binding.forget(obj)
    task = tasks.start(obj, handlers._bound_again)
    tasks._tick()
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.context.view_layer.update()
    assert task.finished and tasks.running(obj) is None, "the bind still runs in Edit Mode"
    bm = bmesh.from_edit_mesh(obj.data)
    edited = np.array([v.co for v in bm.verts], np.float32)
    assert np.abs(edited - rest).max() <= 1e-6 * diagonal, "Edit Mode shows the pose"
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.context.view_layer.update()
    task = tasks.running(obj)
    assert task is not None, "leaving Edit Mode did not bind again"
    drive(task, rest, diagonal)
    assert task.error is None, task.error
    assert "Bound again from the edited rest shape" in " ".join(support.panel_lines(obj))
    assert np.abs(support.evaluated(obj) - pose).max() <= 1e-5 * diagonal


def check_undo_while_binding(rest, pose, diagonal):
    """Unbind, Bind again as a task, and Undo while it runs (which gives back the bound mesh
    before Unbind): that Bind is cancelled, and the mesh bound again from its saved rest in the
    background, showing the pose undone to meanwhile and after."""
    bpy.context.view_layer.update()
    assert bpy.ops.ed.undo_push(message="posed") == {"FINISHED"}
    assert bpy.ops.specdeform.unbind("EXEC_DEFAULT", True) == {"FINISHED"}
    first = tasks.start(bpy.data.objects["bar"], lambda _obj, _error: None)
    tasks._tick()
    assert bpy.ops.ed.undo() == {"FINISHED"}
    bpy.context.view_layer.update()
    obj = bpy.data.objects["bar"]  # an undo replaces the objects
    assert first.finished and first.error == preparing.CANCELLED, first.error
    assert obj.specdeform.bound, "Unbind not undone"
    task = tasks.running(obj)
    assert task is not None and task is not first, "not bound again after the undo"
    drive(task, pose, diagonal)
    assert task.error is None and binding.binding(obj) is not None, task.error
    assert np.abs(support.evaluated(obj) - pose).max() <= 1e-6 * diagonal
    support.move(bpy.data.objects["bar-target"], np.eye(4))
    assert np.abs(support.evaluated(obj) - rest).max() <= 1e-6 * diagonal, "not from its rest"
    return obj, bpy.data.objects["bar-target"]


def check_target_moved_while_binding(obj, empty, rest, diagonal, handle):
    """A target moved while Bind runs: the rest is the pose as Bind began, so the mesh, once
    bound, follows the move (its handle at the target, 0.5% of the diagonal)."""
    assert bpy.ops.specdeform.unbind() == {"FINISHED"}
    support.move(empty, np.eye(4))
    task = tasks.start(obj, lambda _obj, _error: None)
    tasks._tick()
    T = np.eye(4)
    T[:3, 3] = (0, -0.4, 0.2)
    support.move(empty, T)
    drive(task, rest, diagonal)
    assert task.error is None and obj.specdeform.bound, task.error
    X = support.evaluated(obj)
    miss = np.linalg.norm(X[handle] - support.apply_transform(T, rest[handle]), axis=1).max()
    assert miss <= 0.005 * diagonal, miss / diagonal


def main():
    V, F = specdeform.bumpy_bar(cells_per_unit=24)
    handle, fixed = np.flatnonzero(V[:, 0] > 3.6), np.flatnonzero(V[:, 0] < 0.4)
    support.fresh_file()
    with tempfile.TemporaryDirectory() as cache:
        os.environ["XDG_CACHE_HOME"] = cache
        obj, empty = support.add_object("bar", V, F, handle, fixed)
        rest = support.evaluated(obj)
        diagonal = support.diagonal(rest)
        support.bind(obj)
        T = np.eye(4)
        T[:3, 3] = (0, 0.5, 0.3)
        support.move(empty, T)
        pose = support.evaluated(obj)
        assert np.abs(pose - rest).max() > 0.1 * diagonal
        check_bound_again(obj, pose, diagonal)
        check_cancel_everywhere(obj, pose, diagonal)
        check_edit_mode(obj, rest, pose, diagonal)
        obj, empty = check_undo_while_binding(rest, pose, diagonal)
        check_target_moved_while_binding(obj, empty, rest, diagonal, handle)
        workers_stop()
    print("passed")


main()
