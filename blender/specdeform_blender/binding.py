"""A bound object: Bind's input read from the object (Request), its basis computed or loaded on a
worker thread (BasisJob), the deformer made from both (bind), and the mesh following its targets
(update)."""

import contextlib
import functools
import os
import threading
import time
from dataclasses import dataclass, field

import bpy
import numpy as np
from mathutils import Matrix

from . import library, mesh_helpers

WEIGHT_STEP = 0.01  # handle weights are rounded to this: each level is one group of the scene
QUICK_ABOVE_MS = 50.0  # Quick drags: where a full update takes longer than this
SETTLE_S = 0.25  # the full details once the targets rested this long


@dataclass
class Binding:
    """What a bound object keeps in memory (remade from the file by the load handler)."""

    deformer: object
    rest: np.ndarray  # float32 (n, 3): the input, every vertex
    used: object  # the vertices the faces use, in the deformer's numbering (or all: a slice)
    levels: list  # (handle, weight) of each of the deformer's handle groups
    positions: np.ndarray = None  # float32 (n, 3): the pose (written as Strength mixes it)
    last: np.ndarray = None  # the transforms last solved for
    mix: tuple = (True, 1.0)  # Enabled and Strength last written
    editing: bool = False  # in Edit Mode: the mesh shows its rest shape
    exact: bool = True  # the mesh shows the full details (not displacements meanwhile)
    full_ms: float = 0.0  # the last update with the full details took this long
    moved: float = 0.0  # time of the last update shown with displacements
    finishing: bool = False  # the timer that solves again with the full details is registered
    status: dict = field(default_factory=dict)


_bindings = {}  # Object.name_full -> Binding (a renamed object is bound again from the file)
problems = {}  # Object.name_full -> why a bound object has no binding (one line)
notices = {}  # Object.name_full -> what the add-on did on its own (unbound, one line)
_jobs = set()  # BasisJobs whose thread still runs (computing, or saving the cache)


def binding(obj):
    """The object's binding while its settings say bound (undo past Bind leaves one in memory)."""
    return _bindings.get(obj.name_full) if obj.specdeform.bound else None


def forget_all():
    _bindings.clear()
    problems.clear()
    notices.clear()


def shutdown():
    """At exit (atexit) and when the add-on is disabled (Blender disables every add-on as it
    quits, before Python's atexit): the cache files being saved written, the bases being computed
    cancelled, and the deformers, with their background threads, released while Python and the
    library are still whole. A worker thread still inside the library when Python finalises is
    ended mid-call, which aborts Blender ("terminate called without an active exception", seen
    after a test's Bind whose basis was still being saved)."""
    for job in list(_jobs):
        job.cancel()
        job._thread.join()
    forget_all()


def handles(obj):
    """(vertex group, target, owner of bound_matrix) of each handle: the first is the settings'
    own handle_group and target, then the list's (read each time: undo replaces the objects)."""
    s = obj.specdeform
    return [(s.handle_group, s.target, s)] + [(h.group, h.target, h) for h in s.handles]


def local_transforms(obj, depsgraph=None):
    """Each target's transform since binding, in the object's local space: moving the object
    and its targets together leaves the mesh as it is (as a Hook modifier does). With a
    depsgraph, the matrices it evaluated (a render's at its frame)."""
    seen = (lambda o: o.evaluated_get(depsgraph)) if depsgraph else (lambda o: o)
    to_local = seen(obj).matrix_world.inverted()
    return np.array(
        [
            to_local @ seen(t).matrix_world @ Matrix(np.reshape(m.bound_matrix, (4, 4)).tolist())
            for _, t, m in handles(obj)
        ]
    )


def blend(transforms, levels):
    """Hook's weights: weight w takes a vertex to rest + w (T rest - rest), ((1-w) I + w T) rest."""
    return [(1 - w) * np.eye(4) + w * transforms[h] for h, w in levels]


_final = 0  # inside final_frames()


@contextlib.contextmanager
def final_frames():
    """Every frame solved inside carries the full details (Bake's frames)."""
    global _final
    _final += 1
    try:
        yield
    finally:
        _final -= 1


def _must_be_final():
    """Whether a frame must carry the full details (a render, a background process, a bake)
    rather than the displacements shown meanwhile in the window."""
    running = getattr(bpy.app, "is_job_running", lambda _: False)
    return _final > 0 or bpy.app.background or running("RENDER")


