"""Blender's Undo and Redo across a bound mesh's life, headless: operators called with undo=True
and a step pushed after each other change, as the window does after each action of the user.
Every state undone or redone to shows the mesh as it was then, and where it is bound, a binding
that fits it: moving the target poses it from its own rest, never from a pose (a pose applied
twice). Target moves, Bind, Unbind, Strength, a modifier applied, Edit Mode's edits, and Join.

    blender -b --factory-startup --python-exit-code 1 --python undo_test.py
Environment: SPECDEFORM_BLENDER_DIR, SPECDEFORM_PYTHON_DIR. Exits 1 on a failed check.
"""

import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import support  # noqa: E402

import bmesh  # noqa: E402
import bpy  # noqa: E402
import numpy as np  # noqa: E402
import specdeform  # noqa: E402

NAME = "bar"


def shift(y):
    T = np.eye(4)
    T[:3, 3] = (0, y, 0)
    return T


def objects():
    """The bar and its target, looked up again: an undo replaces every object."""
    return bpy.data.objects[NAME], bpy.data.objects[NAME + "-target"]


def push(message):
    """What the window does after a change the user made."""
    bpy.context.view_layer.update()
    assert bpy.ops.ed.undo_push(message=message) == {"FINISHED"}


def undo(redo=False):
    assert (bpy.ops.ed.redo if redo else bpy.ops.ed.undo)() == {"FINISHED"}
    bpy.context.view_layer.update()


def shown():
    bpy.context.view_layer.update()
    return support.evaluated(objects()[0])


def same(A, B, what, tolerance=1e-6):
    assert A.shape == B.shape, f"{what}: {A.shape} vertices against {B.shape}"
    error = np.abs(A - B).max() / support.diagonal(B)
    assert error <= tolerance, f"{what}: {error:.2e} of the diagonal"


def fits(poses, what):
    """The bar is bound, and moving its target poses it as the first binding did (each of
    `poses`: target shift -> pose)."""
    obj, empty = objects()
    assert obj.specdeform.bound, f"{what}: not bound"
    for y, pose in poses.items():
        support.move(empty, shift(y))
        same(shown(), pose, f"{what}, target at {y}")


def in_edit_mode():
    bm = bmesh.from_edit_mesh(objects()[0].data)
    return np.array([v.co for v in bm.verts], np.float32)


def at(y, mode):
    """The state undone to has the target at `y` and the bar in `mode`."""
    obj, empty = objects()
    return obj.mode == mode and abs(empty.location.y - y) < 1e-6


