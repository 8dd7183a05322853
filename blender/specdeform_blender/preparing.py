"""Bind's pipeline in steps, so that Bind, a file reopened and Edit Mode left never hold the
window: Blender's main thread does what only it may (the settings, the rest and the faces in a
few bulk reads, the vertex groups' weights in steps of at most STEP_S whatever else runs on the
machine, then attaching the deformer to the object), and a worker thread the rest (the faces
triangulated, the mesh renumbered, the basis computed or loaded from the cache, the selection
checked, the deformer built). `steps()` is a generator that yields between the main thread's
steps; a timer drives it in a window (tasks.py), `bind_now()` at once (scripts, `blender -b`,
renders)."""

import os
import threading
import time
from dataclasses import dataclass

import numpy as np

from . import binding, library, mesh_helpers, triangulation

# The main thread's steps end once they have run this long: the vertex groups are read a chunk at
# a time (a Python loop: Blender 3.4 has no bulk access to them), chunks sized by the time the
# last one took.
STEP_S = 0.1
GROUP_CHUNK = 4_000  # the first chunk of vertices (about 7 ms idle); then a quarter step each
CANCELLED = "bind: cancelled"
CHANGED = "Object Data: the mesh changed while it was being bound; press Bind again"


@dataclass
class Request:
    """What Bind reads from the object on the main thread (rest, triangles, settings, vertex
    groups), and what the worker thread makes of it in the deformer's numbering."""

    rest: np.ndarray  # float32 (n, 3), every vertex
    faces: tuple  # mesh_helpers.polygons: the corners of each face and their vertices
    modes: int
    eigensolver: str
    options: dict  # the deformer's keywords
    names: list  # the vertex group of each handle, then the fixed group's (if any)
    fields: list  # the panel's field of each of `names`
    fixed: bool  # the last of `names` is the fixed group
    transforms: np.ndarray  # the targets' (binding.local_transforms) as Bind began
    weights: dict = None  # name -> (vertex indices, weights), Blender's numbering
    # Made by the worker thread:
    triangles: np.ndarray = None  # int32 (f, 3), Blender's numbering
    used: np.ndarray = None  # the vertices the faces use
    renumber: np.ndarray = None  # each vertex's index in the deformer's numbering (-1: in no face)
    V: np.ndarray = None  # float64 (m, 3): the used vertices' rest
    F: np.ndarray = None  # int32 (f, 3): the triangles in the deformer's numbering
    groups: list = None  # vertex indices (deformer's numbering) of each handle group of the scene
    levels: list = None  # (handle, weight) of each
    fixed_vertices: np.ndarray = None


def request(obj):
    """Bind's settings, rest, faces and targets from `obj` (its saved rest when it is bound
    already; on a first Bind the targets are held as they are now, binding.hold_targets), or an
    error message; the vertex groups are read by the next steps."""
    s = obj.specdeform
    problem = binding.check(obj)
    if problem:
        return problem
    rest = _rest(obj)
    names = [group for group, _, _ in binding.handles(obj)] + [s.fixed_group] * bool(s.fixed_group)
    options = {"energy": s.energy, "detail": s.detail, "unconstrained": s.unconstrained,
               "constraint_weight": s.constraint_weight}
    if not s.bound:
        binding.hold_targets(obj)
    return Request(rest, mesh_helpers.polygons(obj.data), s.modes, s.eigensolver, options, names,
                   binding.fields(obj)[:len(names)], bool(s.fixed_group),
                   binding.local_transforms(obj))


def _rest(obj):
    """The rest Bind starts from: the one saved when the object was bound (binding it again), or
    the mesh's own."""
    rest = mesh_helpers.saved_rest(obj.data) if obj.specdeform.bound else None
    return mesh_helpers.rest_coordinates(obj.data) if rest is None else rest