def _finish_later(name):
    """A timer: the pose of `name`'s binding, shown with its details as displacements (the
    transfer was being factored, or a quick drag), solved again with the full details once the
    transfer is ready and the targets rested for SETTLE_S."""
    obj, b = bpy.data.objects.get(name), _bindings.get(name)
    if obj is None or b is None:
        return None
    try:
        if b.deformer.detail_pending:
            return 0.2
        wait = SETTLE_S - (time.perf_counter() - b.moved)
        if wait > 0:
            return wait
        b.finishing = False
        if not b.exact:
            update(obj, b, full=True)
    except library.specdeform.Error as e:  # a singular Poisson system, say
        b.finishing = False
        b.status["error"] = str(e)
    return None


def finish(obj):
    """The mesh with the full details of its pose (Apply, Bake Pose): waits for the transfer
    where it is being factored and solves again where the mesh shows displacements."""
    b = binding(obj)
    if b is not None and not b.exact:
        update(obj, b, full=True)


def update(obj, b, depsgraph=None, full=False):
    """Solves for the targets' transforms and writes the positions, unless they did not move.
    In the window, where a full update is slow (over QUICK_ABOVE_MS) and Quick drags is on, a
    moving target's pose is shown with its details as displacements (the library's preview: no
    transfer) and solved in full once the targets rest; `full`, renders and bakes always solve
    in full."""
    transforms = local_transforms(obj, depsgraph)
    final = full or _must_be_final()
    s = obj.specdeform
    mix = (s.enabled, s.strength)
    if not s.enabled:  # the rest shown; solved again once enabled if the targets moved
        if b.mix != mix:
            b.mix = mix
            mesh_helpers.show(obj.data, b.rest)
        return
    if b.last is not None and np.array_equal(transforms, b.last) and (b.exact or not final):
        if b.mix != mix:
            b.mix = mix
            _write(obj, b)
        return
    start = time.perf_counter()
    T = blend(transforms, b.levels)
    pending = b.deformer.detail_pending
    if pending and final:
        b.deformer.wait_for_detail()
        pending = False
    quick = (not final and not pending and obj.specdeform.quick_drags
             and b.full_ms > QUICK_ABOVE_MS)
    if isinstance(b.used, slice):  # straight into the positions, no temporary
        (b.deformer.preview if quick else b.deformer.solve)(T, out=b.positions)
    else:
        b.positions[b.used] = b.deformer.preview(T) if quick else b.deformer.solve(T)
    solved = time.perf_counter()
    if not quick and not pending:
        b.full_ms = 1e3 * (solved - start)
    b.exact = not quick and not pending
    b.last, b.mix = transforms, mix  # before writing: the write triggers the handler again
    _write(obj, b)
    st = b.status
    st.pop("error", None)
    if quick:
        st["detail"] = "details as displacements while the target moves"
    elif pending:
        st["detail"] = "details as displacements until the transfer is ready"
    else:
        st.pop("detail", None)
    if not b.exact:
        b.moved = solved
        if not b.finishing:
            b.finishing = True
            bpy.app.timers.register(functools.partial(_finish_later, obj.name_full),
                                    first_interval=0.2 if pending else SETTLE_S)
    st["iterations"] = b.deformer.report.get("iterations", 0)
    st["solve_ms"] = 1e3 * (solved - start)
    st["quick"] = quick
    st["write_ms"] = 1e3 * (time.perf_counter() - solved)


def _write(obj, b):
    """The mesh's coordinates: the pose, or rest + strength x (pose - rest)."""
    strength = b.mix[1]
    if strength == 1.0:
        mesh_helpers.show(obj.data, b.positions)
    else:
        shown = b.rest + np.float32(strength) * (b.positions - b.rest)
        mesh_helpers.show(obj.data, shown)


@dataclass
class Request:
    """What Bind reads from the object and its settings: the mesh (request), then, while the
    worker computes the basis, the handles and fixed vertices (select)."""

    rest: np.ndarray
    used: np.ndarray
    renumber: np.ndarray  # each vertex's index in the deformer's numbering (-1: in no face)
    V: np.ndarray
    F: np.ndarray
    modes: int
    eigensolver: str
    groups: list = None  # vertex indices (deformer's numbering) of each handle group of the scene
    levels: list = None  # (handle, weight) of each
    fixed: np.ndarray = None


def _check(obj):
    """Why the settings cannot be bound, or None: each line names the panel's field to fix."""
    s, groups = obj.specdeform, obj.vertex_groups
    for i, ((group, target, _), field) in enumerate(zip(handles(obj), _fields(obj))):
        if not group:
            if len(groups) == 0:
                return (f"{field}: the mesh has no vertex groups; add one with the vertices to "
                        "move (Object Data properties, Vertex Groups) and pick it")
            return f"{field}: pick the vertex group to move"
        if group not in groups:
            return f"{field}: this mesh has no vertex group '{group}'"
        if target is None or target == obj:
            what = "Target" if i == 0 else f"More handles, row {i}, target"
            return (f"{what}: choose the object that moves the handle (normally an Empty), "
                    "not the mesh")
    if s.fixed_group and s.fixed_group not in groups:
        return f"Fixed: this mesh has no vertex group '{s.fixed_group}' (or leave Fixed empty)"
    if obj.data.users > 1:
        return (f"Object Data: the mesh '{obj.data.name}' is shared by {obj.data.users} objects "
                "(a linked duplicate); Object > Relation > Make Single User, then Bind")
    return None


