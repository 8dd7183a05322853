"""A bound mesh in Edit Mode: entering it, the edit mesh shows the rest shape (outside it, the
mesh shows a pose); leaving it, the mesh as edited is the new rest, bound again in the background.

Undo and Redo give back the steps of entering and leaving Edit Mode as Blender saved them, before
the add-on's handler ran: entering's holds an edit mesh showing the pose, leaving's the edited
rest beside the rest saved before the edits. Both are told by what the mesh showed at that moment
(kept here) and treated as the handler treated them then: the rest shown, or bound again from the
edited rest. Bound from a pose, a mesh would be posed twice."""

import itertools

import bmesh
import numpy as np

from . import binding, mesh_helpers, preparing, tasks

_pending = set()  # Object.name_full: in Edit Mode without a binding (leaving it binds)
_entered = {}  # Object.name_full -> float32 (n, 3): what the mesh showed as Edit Mode began
_left = {}  # Object.name_full -> float32 (n, 3): the rest as edited, as Edit Mode ended


def show_rest(obj, rest=None):
    """The edit mesh shows the rest shape, which the edits change: `rest`, or the one saved in
    the mesh. BMesh has no bulk write, so vertex by vertex: from the saved rest's attribute (a
    layer of the edit mesh in Edit Mode), where it is there and holds `rest` (on a sample of
    vertices), each vertex's coordinates set from its layer's vector (0.06-0.08 s at 692k
    vertices); else from `rest` made Python floats (0.3-0.5 s; a list per vertex took 1.0-1.5 s,
    Python's garbage collector set off over and over by them). With shape keys there is nothing
    to do: Edit Mode shows the active key, the Basis (the rest) unless the artist chose another
    key to edit, which stays as it is."""
    if mesh_helpers.pose_key(obj.data) is not None:
        return
    bm = bmesh.from_edit_mesh(obj.data)
    layer = bm.verts.layers.float_vector.get(mesh_helpers.REST)
    if layer is not None and (rest is None or _layer_holds(bm, layer, rest)):
        for v in bm.verts:
            v.co = v[layer]
    elif rest is not None and len(bm.verts) == len(rest):
        floats = iter(np.asarray(rest, np.float64).ravel().tolist())
        for v, x, y, z in zip(bm.verts, floats, floats, floats):
            v.co = (x, y, z)
    else:
        return
    bmesh.update_edit_mesh(obj.data, loop_triangles=False, destructive=False)


def _sample_holds(bm, read, co):
    """Whether read(v) is co's row for about 64 vertices v spread over the edit mesh (every
    step-th: a lookup table would take 0.2 s at 692k vertices); false where the counts differ."""
    if len(bm.verts) != len(co):
        return False
    step = max(1, len(co) // 64)
    sample = [read(v) for v in itertools.islice(bm.verts, 0, None, step)]
    return np.array_equal(np.array(sample, np.float32), np.asarray(co, np.float32)[::step])


def _layer_holds(bm, layer, rest):
    """Whether the edit mesh's `layer` holds `rest` (float32 (n, 3)), on a sample: the saved rest
    is written with each binding's rest, so it differs everywhere or nowhere."""
    return _sample_holds(bm, lambda v: v[layer], rest)


def _edit_mesh_shows(obj, co):
    """Whether the edit mesh's vertices are at `co`: a sample first (reading them all is a loop,
    half a second at 692k)."""
    bm = bmesh.from_edit_mesh(obj.data)
    if not _sample_holds(bm, lambda v: v.co, co):
        return False
    return np.array_equal(np.array([v.co for v in bm.verts], np.float32).reshape(-1, 3), co)


def _remember_entering(obj):
    """In Edit Mode the mesh's own vertices still hold what it showed before."""
    _entered[obj.name_full] = mesh_helpers.coordinates(obj.data)


def enter(obj, b):
    """Edit Mode entered by a bound mesh with its binding `b`."""
    _remember_entering(obj)
    show_rest(obj, b.rest)
    b.editing = True


def enter_while_binding(obj):
    """Edit Mode entered while the object is bound again: that bind is dropped, the edit mesh
    shows the saved rest (not the saved pose), and leaving Edit Mode binds from the edited rest."""
    _pending.add(obj.name_full)
    _remember_entering(obj)
    tasks.cancel(obj)
    show_rest(obj)


def pending(obj):
    """Whether the object is in Edit Mode without a binding, or left it and is to be bound."""
    return obj.name_full in _pending


def leave(obj):
    """Leaving Edit Mode: the mesh as edited is the new rest, shown until it is bound again from
    it (the basis from the cache when the mesh did not change) and posed again."""
    _pending.discard(obj.name_full)
    rest = mesh_helpers.rest_coordinates(obj.data)
    _left[obj.name_full] = rest
    mesh_helpers.save_rest(obj.data, rest)
    binding.forget(obj)
    tasks.start(obj, _bound_again, showing="the mesh shows its edited rest shape")


def _bound_again(obj, error):
    if obj is None or obj.name_full in _pending:
        return
    if error == preparing.CANCELLED:
        binding.problems[obj.name_full] = ("Edit Mode: binding again cancelled; the mesh shows "
                                           "its edited rest shape: Bind poses it")
    elif error:
        binding.problems[obj.name_full] = f"Edit Mode: {error}"
    else:
        binding.binding(obj).status["note"] = "Bound again from the edited rest shape"


def undone_to(obj, b):
    """Undo or Redo gave back a state of the bound `obj` (`b`: its binding, or None). In Edit
    Mode: entering's step shows the rest as entering did, and leaving binds from the edit mesh.
    Leaving's step: bound again from the edited rest, as leaving did. Returns whether the state
    was either (the object is dealt with)."""
    name = obj.name_full
    if obj.mode == "EDIT":
        shown = _entered.get(name)
        if shown is not None and _edit_mesh_shows(obj, shown):
            show_rest(obj)
        if b is None:
            _pending.add(name)
        else:
            b.editing = True
        return True
    _pending.discard(name)
    edited = _left.get(name)
    if edited is None or not np.array_equal(mesh_helpers.rest_coordinates(obj.data), edited):
        return False
    if np.array_equal(mesh_helpers.saved_rest(obj.data), edited):
        return False
    leave(obj)
    return True


def clear():
    """Another file loaded."""
    _pending.clear()
    _entered.clear()
    _left.clear()