def _group_weights(obj, names):
    """Generator: the weights of the vertex groups `names` (mesh_helpers.add_group_weights), in
    steps of about STEP_S; each resumption passes the object again (an undo replaces it).
    Returns the object as last passed and the weights, or an error message."""
    n = len(obj.data.vertices)
    index = {obj.vertex_groups[name].index: name for name in names}
    found = {name: ([], []) for name in names}
    start, chunk = 0, GROUP_CHUNK
    while start < n:
        if len(obj.data.vertices) != n:
            return obj, CHANGED
        began = time.perf_counter()
        while start < n and time.perf_counter() - began < STEP_S:
            stop = min(n, start + chunk)
            chunk_began = time.perf_counter()
            mesh_helpers.add_group_weights(obj.data.vertices[start:stop], index, found)
            per_vertex = (time.perf_counter() - chunk_began) / (stop - start)
            chunk = max(100, int(0.25 * STEP_S / max(per_vertex, 1e-9)))  # a quarter step
            start = stop
        obj = yield "reading the vertex groups", start / n
    return obj, {name: (np.array(i, np.int64), np.array(w)) for name, (i, w) in found.items()}


def _renumber(r):
    """The deformer's numbering: the vertices the faces use (loose ones stay put); an error
    message, or None."""
    r.triangles = triangulation.triangulate(*r.faces, r.rest)
    used = np.flatnonzero(np.bincount(r.triangles.ravel(), minlength=len(r.rest)))
    if r.modes > len(used):
        return f"Modes is {r.modes}, more than the mesh's {len(used)} vertices: lower Modes"
    r.used = used
    r.renumber = np.full(len(r.rest), -1, np.int64)
    r.renumber[used] = np.arange(len(used))
    return None


def _select(r, handle_count):
    """The request's handle groups split by their weights' levels and the fixed vertices, in the
    deformer's numbering; an error message, or None."""
    members = {}
    for name, (indices, w) in r.weights.items():
        keep = r.renumber[indices] >= 0
        if not keep.any():
            field = r.fields[r.names.index(name)]
            return f"{field}: vertex group '{name}' holds no vertex of a face"
        members[name] = (r.renumber[indices][keep], w[keep])
    problem = binding.shared(r.names, r.fields, members)
    if problem:
        return problem
    split = [x for h in range(handle_count) for x in binding.levels(h, *members[r.names[h]])]
    r.groups, r.levels = [g for g, _ in split], [level for _, level in split]
    r.fixed_vertices = members[r.names[-1]][0] if r.fixed else np.empty(0, np.int64)
    return None


class _Cancelled(Exception):
    pass