def _levels(h, indices, weights):
    """The handle's vertices split by weight (rounded to WEIGHT_STEP, at least one step)."""
    rounded = np.maximum(np.round(weights / WEIGHT_STEP), 1) * WEIGHT_STEP
    return [(indices[rounded == w], (h, float(w))) for w in np.unique(rounded)]


def _shared(names, fields, members):
    """Two of the groups (handles, fixed) that share vertices, said in one line naming the
    field to change, or None."""
    for i, a in enumerate(names):
        for j in range(i + 1, len(names)):
            b = names[j]
            if a == b:
                return (f"{fields[j]}: vertex group '{a}' is used twice (also {fields[i]}): "
                        "each vertex follows one handle")
            if np.intersect1d(members[a][0], members[b][0]).size:
                return (f"{fields[j]}: vertex groups '{a}' and '{b}' share vertices: "
                        "each follows one handle")
    return None


def _fields(obj):
    """The panel's name of each handle's field, then the fixed group's."""
    return ["Handle"] + [f"More handles, row {i}" for i in range(1, len(handles(obj)))] + ["Fixed"]


def request(obj):
    """Bind's mesh from `obj` (its saved rest when it is bound already), or an error message."""
    s = obj.specdeform
    problem = _check(obj)
    if problem:
        return problem
    mesh = obj.data
    rest = mesh_helpers.saved_rest(mesh) if s.bound else None
    if rest is None:
        rest = mesh_helpers.rest_coordinates(mesh)
    F = mesh_helpers.triangles(mesh)
    if len(F) == 0:
        return "the mesh has no faces"
    used = np.flatnonzero(np.bincount(F.ravel(), minlength=len(rest)))  # loose ones stay put
    if s.modes > len(used):
        return f"Modes is {s.modes}, more than the mesh's {len(used)} vertices: lower Modes"
    renumber = np.full(len(rest), -1, np.int64)
    renumber[used] = np.arange(len(used))
    return Request(rest, used, renumber, rest[used].astype(np.float64),
                   renumber[F].astype(np.int32), s.modes, s.eigensolver)


def select(obj, r):
    """The request's handle groups, their weights' levels and the fixed vertices, from the vertex
    groups (read vertex by vertex: a third of a second at 692k vertices, which Bind spends while
    the worker computes the basis); an error message, or None."""
    s = obj.specdeform
    names = [group for group, _, _ in handles(obj)] + [s.fixed_group] * bool(s.fixed_group)
    fields = _fields(obj)[:len(names)]
    weights = mesh_helpers.group_weights(obj, set(names))
    members = {}
    for name, (indices, w) in weights.items():
        keep = r.renumber[indices] >= 0
        if not keep.any():
            return f"{fields[names.index(name)]}: vertex group '{name}' holds no vertex of a face"
        members[name] = (r.renumber[indices][keep], w[keep])
    problem = _shared(names, fields, members)
    if problem:
        return problem
    split = [x for h, (group, _, _) in enumerate(handles(obj)) for x in _levels(h, *members[group])]
    r.groups, r.levels = [g for g, _ in split], [level for _, level in split]
    r.fixed = members[s.fixed_group][0] if s.fixed_group else np.empty(0, np.int64)
    return None


def start(obj):
    """Bind's request and its basis job (started before the vertex groups are read), or an error
    message."""
    r = request(obj)
    if isinstance(r, str):
        return r
    job = BasisJob(r)
    problem = select(obj, r)
    if problem:
        job.cancel()
        return problem
    return r, job


class _Cancelled(Exception):
    pass


