"""The handlers that keep bound meshes following their targets: after each depsgraph update and
each frame change (keyframes, drivers, `frame_set`, `blender -b -a` renders), on Edit Mode's way in
and out, and when a file is loaded (bound meshes bound again without a click, in the background in
a window: tasks.py)."""

import bpy
import numpy as np

from . import binding, editing, library, mesh_helpers, preparing, tasks


def _follow(obj, b, depsgraph):
    if obj.mode == "EDIT":
        if not b.editing:
            editing.enter(obj, b)
        return
    if b.editing:
        editing.leave(obj)
        return
    if len(b.rest) != len(obj.data.vertices):  # a modifier applied, Join, Separate, Decimate
        binding.release_changed(obj, f"the mesh went from {len(b.rest):,} to "
                                f"{len(obj.data.vertices):,} vertices outside Edit Mode (a "
                                "modifier applied, Join, Separate or Decimate)")
        return
    binding.leave_pose_out_of_new_keys(obj, b)
    if all(target for _, target, _ in binding.handles(obj)):
        try:
            binding.update(obj, b, depsgraph)
        except library.specdeform.Error as e:
            b.status["error"] = str(e)
        except binding.ChangedOutside:
            binding.release_changed(obj)


@bpy.app.handlers.persistent
def follow_targets(scene, depsgraph):
    """depsgraph_update_post and frame_change_post: each bound mesh of the scene follows; one
    bound without a binding (renamed, or Unbind undone) is bound again first."""
    if library.specdeform is None:
        return
    for obj in scene.objects:
        if obj.type != "MESH" or not obj.specdeform.bound:
            continue
        if tasks.running(obj):
            if obj.mode == "EDIT":
                editing.enter_while_binding(obj)
        elif editing.pending(obj):
            if obj.mode != "EDIT":
                editing.leave(obj)
        elif binding.binding(obj) is None:
            if not mesh_helpers.rest_covers(obj.data):  # Join redone, say
                binding.release_changed(obj, "vertices were joined to the mesh outside Edit "
                                        "Mode (Join)")
            elif obj.name_full not in binding.problems:
                _bind_again(obj)
        else:
            _follow(obj, binding.binding(obj), depsgraph)


def _bind_again(obj):
    """Binds a bound object again from its saved rest (a file loaded, the object renamed, Unbind
    undone): in a window in the background, the mesh showing its saved pose meanwhile. A failure
    is kept (said in the panel) so that it is not tried on every update."""
    tasks.start(obj, _bound_again, keep_shown=True,
                showing="the mesh shows the pose it was saved with")


def _bound_again(obj, error):
    if obj is None or not error or editing.pending(obj):
        return
    if error == preparing.CANCELLED:
        error = "Binding again cancelled: the mesh shows its saved pose; Bind resumes"
    binding.problems[obj.name_full] = error
    print(f"specdeform: '{obj.name}' stays as saved: {error}")


@bpy.app.handlers.persistent
def bind_loaded(*_):
    """load_post: the bound meshes of the file loaded bound again from their saved rest (the
    basis from the cache, or computed), as they were posed."""
    tasks.cancel_all()  # the last file's
    binding.forget_all()
    editing.clear()
    if library.specdeform is None:
        return
    for obj in bpy.data.objects:
        if obj.type == "MESH" and obj.specdeform.bound:
            _bind_again(obj)


@bpy.app.handlers.persistent
def undone(*_):
    """undo_post and redo_post: Blender gave back another state of the file, every object and
    mesh as it was then (a bound mesh shows the pose of that state), which the add-on follows:
    - a bind running for a mesh now in Edit Mode, or bound since it began or no longer bound, is
      cancelled (the others check before attaching that the rest they read is still the mesh's);
    - Edit Mode, and the step of leaving it: editing.undone_to;
    - a binding whose rest is not the one its mesh saved (a modifier's apply or Edit Mode
      undone) is dropped, and the mesh bound again from the rest it saved, showing the pose
      undone to; the others solve again for their targets as they were;
    - what was said of an object is forgotten, but for the failures of the bound meshes still
      without a binding."""
    binding.notices.clear()
    for task in tasks.all_running():
        obj = bpy.data.objects.get(task.name)
        if obj is not None and (obj.mode == "EDIT" or obj.specdeform.bound != task.bound):
            task.cancel()
            binding.problems.pop(task.name, None)
    for obj in bpy.data.objects:
        if obj.type != "MESH" or not obj.specdeform.bound:
            binding.problems.pop(obj.name_full, None)
            continue
        b = binding.binding(obj)
        if editing.undone_to(obj, b) or b is None:
            continue
        if b.editing or not np.array_equal(mesh_helpers.saved_rest(obj.data), b.rest):
            binding.forget(obj)
        else:  # the mesh shows the pose of the state undone to: solved again
            b.last, b.written = None, False


@bpy.app.handlers.persistent
def note_before_saving(*_):
    """save_pre: a save never solves nor waits for the transfer; the file keeps each bound mesh's
    pose as shown, noting whether it carries the full details (saved_full). Reopened with its
    targets where they were, a full pose is kept as saved, bit for bit; one shown with its details
    as displacements (a quick drag, the transfer still being factored) is shown as saved and
    solved in full in the background (binding.attach)."""
    for obj in bpy.data.objects:
        b = binding.binding(obj) if obj.type == "MESH" and obj.specdeform.bound else None
        if b is not None and obj.specdeform.saved_full != b.exact:
            obj.specdeform.saved_full = b.exact