class BindJob:
    """The worker thread of one Bind: the request renumbered, its basis computed or loaded from
    the cache (the module releases the GIL), then, once the main thread has read the vertex
    groups (selected()), the selection checked and the deformer built. cancel() stops it at the
    solver's next progress report or between stages; the caller does not wait for that (a
    deformer being built is finished and dropped). A computed basis is saved in the cache after
    `done` (`saving`; 553 MB at 692k vertices, seconds that Bind does not wait for)."""

    def __init__(self, request, handle_count):
        self.fraction, self.stage, self.basis_done = 0.0, "starting", False
        self.result = self.deformer = self.error = None
        self.start, self.basis_seconds = time.perf_counter(), 0.0
        self.saving = False
        self._cancel, self._selected, self._done = (threading.Event(), threading.Event(),
                                                    threading.Event())
        self._thread = threading.Thread(target=self._run, args=(request, handle_count),
                                        daemon=True)
        binding.jobs.add(self)
        self._thread.start()

    def _progress(self, fraction, stage):
        if self._cancel.is_set():
            raise _Cancelled
        self.fraction, self.stage = fraction, stage

    def _basis(self, r, file):
        sd = library.specdeform
        cached = os.path.exists(file)
        self.result = sd.manifold_harmonics(
            r.V, r.F, r.modes, cache=file if cached else None, eigensolver=r.eigensolver,
            progress=self._progress)
        self.basis_seconds = time.perf_counter() - self.start
        self.basis_done = True  # the stages after it are said without "basis:"
        self.saving = not cached and self.result[1].base.converged

    def _deformer(self, r):
        sd = library.specdeform
        self._progress(1.0, "building the deformer")
        d = sd.SpectralDeformer(
            r.V, r.F, basis=self.result, **r.options,
            background_transfer=True,  # the details as displacements until it is factored
            float32_basis=True,  # Blender's coordinates are float32: half the inverse transform
        )
        d.set_selection(handles=r.groups, fixed=r.fixed_vertices)
        self._progress(1.0, "posing")
        return d

    def _run(self, r, handle_count):
        sd = library.specdeform
        file = None
        try:
            self.error = _renumber(r)
            if self.error is None:
                r.V = r.rest[r.used].astype(np.float64)
                r.F = r.renumber[r.triangles].astype(np.int32)
                os.makedirs(library.cache_dir(), exist_ok=True)
                file = sd.basis_cache_file(r.V, r.F, r.modes, cache=library.cache_dir(),
                                           eigensolver=r.eigensolver)
                self._basis(r, file)
                while not self._selected.is_set():
                    self._progress(1.0, "reading the vertex groups")
                    self._selected.wait(0.05)
                self.error = _select(r, handle_count) if r.weights is not None else CANCELLED
            if self.error is None:
                self.deformer = self._deformer(r)
        except _Cancelled:
            self.error = CANCELLED
        except Exception as e:  # said in the panel; Bind never waits for a thread that died
            self.error = f"bind: {e}"
        finally:
            self.saving = self.saving and not self._cancel.is_set()  # a cancel leaves nothing
            self._done.set()
        if self.saving:
            if hasattr(os, "setpriority"):  # the lowest priority: Bind and Blender keep the cores
                os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), 19)
            try:
                sd.save_basis(file, self.result, r.V, r.F)
            except (sd.Error, OSError) as e:
                print(f"specdeform: warning: basis not cached: {e}")
            self.saving = False
        binding.jobs.discard(self)

    def selected(self):
        """The main thread has read the vertex groups (or given up: request.weights None)."""
        self._selected.set()

    def cancel(self):
        self._cancel.set()
        self._selected.set()

    def join(self, timeout=None):
        self._done.wait(timeout)
        return self

    @property
    def done(self):
        return self._done.is_set()

    def progress_text(self):
        """'basis: <stage> 40%, about 12 s left' (the estimate once a tenth is done)."""
        if self.basis_done:
            return self.stage
        elapsed = time.perf_counter() - self.start
        text = f"basis: {self.stage} {100 * self.fraction:.0f}%"
        if self.fraction >= 0.1:
            text += f", about {elapsed * (1 - self.fraction) / self.fraction:.0f} s left"
        return text


def steps(obj, keep_shown=False):
    """Bind's pipeline as a generator. Each `yield` ends a main-thread step with what is being
    done (the stage and the fraction done) or the job being waited for; the driver resumes it
    with the object looked up again (`send(obj)`) and closes it to cancel. keep_shown: see
    binding.attach. Returns an error message, or None."""
    started = time.perf_counter()
    r = request(obj)
    if isinstance(r, str):
        return r
    if len(r.faces[0]) == 0:
        return "Object Data: the mesh has no faces"
    job = BindJob(r, len(binding.handles(obj)))
    try:
        obj = yield "reading the vertex groups", 0.0
        obj, weights = yield from _group_weights(obj, r.names)
        if isinstance(weights, str):
            return weights
        r.weights = weights
        job.selected()
        while not job.done:
            obj = yield job
    finally:
        if not job.done:  # closed (cancelled) or failed: the thread stops at its next report
            job.cancel()
    if job.error:
        return job.error
    if len(obj.data.vertices) != len(r.rest) or not np.array_equal(_rest(obj), r.rest):
        return CHANGED  # an undo, say
    binding.attach(obj, r, job, time.perf_counter() - started, keep_shown)
    return None


def bind_now(obj, report=None, keep_shown=False):
    """Bind's whole pipeline at once (scripts, `blender -b`, renders); report(text) is called
    every second while the worker runs. Returns an error message, or None."""
    pipeline = steps(obj, keep_shown)
    try:
        waiting = next(pipeline)
        while True:
            if isinstance(waiting, BindJob):
                waiting.join(1.0)
                if report and not waiting.done:
                    report(waiting.progress_text())
            waiting = pipeline.send(obj)
    except StopIteration as end:
        return end.value
