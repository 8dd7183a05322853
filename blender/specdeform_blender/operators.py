"""Bind, Unbind, Apply, and the depsgraph handler that makes a bound mesh follow its target."""

import os
import threading
import time
from dataclasses import dataclass, field

import bpy
import numpy as np
from mathutils import Matrix

from . import library, mesh_helpers


@dataclass
class Binding:
    """What a bound object keeps in memory (not saved: reopening a .blend asks for Bind)."""

    deformer: object
    rest: np.ndarray  # float32 (n, 3): the input, every vertex
    used: np.ndarray  # the vertices the faces use, in the deformer's numbering
    last: np.ndarray = None  # the transforms last solved for
    status: dict = field(default_factory=dict)


_bindings = {}  # Object.name_full -> Binding (a renamed object asks for Bind again)


def binding(obj):
    return _bindings.get(obj.name_full)


@bpy.app.handlers.persistent
def forget_bindings(*_):
    _bindings.clear()


def _targets(obj):
    """One target per handle group (read each time: undo replaces the objects)."""
    return [obj.specdeform.target]


def _local_transforms(obj):
    """Each target's transform since binding, in the object's local space: moving the object
    and its target together leaves the mesh as it is (as a Hook modifier does)."""
    in_target = Matrix(np.reshape(obj.specdeform.bound_matrix, (4, 4)).tolist())
    to_local = obj.matrix_world.inverted()
    return np.array([to_local @ t.matrix_world @ in_target for t in _targets(obj)])


def _update(obj, b):
    transforms = _local_transforms(obj)
    if b.last is not None and np.array_equal(transforms, b.last):
        return
    start = time.perf_counter()
    X = b.deformer.solve(list(transforms))
    solved = time.perf_counter()
    co = b.rest.copy()
    co[b.used] = X
    b.last = transforms  # before writing: the write triggers this handler again
    mesh_helpers.set_coordinates(obj.data, co)
    b.status["iterations"] = b.deformer.report.get("iterations", 0)
    b.status["solve_ms"] = 1e3 * (solved - start)
    b.status["write_ms"] = 1e3 * (time.perf_counter() - solved)


@bpy.app.handlers.persistent
def follow_targets(scene, _depsgraph):
    for obj in scene.objects:
        b = _bindings.get(obj.name_full) if obj.type == "MESH" else None
        if b is None or not obj.specdeform.bound or not all(_targets(obj)):
            continue
        if len(b.rest) != len(obj.data.vertices):  # another mesh under this name
            del _bindings[obj.name_full]
            continue
        try:
            _update(obj, b)
        except library.specdeform.Error as e:
            b.status["error"] = str(e)


def _bind(obj, context):
    """Binds `obj` (its saved rest and target matrix when it is bound already). Returns an
    error message, or None."""
    s = obj.specdeform
    groups = obj.vertex_groups
    if not s.handle_group or s.handle_group not in groups:
        return f"no vertex group '{s.handle_group}' for the handle"
    if s.fixed_group and s.fixed_group not in groups:
        return f"no vertex group '{s.fixed_group}' for the fixed region"
    if s.target is None or s.target == obj:
        return "choose a target object (normally an Empty) other than the mesh"
    mesh = obj.data
    if mesh.shape_keys is not None:
        return "the mesh has shape keys: apply or remove them first"
    rest = mesh_helpers.saved_rest(mesh) if s.bound else None
    if rest is None:
        rest = mesh_helpers.coordinates(mesh)
    F = mesh_helpers.triangles(mesh)
    if len(F) == 0:
        return "the mesh has no faces"
    used, F = np.unique(F, return_inverse=True)  # loose vertices stay where they are
    F = F.reshape(-1, 3).astype(np.int32)
    renumber = np.full(len(rest), -1, np.int64)
    renumber[used] = np.arange(len(used))
    handle = renumber[mesh_helpers.group_members(obj, s.handle_group)]
    handle = handle[handle >= 0]
    if len(handle) == 0:
        return f"vertex group '{s.handle_group}' holds no vertex of a face"
    fixed = np.empty(0, np.int64)
    if s.fixed_group:
        fixed = renumber[mesh_helpers.group_members(obj, s.fixed_group)]
        fixed = fixed[fixed >= 0]
        if len(fixed) == 0:
            return f"vertex group '{s.fixed_group}' holds no vertex of a face"

    sd = library.specdeform
    V = rest[used].astype(np.float64)
    wm = context.window_manager
    main = threading.main_thread()

    def progress(fraction, _stage):
        if threading.current_thread() is main:
            wm.progress_update(int(100 * fraction))

    cache = library.cache_dir()
    os.makedirs(cache, exist_ok=True)
    start = time.perf_counter()
    wm.progress_begin(0, 100)
    try:
        evals, evecs = sd.manifold_harmonics(V, F, s.modes, cache=cache, progress=progress)
        basis_s = time.perf_counter() - start
        d = sd.SpectralDeformer(
            V,
            F,
            basis=(evals, evecs),
            energy=s.energy,
            detail=s.detail,
            constraint_weight=s.constraint_weight,
        )
        d.set_selection(handles=[handle], fixed=fixed)
    except sd.Error as e:
        return str(e)
    finally:
        wm.progress_end()
    h = evecs.base
    status = {
        "basis_s": basis_s,
        "bind_s": time.perf_counter() - start,
        "basis": f"{len(evals)} modes, residual {h.max_residual:.1e}"
        + ("" if h.converged else " (approximate)"),
    }
    b = Binding(d, rest, used, status=status)
    if not s.bound:  # the input stays as it is until the target moves
        mesh_helpers.save_rest(mesh, rest)
        in_target = s.target.matrix_world.inverted() @ obj.matrix_world
        s.bound_matrix = [x for row in in_target for x in row]
        s.bound = True
        b.last = _local_transforms(obj)
    _bindings[obj.name_full] = b
    _update(obj, b)
    return None


def _poll_mesh(context):
    obj = context.object
    return library.specdeform is not None and obj is not None and obj.type == "MESH"


class SPECDEFORM_OT_bind(bpy.types.Operator):
    """Compute (or load from the cache) the mesh's harmonics and follow the target"""

    bl_idname = "specdeform.bind"
    bl_label = "Bind"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return _poll_mesh(context) and context.mode == "OBJECT"

    def execute(self, context):
        error = _bind(context.object, context)
        if error:
            self.report({"ERROR"}, error)
            return {"CANCELLED"}
        return {"FINISHED"}


class SPECDEFORM_OT_unbind(bpy.types.Operator):
    """Stop following the target and restore the input mesh"""

    bl_idname = "specdeform.unbind"
    bl_label = "Unbind"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return _poll_mesh(context) and context.object.specdeform.bound

    def execute(self, context):
        obj = context.object
        rest = mesh_helpers.saved_rest(obj.data)
        if rest is None:
            self.report({"ERROR"}, "the input coordinates are gone (the mesh was edited)")
            return {"CANCELLED"}
        _release(obj)
        mesh_helpers.set_coordinates(obj.data, rest)
        return {"FINISHED"}


class SPECDEFORM_OT_apply(bpy.types.Operator):
    """Keep the deformed mesh as the mesh's own coordinates and stop following the target"""

    bl_idname = "specdeform.apply"
    bl_label = "Apply"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return _poll_mesh(context) and context.object.specdeform.bound

    def execute(self, context):
        _release(context.object)
        return {"FINISHED"}


def _release(obj):
    _bindings.pop(obj.name_full, None)
    obj.specdeform.bound = False
    mesh_helpers.drop_rest(obj.data)
