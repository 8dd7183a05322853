"""A bound object: its settings checked, the deformer Bind made (preparing.py) attached to it, and
the mesh following its targets (update)."""

import contextlib
import functools
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
    written: bool = False  # the mesh shows what the add-on wrote last (checked before writing)
    keys: tuple = ()  # the names of the mesh's shape keys when last looked at
    status: dict = field(default_factory=dict)


class ChangedOutside(Exception):
    """The mesh no longer shows what the add-on wrote last: something else changed its
    coordinates (a modifier applied that keeps the vertex count, Apply Scale, Sculpt Mode)."""


_bindings = {}  # Object.name_full -> Binding (a renamed object is bound again from the file)
problems = {}  # Object.name_full -> why a bound object has no binding (one line)
notices = {}  # Object.name_full -> what the add-on did on its own (unbound, one line)
jobs = set()  # preparing.BindJobs whose thread still runs (binding, or saving the cache)


def binding(obj):
    """The object's binding while its settings say bound (undo past Bind leaves one in memory)."""
    return _bindings.get(obj.name_full) if obj.specdeform.bound else None


def forget(obj):
    """The object's binding dropped (bound again next)."""
    _bindings.pop(obj.name_full, None)


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
    for job in list(jobs):
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
    except ChangedOutside:
        release_changed(obj)
    return None


def _finish_later_once(obj, b, first_interval):
    if not b.finishing:
        b.finishing = True
        bpy.app.timers.register(functools.partial(_finish_later, obj.name_full),
                                first_interval=first_interval)


def finish(obj):
    """The mesh with the full details of its pose (Apply, Bake Pose): waits for the transfer
    where it is being factored and solves again where the mesh shows displacements."""
    b = binding(obj)
    if b is not None and not b.exact:
        try:
            update(obj, b, full=True)
        except ChangedOutside:
            release_changed(obj)


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
    same = b.last is not None and np.array_equal(transforms, b.last) and (b.exact or not final)
    if not s.enabled or same:  # disabled: the rest, solved again once enabled if targets moved
        if b.mix != mix:
            _check_untouched(obj, b)
            b.mix = mix
            _write(obj, b)
        return
    _check_untouched(obj, b)
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
        _finish_later_once(obj, b, 0.2 if pending else SETTLE_S)
    st["iterations"] = b.deformer.report.get("iterations", 0)
    st["solve_ms"] = 1e3 * (solved - start)
    st["quick"] = quick
    st["write_ms"] = 1e3 * (time.perf_counter() - solved)


def _shown(b):
    """What the mix asks the mesh to show: the rest (disabled), the pose, or rest + strength x
    (pose - rest)."""
    enabled, strength = b.mix
    if not enabled:
        return b.rest
    if strength == 1.0:
        return b.positions
    return b.rest + np.float32(strength) * (b.positions - b.rest)


def _write(obj, b):
    mesh_helpers.show(obj.data, _shown(b))
    b.written = True


def _check_untouched(obj, b):
    """Before writing: ChangedOutside where the mesh no longer shows what was written last
    (the pose would overwrite the change)."""
    if b.written and not np.array_equal(mesh_helpers.shown(obj.data), _shown(b)):
        raise ChangedOutside


def leave_pose_out_of_new_keys(obj, b):
    """Shape keys added to a bound mesh never apply its pose twice. The first keys of a mesh bound
    without any: Blender made the Basis of the pose shown, which is set back to the rest, and the
    pose moves into the add-on's own key. New Shape from Mix takes every key's offset, the pose's
    included, into the new key: a key new since the mesh was last looked at that holds the mix
    (to float rounding) gets the pose's offset taken out again, holding the artist's keys mixed
    over the rest; a key made otherwise (the Basis copied, a script's) is left as it is. The
    panel says what was done (Bake Pose keeps a pose as a key)."""
    mesh = obj.data
    keys = mesh.shape_keys
    names = mesh_helpers.key_names(mesh)
    if names == b.keys:
        return
    known, b.keys = b.keys, names
    if keys is None:
        return
    if not known:
        keys.reference_key.data.foreach_set("co", b.rest.ravel())
        mesh_helpers.set_coordinates(mesh, b.rest)
        mesh_helpers.add_pose_key(obj)
        b.keys = mesh_helpers.key_names(mesh)
        _write(obj, b)
        b.status["note"] = ("Shape keys added while bound: the Basis is the rest shape, the pose "
                            f"the add-on's key '{mesh_helpers.POSE_KEY}'")
    ours = mesh_helpers.pose_key(mesh)
    mix = mesh_helpers.relative_mix(obj)
    if ours is None or ours.mute or mix is None:
        return
    offset = np.float32(ours.value) * (mesh_helpers.key_coordinates(ours)
                                       - mesh_helpers.key_coordinates(ours.relative_key))
    tolerance = 1e-5 * (1 + float(np.abs(mix).max()))
    if np.abs(offset).max() <= tolerance:
        return
    for key in keys.key_blocks:
        if key.name in known or key in (ours, keys.reference_key):
            continue
        co = mesh_helpers.key_coordinates(key)
        if np.abs(co - mix).max() <= tolerance:
            key.data.foreach_set("co", (co - offset).ravel())
            mesh.update()
            b.status["note"] = (f"New Shape from Mix: '{key.name}' holds your keys mixed over "
                                "the rest, without the specdeform pose (Bake Pose keeps the pose "
                                "as a key)")


