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
    b.status.pop("error", None)
    b.status["iterations"] = b.deformer.report.get("iterations", 0)
    b.status["solve_ms"] = 1e3 * (solved - start)
    b.status["write_ms"] = 1e3 * (time.perf_counter() - solved)


@bpy.app.handlers.persistent
def follow_targets(scene, _depsgraph):
    for obj in scene.objects:
        b = _bindings.get(obj.name_full) if obj.type == "MESH" else None
        if b is None or not obj.specdeform.bound or obj.mode == "EDIT" or not all(_targets(obj)):
            continue
        if len(b.rest) != len(obj.data.vertices):  # another mesh under this name
            del _bindings[obj.name_full]
            continue
        try:
            _update(obj, b)
        except library.specdeform.Error as e:
            b.status["error"] = str(e)


@dataclass
class Request:
    """What Bind reads from the object and its settings before the basis is computed."""

    rest: np.ndarray
    used: np.ndarray
    V: np.ndarray
    F: np.ndarray
    handle: np.ndarray
    fixed: np.ndarray
    modes: int


def _request(obj):
    """Bind's input from `obj` (its saved rest when it is bound already), or an error message."""
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
    renumber = np.full(len(rest), -1, np.int64)
    renumber[used] = np.arange(len(used))
    members = {}
    for name in filter(None, (s.handle_group, s.fixed_group)):
        members[name] = renumber[mesh_helpers.group_members(obj, name)]
        members[name] = members[name][members[name] >= 0]
        if len(members[name]) == 0:
            return f"vertex group '{name}' holds no vertex of a face"
    return Request(rest, used, rest[used].astype(np.float64), F.reshape(-1, 3).astype(np.int32),
                   members[s.handle_group], members.get(s.fixed_group, np.empty(0, np.int64)),
                   s.modes)


class _Cancelled(Exception):
    pass


class BasisJob:
    """A Request's basis computed, or loaded from the cache, on a worker thread (the module
    releases the GIL); cancel() stops it at the solver's next progress report."""

    def __init__(self, request):
        self.fraction, self.result, self.error, self.seconds = 0.0, None, None, 0.0
        self._cancel = threading.Event()
        self._thread = threading.Thread(target=self._run, args=(request,), daemon=True)
        self._thread.start()

    def _progress(self, fraction, _stage):
        if self._cancel.is_set():
            raise _Cancelled
        self.fraction = fraction

    def _run(self, r):
        start = time.perf_counter()
        try:
            os.makedirs(library.cache_dir(), exist_ok=True)
            self.result = library.specdeform.manifold_harmonics(
                r.V, r.F, r.modes, cache=library.cache_dir(), progress=self._progress
            )
        except _Cancelled:
            self.error = "cancelled"
        except (library.specdeform.Error, OSError) as e:
            self.error = str(e)
        self.seconds = time.perf_counter() - start

    def cancel(self):
        self._cancel.set()

    def join(self):
        self._thread.join()
        return self

    @property
    def done(self):
        return not self._thread.is_alive()


def _finish(obj, r, job):
    """Binds `obj` to the basis `job` computed. Returns an error message, or None."""
    if job.error:
        return f"bind: {job.error}"
    s = obj.specdeform
    sd = library.specdeform
    start = time.perf_counter()
    evals, evecs = job.result
    try:
        d = sd.SpectralDeformer(
            r.V,
            r.F,
            basis=(evals, evecs),
            energy=s.energy,
            detail=s.detail,
            unconstrained=s.unconstrained,
            constraint_weight=s.constraint_weight,
        )
        d.set_selection(handles=[r.handle], fixed=r.fixed)
    except sd.Error as e:
        return str(e)
    h = evecs.base
    status = {
        "basis_s": job.seconds,
        "bind_s": job.seconds + time.perf_counter() - start,
        "basis": f"{len(evals)} modes" + ("" if h.converged else ", approximate"),
        "residual": h.max_residual,
    }
    b = Binding(d, r.rest, r.used, status=status)
    if not s.bound:  # the input stays as it is until the target moves
        mesh_helpers.save_rest(obj.data, r.rest)
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
        r = _request(context.object)
        error = r if isinstance(r, str) else _finish(context.object, r, BasisJob(r).join())
        return self._done(error)

    def invoke(self, context, _event):
        """From the panel: the basis on a worker thread, progress in the status bar, Esc to
        cancel."""
        self.obj = context.object
        self.r = _request(self.obj)
        if isinstance(self.r, str):
            return self._done(self.r)
        self.job = BasisJob(self.r)
        wm = context.window_manager
        wm.progress_begin(0, 100)
        self.timer = wm.event_timer_add(0.1, window=context.window)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC":
            self.job.cancel()
        if event.type != "TIMER":
            return {"RUNNING_MODAL"}
        wm = context.window_manager
        wm.progress_update(int(100 * self.job.fraction))
        context.workspace.status_text_set(
            f"specdeform: basis {100 * self.job.fraction:.0f}% (Esc cancels)"
        )
        if not self.job.done:
            return {"RUNNING_MODAL"}
        wm.event_timer_remove(self.timer)
        wm.progress_end()
        context.workspace.status_text_set(None)
        return self._done(_finish(self.obj, self.r, self.job))

    def _done(self, error):
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
