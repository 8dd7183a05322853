"""The handlers that keep bound meshes following their targets: after each depsgraph update and
each frame change (keyframes, drivers, `frame_set`, `blender -b -a` renders), on Edit Mode's way in
and out, and when a file is loaded (bound meshes bound again without a click)."""

import bmesh
import bpy

from . import binding, library, mesh_helpers


def _show_rest(obj, b):
    """Entering Edit Mode: the edit mesh shows the rest shape, which the edits change."""
    bm = bmesh.from_edit_mesh(obj.data)
    if len(bm.verts) == len(b.rest):
        for v, co in zip(bm.verts, b.rest.tolist()):
            v.co = co
        bmesh.update_edit_mesh(obj.data, loop_triangles=False, destructive=False)
    b.editing = True


def _rebind_edited(obj):
    """Leaving Edit Mode: the mesh as edited is the new rest; bound again from it (the basis from
    the cache when the mesh did not change) and posed again."""
    mesh_helpers.save_rest(obj.data, mesh_helpers.rest_coordinates(obj.data))
    binding._bindings.pop(obj.name_full, None)
    error = binding.bind_now(obj)
    if error:
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
            _show_rest(obj, b)
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
    for obj in scene.objects:
        if obj.type == "MESH" and obj.specdeform.bound and library.specdeform is not None:
            if binding.binding(obj) is None and obj.name_full not in binding.problems:
                _bind_again(obj)
            b = binding.binding(obj)
            if b is not None:
                _follow(obj, b, depsgraph)


def _bind_again(obj):
    """Binds a bound object from its saved rest, its progress printed; a failure is kept (and
    said in the panel) so that it is not tried on every update."""
    name = obj.name
    error = binding.bind_now(obj, lambda text: print(f"specdeform: '{name}': {text}"))
    if error:
        binding.problems[obj.name_full] = error
        print(f"specdeform: '{name}' stays as saved: {error}")


@bpy.app.handlers.persistent
def bind_loaded(*_):
    """load_post: the bound meshes of the file loaded bound again from their saved rest (the
    basis from the cache, or computed, its progress printed), as they were posed."""
    binding.forget_all()
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