def main():
    support.fresh_file()
    V, F = specdeform.bumpy_bar(cells_per_unit=6)
    handle, fixed = np.flatnonzero(V[:, 0] > 3.6), np.flatnonzero(V[:, 0] < 0.4)
    obj, empty = support.add_object(NAME, V, F, handle, fixed)
    push("added")
    assert bpy.ops.specdeform.bind("EXEC_DEFAULT", True) == {"FINISHED"}
    poses = {0.0: shown()}
    same(poses[0.0], V, "bound: the input as it was")
    for y in (0.4, 0.8):
        support.move(objects()[1], shift(y))
        push(f"target at {y}")
        poses[y] = shown()
    assert np.abs(poses[0.8] - V).max() > 0.5

    # Target moves undone and redone; Bind undone (the input back, unbound) and redone.
    undo()
    same(shown(), poses[0.4], "target move undone")
    undo(redo=True)
    same(shown(), poses[0.8], "target move redone")
    undo(), undo(), undo()
    assert not objects()[0].specdeform.bound, "Bind undone: still bound"
    same(shown(), V, "Bind undone")
    undo(redo=True)
    same(shown(), V, "Bind redone")
    undo(redo=True), undo(redo=True)
    same(shown(), poses[0.8], "redone to the last target move")
    fits(poses, "Bind redone")
    push("back at 0.8")

    # Unbind undone: bound again from the saved rest, showing the pose undone to.
    bpy.context.view_layer.objects.active = objects()[0]
    assert bpy.ops.specdeform.unbind("EXEC_DEFAULT", True) == {"FINISHED"}
    undo()
    same(shown(), poses[0.8], "Unbind undone")
    fits(poses, "Unbind undone")
    push("back at 0.8")

    # Strength undone.
    objects()[0].specdeform.strength = 0.5
    push("strength")
    same(shown(), V + 0.5 * (poses[0.8] - V), "Strength 0.5", 1e-5)
    undo()
    assert objects()[0].specdeform.strength == 1.0
    same(shown(), poses[0.8], "Strength undone")

    # A Subdivision Surface applied while posed (the add-on unbinds the mesh, keeping its shape),
    # undone back to the bound bar: it fits again, whatever state Blender passes through.
    obj = objects()[0]
    obj.modifiers.new("subdivision", "SUBSURF").levels = 1
    push("modifier added")
    bpy.context.view_layer.objects.active = obj
    assert bpy.ops.object.modifier_apply("EXEC_DEFAULT", True, modifier="subdivision") == {
        "FINISHED"}
    assert not objects()[0].specdeform.bound and len(shown()) > len(V)
    for _ in range(3):
        undo()
        obj = objects()[0]
        if len(obj.data.vertices) == len(V):
            same(support.mesh_helpers.shown(obj.data), poses[0.8], "Apply undone")
            if not obj.modifiers:
                break
        elif obj.specdeform.bound:  # the state applied: bound with the subdivided rest
            support.move(objects()[1], np.eye(4))
            same(shown(), support.mesh_helpers.saved_rest(obj.data), "applied, target back")
    assert len(objects()[0].data.vertices) == len(V), "Apply not undone"
    same(shown(), poses[0.8], "Apply undone")
    fits(poses, "Apply undone")
    push("back at 0.8")

    # Edit Mode: the middle raised, then each state walked through, back and forth. In Edit Mode
    # the mesh shows its rest (as it was, or as edited), never a pose; leaving it binds from
    # that rest. Undone past Edit Mode, the bar poses from its first rest again.
    middle = np.abs(V[:, 0] - 2) < 0.3
    edited = V.copy()
    edited[middle, 2] += 0.3
    bpy.context.view_layer.objects.active = objects()[0]
    assert bpy.ops.object.mode_set("EXEC_DEFAULT", True, mode="EDIT") == {"FINISHED"}
    same(in_edit_mode(), V, "Edit Mode: the rest")
    bm = bmesh.from_edit_mesh(objects()[0].data)
    for v in bm.verts:
        v.co.z += 0.3 * middle[v.index]
    bmesh.update_edit_mesh(objects()[0].data)
    push("edited")
    assert bpy.ops.object.mode_set("EXEC_DEFAULT", True, mode="OBJECT") == {"FINISHED"}
    edited_poses = {0.8: shown()}
    support.move(objects()[1], np.eye(4))
    edited_poses[0.0] = shown()
    same(edited_poses[0.0], edited, "edited, target back")
    support.move(objects()[1], shift(0.4))
    edited_poses[0.4] = shown()
    push("edited, target at 0.4")

    def state(y, mode, rest):
        """The state undone or redone to: the target at `y`, the bar in `mode` showing `rest`
        (Edit Mode) or a pose from it."""
        assert at(y, mode), f"not at {y} in {mode}"
        if mode == "EDIT":
            same(in_edit_mode(), rest, "Edit Mode undone or redone to")
        else:
            poses_of = edited_poses if rest is edited else poses
            same(shown(), poses_of[y], "undone or redone to")
            fits(poses_of, "undone or redone to")

    walk = [(0.8, "OBJECT", V), (0.8, "EDIT", V), (0.8, "EDIT", edited), (0.8, "OBJECT", edited),
            (0.4, "OBJECT", edited)]
    for i in range(len(walk) - 2, -1, -1):
        undo()
        state(*walk[i])
    for i in range(1, len(walk)):
        undo(redo=True)
        state(*walk[i])
    undo(), undo(), undo()
    state(*walk[1])
    bpy.ops.object.mode_set(mode="OBJECT")  # the edit undone: the bar as it was
    fits(poses, "Edit Mode left, its edit undone")
    push("back at 0.8")
    check_join(V, poses)
    print("passed")


def check_join(V, poses):
    """Join with the bound bar active unbinds it, keeping the joined shape; undone, the bar is
    bound and fits; redone, the joined mesh is unbound again with one line saying why, never
    bound to a rest that Join filled with zeros for the cube's vertices (the flags beside the
    rest, false for them, say it)."""
    support.move(objects()[1], shift(0.8))
    posed = shown()
    bpy.ops.mesh.primitive_cube_add(location=(2, 3, 0))
    cube = bpy.context.object
    push("cube added")
    bpy.ops.object.select_all(action="DESELECT")
    obj = objects()[0]
    obj.select_set(True), cube.select_set(True)
    bpy.context.view_layer.objects.active = obj
    assert bpy.ops.object.join("EXEC_DEFAULT", True) == {"FINISHED"}
    bpy.context.view_layer.update()
    joined = shown()
    assert len(joined) == len(V) + 8 and not objects()[0].specdeform.bound
    same(joined[:len(V)], posed, "joined: the bar's pose kept")
    undo()
    assert objects()[0].specdeform.bound and len(shown()) == len(V), "Join undone"
    same(shown(), posed, "Join undone")
    fits(poses, "Join undone")
    support.move(objects()[1], shift(0.8))
    undo(redo=True)
    obj = objects()[0]
    assert len(obj.data.vertices) == len(V) + 8, "Join redone"
    assert not obj.specdeform.bound, "Join redone: bound to a rest that does not fit"
    assert obj.name_full not in support.binding.problems, support.binding.problems
    notice = support.binding.notices[obj.name_full]
    print(f"Join redone: {notice}")
    assert "joined" in notice and notice.endswith("Bind to deform it again"), notice
    same(shown(), joined, "Join redone: the joined shape kept")


with tempfile.TemporaryDirectory() as cache:
    os.environ["XDG_CACHE_HOME"] = cache
    main()