class BasisJob:
    """A Request's basis computed, or loaded from the cache, on a worker thread (the module
    releases the GIL); cancel() stops it at the solver's next progress report. A computed basis
    is done before it is saved in the cache: the thread saves it afterwards, while Bind goes on
    (`saving`; 553 MB at 692k vertices, seconds that Bind does not wait for)."""

    def __init__(self, request):
        self.fraction, self.stage, self.result, self.error = 0.0, "starting", None, None
        self.start, self.seconds = time.perf_counter(), 0.0
        self.saving = False
        self._cancel, self._done = threading.Event(), threading.Event()
        self._thread = threading.Thread(target=self._run, args=(request,), daemon=True)
        _jobs.add(self)
        self._thread.start()

    def _progress(self, fraction, stage):
        if self._cancel.is_set():
            raise _Cancelled
        self.fraction, self.stage = fraction, stage

    def _run(self, r):
        sd = library.specdeform
        try:
            os.makedirs(library.cache_dir(), exist_ok=True)
            file = sd.basis_cache_file(
                r.V, r.F, r.modes, cache=library.cache_dir(), eigensolver=r.eigensolver
            )
            cached = os.path.exists(file)
            self.result = sd.manifold_harmonics(
                r.V, r.F, r.modes, cache=file if cached else None, eigensolver=r.eigensolver,
                progress=self._progress,
            )
            self.saving = not cached and self.result[1].base.converged
        except _Cancelled:
            self.error = "cancelled"
        except Exception as e:  # said in the panel; Bind never waits for a thread that died
            self.error = str(e)
        finally:
            self.seconds = time.perf_counter() - self.start
            self._done.set()
        if self.saving:
            if hasattr(os, "setpriority"):  # the lowest priority: Bind and Blender keep the cores
                os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), 19)
            try:
                sd.save_basis(file, self.result, r.V, r.F)
            except (sd.Error, OSError) as e:
                print(f"specdeform: warning: basis not cached: {e}")
            self.saving = False
        _jobs.discard(self)

    def cancel(self):
        self._cancel.set()

    def join(self, timeout=None):
        self._done.wait(timeout)
        return self

    @property
    def done(self):
        return self._done.is_set()

    def progress_text(self):
        """'basis: <stage> 40%, about 12 s left' (the estimate once a tenth is done)."""
        elapsed = time.perf_counter() - self.start
        text = f"basis: {self.stage} {100 * self.fraction:.0f}%"
        if self.fraction >= 0.1:
            text += f", about {elapsed * (1 - self.fraction) / self.fraction:.0f} s left"
        return text


def _basis_line(evals, h):
    """The panel's line on the basis, in words: how good it is for deforming, and why it holds
    more modes than asked."""
    if h.approximate:
        line = f"Approximate basis (multilevel), {len(evals)} modes: fine for deformation"
    elif h.converged:
        line = f"Exact basis, {len(evals)} modes (residual {h.max_residual:.0e})"
    else:
        line = (f"Basis of {len(evals)} modes, not fully converged (residual "
                f"{h.max_residual:.0e}): fine for deformation")
    if len(evals) > h.requested_modes > 0:
        line += f"; {h.requested_modes} asked, more as each of {h.pieces} loose parts gets its own"
    return line


def bind(obj, r, job):
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
            background_transfer=True,  # the details as displacements until it is factored
            float32_basis=True,  # Blender's coordinates are float32: half the inverse transform
        )
        d.set_selection(handles=r.groups, fixed=r.fixed)
    except sd.Error as e:
        return str(e)
    h = evecs.base
    status = {
        "basis_s": job.seconds,
        "bind_s": job.seconds + time.perf_counter() - start,
        "basis": _basis_line(evals, h),
    }
    # All vertices in faces: a slice, which numpy writes ten times faster than an index array.
    used = slice(None) if len(r.used) == len(r.rest) else r.used
    b = Binding(d, r.rest, used, r.levels, positions=r.rest.copy(), status=status)
    if not s.bound:  # the input stays as it is until a target moves
        mesh_helpers.save_rest(obj.data, r.rest)
        mesh_helpers.add_pose_key(obj)
        for _, target, owner in handles(obj):
            in_target = target.matrix_world.inverted() @ obj.matrix_world
            owner.bound_matrix = [x for row in in_target for x in row]
        s.bound = True
        b.last = local_transforms(obj)
    _bindings[obj.name_full] = b
    notices.pop(obj.name_full, None)
    problems.pop(obj.name_full, None)
    update(obj, b)
    return None


def bind_now(obj, report=None):
    """Bind's whole pipeline on this thread (scripts, the load handler, leaving Edit Mode);
    report(text) is called every second with the progress. Returns an error message, or None."""
    started = start(obj)
    if isinstance(started, str):
        return started
    r, job = started
    while not job.done:
        job.join(1.0)
        if report and not job.done:
            report(job.progress_text())
    return bind(obj, r, job)


def release(obj):
    """Stops following: the binding forgotten, the saved rest dropped."""
    _bindings.pop(obj.name_full, None)
    problems.pop(obj.name_full, None)
    obj.specdeform.bound = False
    mesh_helpers.drop_rest(obj.data)
