"""The handlers that keep bound meshes following their targets: after each depsgraph update and
each frame change (keyframes, drivers, `frame_set`, `blender -b -a` renders), on Edit Mode's way in
and out, and when a file is loaded (bound meshes bound again without a click, in the background in
a window: tasks.py)."""

import bmesh
import bpy

from . import binding, library, mesh_helpers, preparing, tasks

_editing = set()  # Object.name_full: Edit Mode entered while the object was being bound again


def _show_rest(obj, rest=None):
    """Entering Edit Mode: the edit mesh shows the rest shape, which the edits change: `rest`, or
    the one saved in the mesh (its attribute is a layer of the edit mesh in Edit Mode)."""
    bm = bmesh.from_edit_mesh(obj.data)
    if rest is None:
        layer = bm.verts.layers.float_vector.get(mesh_helpers.REST)
        rest = [v[layer].copy() for v in bm.verts] if layer is not None else []
    else:
        rest = rest.tolist()
    if len(bm.verts) == len(rest):
        for v, co in zip(bm.verts, rest):
            v.co = co
        bmesh.update_edit_mesh(obj.data, loop_triangles=False, destructive=False)


def _edit_while_binding(obj):
    """Edit Mode entered while the object is bound again: that bind is dropped, the edit mesh
    shows the rest (not the saved pose), and leaving Edit Mode binds again from the edited rest."""
    _editing.add(obj.name_full)
    tasks.cancel(obj)
    _show_rest(obj)


def _rebind_edited(obj):
    """Leaving Edit Mode: the mesh as edited is the new rest, shown until it is bound again from
    it (the basis from the cache when the mesh did not change) and posed again."""
    _editing.discard(obj.name_full)
    mesh_helpers.save_rest(obj.data, mesh_helpers.rest_coordinates(obj.data))
    binding.forget(obj)
    tasks.start(obj, _bound_again_edited, showing="the mesh shows its edited rest shape")


def _bound_again_edited(obj, error):
    if obj is None or obj.name_full in _editing:
        return
    if error == preparing.CANCELLED:
        binding.problems[obj.name_full] = ("Edit Mode: binding again cancelled; the mesh shows "
                                           "its edited rest shape: Bind poses it")
    elif error:
        binding.problems[obj.name_full] = f"Edit Mode: {error}"
    else:
        binding.binding(obj).status["note"] = "Bound again from the edited rest shape"


def _changed_outside(obj, before):
    """The mesh's vertices changed in number outside Edit Mode (a modifier applied, Join,
    Separate, Decimate): the binding no longer fits it and its shown shape is the pose already,
    so it is unbound and kept as shown (binding again from it would pose it twice)."""
    binding.release(obj)
    binding.notices[obj.name_full] = (
        f"Unbound: the mesh went from {before:,} to {len(obj.data.vertices):,} vertices outside "
        "Edit Mode (a modifier applied, Join or Separate); it keeps the shape shown. Bind to "
        "deform it again")


def _follow(obj, b, depsgraph):
    if obj.mode == "EDIT":
        if not b.editing:
            _show_rest(obj, b.rest)
            b.editing = True
        return
    if b.editing:
        _rebind_edited(obj)
        return
    if len(b.rest) != len(obj.data.vertices):
        _changed_outside(obj, len(b.rest))
        return
    if all(target for _, target, _ in binding.handles(obj)):
        try:
            binding.update(obj, b, depsgraph)
        except library.specdeform.Error as e:
            b.status["error"] = str(e)


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
                _edit_while_binding(obj)
        elif obj.name_full in _editing:
            if obj.mode != "EDIT":
                _rebind_edited(obj)
        elif binding.binding(obj) is None:
            if obj.name_full not in binding.problems:
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
    if obj is None or not error or obj.name_full in _editing:
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
    _editing.clear()
    if library.specdeform is None:
        return
    for obj in bpy.data.objects:
        if obj.type == "MESH" and obj.specdeform.bound:
            _bind_again(obj)


@bpy.app.handlers.persistent
def finish_before_saving(*_):
    """save_pre: a pose shown with its details as displacements (a quick drag, or the transfer
    still being factored) is solved in full first, so that the file holds the pose its reopening
    computes (the load handler solves in full)."""
    for obj in bpy.data.objects:
        b = binding.binding(obj) if obj.type == "MESH" and obj.specdeform.bound else None
        if b is not None and not b.exact:
            try:
                binding.finish(obj)
            except library.specdeform.Error as e:
                b.status["error"] = str(e)