def release_changed(obj, why=None):
    """A bound mesh that no longer fits its binding, which shows a pose already: unbound, the
    shape shown kept (binding again from it would pose it twice), `why` said in the panel."""
    why = why or ("the mesh's shape was changed outside Edit Mode (a modifier applied, Apply "
                  "Scale, Sculpt Mode)")
    release(obj)
    notices[obj.name_full] = f"Unbound: {why}; it keeps the shape shown. Bind to deform it again"


def hold_targets(obj):
    """Bind begins: each handle's object-in-target matrix, which makes the targets' transforms
    since then (local_transforms) the pose; moving a target while Bind runs poses the mesh once
    it is bound."""
    for _, target, owner in handles(obj):
        in_target = target.matrix_world.inverted() @ obj.matrix_world
        owner.bound_matrix = [x for row in in_target for x in row]


def check(obj):
    """Why the settings cannot be bound, or None: each line names the panel's field to fix."""
    s, groups = obj.specdeform, obj.vertex_groups
    for i, ((group, target, _), label) in enumerate(zip(handles(obj), fields(obj))):
        if not group:
            if len(groups) == 0:
                return (f"{label}: the mesh has no vertex groups; add one with the vertices to "
                        "move (Object Data properties, Vertex Groups) and pick it")
            return f"{label}: pick the vertex group to move"
        if group not in groups:
            return f"{label}: this mesh has no vertex group '{group}'"
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


def levels(h, indices, weights):
    """The handle's vertices split by weight (rounded to WEIGHT_STEP, at least one step)."""
    rounded = np.maximum(np.round(weights / WEIGHT_STEP), 1) * WEIGHT_STEP
    return [(indices[rounded == w], (h, float(w))) for w in np.unique(rounded)]


def shared(names, fields, members):
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


def fields(obj):
    """The panel's name of each handle's field, then the fixed group's."""
    return ["Handle"] + [f"More handles, row {i}" for i in range(1, len(handles(obj)))] + ["Fixed"]


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


def attach(obj, r, job, seconds, keep_shown=False):
    """Binds `obj` to the deformer `job` built (`seconds` since Bind began) and poses it (a pose
    the deformer refuses is said in the status). `keep_shown`: the mesh shows the pose of its
    targets as they were when Bind began (a file reopened, the object renamed); if they did not
    move since, that pose stays: as it is where it carries the full details (saved_full: the
    file's pose bit for bit, never solved again), else until the full details are ready, rather
    than displacements meanwhile."""
    s = obj.specdeform
    evals, evecs = job.result
    status = {"basis_s": job.basis_seconds, "bind_s": seconds,
              "basis": _basis_line(evals, evecs.base)}
    # All vertices in faces: a slice, which numpy writes ten times faster than an index array.
    used = slice(None) if len(r.used) == len(r.rest) else r.used
    b = Binding(job.deformer, r.rest, used, r.levels, positions=r.rest.copy(), status=status)
    if not s.bound:  # the input stays as it is until a target moves (since Bind began)
        mesh_helpers.save_rest(obj.data, r.rest)
        mesh_helpers.add_pose_key(obj)
        s.bound = True
        b.last, b.written = r.transforms, True
    elif keep_shown and s.enabled and s.strength == 1.0 and np.array_equal(
            local_transforms(obj), r.transforms):
        b.positions = mesh_helpers.shown(obj.data)
        b.last, b.exact, b.written = r.transforms, s.saved_full, True
        if not b.exact:
            _finish_later_once(obj, b, 0.2)
    b.keys = mesh_helpers.key_names(obj.data)
    _bindings[obj.name_full] = b
    notices.pop(obj.name_full, None)
    problems.pop(obj.name_full, None)
    try:
        update(obj, b)
    except library.specdeform.Error as e:
        b.status["error"] = str(e)


def release(obj):
    """Stops following: the binding forgotten, the saved rest dropped."""
    _bindings.pop(obj.name_full, None)
    problems.pop(obj.name_full, None)
    obj.specdeform.bound = False
    mesh_helpers.drop_rest(obj.data)
