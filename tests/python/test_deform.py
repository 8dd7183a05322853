"""SpectralDeformer and scenes: equal to `specdeform deform` on the same scene, the options, the
errors, and the basis it shares."""

import gc
import json
import subprocess
import threading
import weakref

import numpy as np
import pytest

import specdeform
from conftest import SHARED


def turn(degrees, center, shift=(0, 0, 0)):
    """4 x 4: a rotation about the z axis through `center`, then a translation."""
    a = np.radians(degrees)
    R = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = center - R @ center + shift
    return T


@pytest.fixture(scope="module")
def bar_scene(tmp_path_factory, bar):
    """The coarse bumpy bar in an OFF file with a Botsch-Sorkine scene: the last 15% along x is
    the handle, turned by 40 degrees and lifted; the first 15% is fixed."""
    V, F = bar
    folder = tmp_path_factory.mktemp("bar")
    specdeform.write_mesh(folder / "bar.off", V, F)
    status = np.ones(len(V), int)
    status[V[:, 0] < 0.6] = 0
    status[V[:, 0] > 3.4] = 2
    (folder / "bar.sel").write_text("# status\n" + "\n".join(map(str, status)) + "\n")
    T = turn(40, V[status == 2].mean(axis=0), (0, 0.3, 0))
    (folder / "bar.def").write_text("# transform\n" + "\n".join(" ".join(map(repr, r)) for r in T))
    return folder


def run_cli(cli, folder, *args):
    out = folder / "cli.off"
    subprocess.run([cli, "deform", *map(str, args), "-o", out], check=True, capture_output=True)
    return specdeform.read_mesh(out)[0]


def relative_difference(X, Y, V):
    return np.abs(X - Y).max() / np.linalg.norm(np.ptp(V, axis=0))


@pytest.mark.parametrize(
    "options",
    [
        {},
        {"energy": "arap"},
        {"energy": "arap", "clusters": 50, "iterations": 7, "arap_tolerance": 0.0},
        {"solver": "spatial", "detail": "displacement"},
        {"detail": "frames", "ks": 1.0, "kb": 0.5},
        {"constraint_weight": 100.0, "detail": "none", "float32_basis": True},
    ],
    ids=lambda o: ",".join(f"{k}={v}" for k, v in o.items()) or "defaults",
)
def test_equal_to_the_program_on_a_generated_scene(cli, bar_scene, options):
    flags = {"energy": "--energy", "clusters": "--clusters", "iterations": "--iterations",
             "arap_tolerance": "--arap-tolerance", "solver": "--solver", "detail": "--detail",
             "constraints": "--constraints", "ks": "--ks", "kb": "--kb",
             "constraint_weight": "--weight"}
    args = [a for k, v in options.items() if k in flags for a in (flags[k], v)]
    if options.get("float32_basis"):
        args.append("--float32")
    X_cli = run_cli(cli, bar_scene, bar_scene / "bar.off", "--sel", bar_scene / "bar.sel",
                    "--def", bar_scene / "bar.def", "-m", 40, *args)
    scene = specdeform.read_scene(bar_scene / "bar.sel", mesh=bar_scene / "bar.off",
                                  transforms=bar_scene / "bar.def")
    deformer = specdeform.SpectralDeformer(scene.V, scene.F, 40, **options)
    deformer.set_selection(scene.handles, scene.fixed)
    X = deformer.solve(scene.transforms)
    assert relative_difference(X, X_cli, scene.V) < 1e-6
    assert relative_difference(X, scene.V, scene.V) > 0.01  # it did move


def test_equal_to_the_program_on_a_json_scene_with_two_groups(cli, bar_scene, bar):
    V, F = bar
    near = lambda p: int(np.argmin(np.linalg.norm(V - p, axis=1)))  # noqa: E731
    scene_file = bar_scene / "two.json"
    scene_file.write_text(json.dumps({
        "mesh": "bar.off",
        "handles": [
            {"vertices": [near([4, 0, 0]), near([4, 0.5, 0])],
             "transform": {"translate": [0, 0.2, 0], "rotate": {"axis": [1, 0, 0], "degrees": 30}}},
            {"around": {"vertex": near([2, 0.5, 0]), "radius": 0.04},
             "transform": {"translate": [0, -0.1, 0]}},
        ],
        "fixed": [near([0, 0, 0]), near([0, 0.5, 0.5]), near([0, -0.5, -0.5])],
        "settings": {"modes": 60, "kb": 2.0, "detail": "displacement", "constraints": "hard"},
    }))
    X_cli = run_cli(cli, bar_scene, bar_scene / "bar.off", "--scene", scene_file)
    scene = specdeform.read_scene(scene_file)
    assert scene.modes == 60 and scene.options["constraints"] == "hard"
    assert len(scene.handles) == 2 and len(scene.fixed) == 3
    deformer = specdeform.SpectralDeformer(scene.V, scene.F, scene.modes, **scene.options)
    deformer.set_selection(scene.handles, scene.fixed)
    X = deformer.solve(scene.transforms)
    assert relative_difference(X, X_cli, V) < 1e-6
    # Hard constraints: the smooth base's handles reach their targets exactly.
    for group, T in zip(scene.handles, scene.transforms):
        target = deformer.base[group] @ T[:3, :3].T + T[:3, 3]
        np.testing.assert_allclose(deformer.deformed_base[group], target, atol=1e-9)


def test_equal_to_the_program_with_a_dmat_selection(cli, bar_scene, bar):
    V, F = bar
    groups = np.full(len(V), -1)
    groups[V[:, 0] < 0.5] = 0
    groups[V[:, 0] > 3.5] = 1
    (bar_scene / "bar.dmat").write_text(f"1 {len(V)}\n" + "\n".join(map(str, groups)) + "\n")
    # One transform: group 1 gets none and stays in place, as group 0 is meant to.
    T = turn(-30, V[groups == 0].mean(axis=0))
    (bar_scene / "one.def").write_text("# \n" + "\n".join(" ".join(map(repr, r)) for r in T))
    X_cli = run_cli(cli, bar_scene, bar_scene / "bar.off", "--dmat", bar_scene / "bar.dmat",
                    "--def", bar_scene / "one.def", "-m", 40)
    scene = specdeform.read_scene(bar_scene / "bar.dmat", bar_scene / "bar.off",
                                  bar_scene / "one.def")
    assert len(scene.transforms) == 2 and np.array_equal(scene.transforms[1], np.eye(4))
    deformer = specdeform.SpectralDeformer(scene.V, scene.F, 40)
    deformer.set_selection(scene.handles, scene.fixed)
    assert relative_difference(deformer.solve(scene.transforms), X_cli, V) < 1e-6


SHARED_SCENES = ["bar-bend", "bar-twist", "bumpy-plane", "cactus"]


@pytest.mark.parametrize("name", SHARED_SCENES)
def test_equal_to_the_program_on_the_shared_scenes(cli, tmp_path, name):
    folder = SHARED / "scenes"
    if not (folder / f"{name}.sel").exists():
        pytest.skip("the shared scenes are absent")
    files = [folder / f"{name}.{e}" for e in ("off", "sel", "def")]
    scene = specdeform.read_scene(files[1], mesh=files[0], transforms=files[2])
    evals, evecs = specdeform.manifold_harmonics(scene.V, scene.F, 100)
    for energy in ("linear", "arap"):
        X_cli = run_cli(cli, tmp_path, files[0], "--sel", files[1], "--def", files[2],
                        "--energy", energy, "--basis", tmp_path / "basis.sdbasis")
        deformer = specdeform.SpectralDeformer(scene.V, scene.F, basis=(evals, evecs),
                                               energy=energy)
        deformer.set_selection(scene.handles, scene.fixed)
        assert relative_difference(deformer.solve(scene.transforms), X_cli, scene.V) < 1e-6


def test_the_basis_is_shared_not_copied(bar):
    V, F = bar
    evals, evecs = specdeform.manifold_harmonics(V, F, 30)
    owner = weakref.ref(evecs.base)
    deformer = specdeform.SpectralDeformer(V, F, basis=(evals, evecs))
    shared_evals, shared_evecs = deformer.basis
    assert np.shares_memory(shared_evecs, evecs) and np.shares_memory(shared_evals, evals)
    del evals, evecs, shared_evals, shared_evecs
    gc.collect()
    assert owner() is None  # the Python owner is gone; the deformer keeps the basis itself
    deformer.set_selection([V[:, 0] > 3.5], V[:, 0] < 0.5)
    assert np.isfinite(deformer.solve([np.eye(4)])).all()
    assert deformer.basis[1].shape == (len(V), 30)
    # Fewer modes than the basis holds, or arrays of another origin: a copy.
    evals, evecs = deformer.basis
    first = specdeform.SpectralDeformer(V, F, 10, basis=(evals, evecs))
    assert first.basis[1].shape == (len(V), 10) and not np.shares_memory(first.basis[1], evecs)
    copied = specdeform.SpectralDeformer(V, F, basis=(evals.copy(), evecs.copy()))
    assert not np.shares_memory(copied.basis[1], evecs)
    np.testing.assert_array_equal(copied.basis[1], evecs)


def test_views_of_the_deformer_keep_it_alive(bar):
    deformer = specdeform.SpectralDeformer(*bar, 10)
    alive = weakref.ref(deformer)
    base = deformer.base
    assert not base.flags.writeable and base.shape == (len(bar[0]), 3)
    del deformer
    gc.collect()
    assert alive() is not None
    del base
    gc.collect()
    assert alive() is None


def test_a_basis_from_scipy_is_accepted_and_checked(bar):
    import scipy.sparse.linalg

    V, F = bar
    K, M = specdeform.cotan_stiffness(V, F), specdeform.mass_matrix(V, F)
    evals, evecs = scipy.sparse.linalg.eigsh(K, 20, M, sigma=-0.01)
    deformer = specdeform.SpectralDeformer(V, F, basis=(evals, evecs))
    ours = specdeform.SpectralDeformer(V, F, 20)
    np.testing.assert_allclose(deformer.base, ours.base, atol=1e-9)
    not_orthonormal = scipy.sparse.linalg.eigsh(K, 20, sigma=-0.01)
    with pytest.raises(specdeform.InputError, match="not orthonormal in the lumped mass"):
        specdeform.SpectralDeformer(V, F, basis=not_orthonormal)
    with pytest.raises(specdeform.InputError, match=r"evecs: expected 2594 rows"):
        specdeform.SpectralDeformer(V, F, basis=(evals, evecs[:-1]))
    with pytest.raises(specdeform.InputError, match=r"evals: expected shape \(20,\)"):
        specdeform.SpectralDeformer(V, F, basis=(evals[:5], evecs))
    with pytest.raises(specdeform.InputError, match="holds 20 frequencies, 30 are asked for"):
        specdeform.SpectralDeformer(V, F, 30, basis=(evals, evecs))


def test_report_timings_and_options(bar):
    V, F = bar
    deformer = specdeform.SpectralDeformer(V, F, 30, energy="arap", clusters=40)
    deformer.set_selection([V[:, 0] > 3.5], V[:, 0] < 0.5)
    X = deformer.solve(turn(60, V[V[:, 0] > 3.5].mean(axis=0)))
    report, timings = deformer.report, deformer.timings
    assert report["energy"] == "arap" and report["clusters"] == 40
    assert report["converged"] and 0 < report["iterations"] <= 100
    assert timings["basis"] > 0 and timings["frame"]["total"] > 0
    assert set(timings) == {"basis", "reduced_system", "detail_factorization", "selection",
                            "frame"}
    assert deformer.options["energy"] == "arap" and deformer.options["clusters"] == 40
    assert deformer.constraint_error(X)["max"] < 1e-9  # transfer anchors the handles exactly
    miss = deformer.base_miss()  # what the solve itself missed by: soft constraints, not zero
    assert 0 < miss["rms"] <= miss["max"] < 0.005
    assert deformer.deformed_base.shape == X.shape and deformer.deformed_base.flags.writeable


def test_pieces_without_handles_follow_are_held_or_refused():
    V1, F1 = specdeform.icosphere(2)
    V = np.vstack([V1, V1 + [3, 0, 0]])
    F = np.vstack([F1, F1 + len(V1)])
    handle, fixed = np.arange(5), np.arange(100, 110)
    follow = specdeform.SpectralDeformer(V, F, 18, detail="displacement")
    follow.set_selection([handle], fixed)
    X = follow.solve(turn(0, V[0], (0, 0.2, 0)))
    assert follow.report["free_pieces"] == 1
    # the one piece that moves takes all of m (the basis gave it 16: 9 by area, 16 at least)
    assert follow.report["constrained_piece_modes"] == [18]
    free = X[len(V1):]
    assert np.abs(free - V[len(V1):]).max() > 1e-3  # moved along, rigidly
    np.testing.assert_allclose(np.linalg.norm(free - free[0], axis=1),
                               np.linalg.norm(V1 - V1[0], axis=1), atol=1e-12)
    deformer = specdeform.SpectralDeformer(V, F, 18, detail="displacement", unconstrained="keep")
    deformer.set_selection([handle], fixed)
    X = deformer.solve(turn(0, V[0], (0, 0.2, 0)))
    np.testing.assert_array_equal(X[len(V1):], V[len(V1):])
    strict = specdeform.SpectralDeformer(V, F, 18, unconstrained="error")
    with pytest.raises(specdeform.InputError, match="162"):
        strict.set_selection([handle], fixed)


def test_spatial_solver_needs_no_basis(bar):
    V, F = bar
    deformer = specdeform.SpectralDeformer(V, F, solver="spatial")
    assert deformer.basis is None and deformer.timings["basis"] == 0
    np.testing.assert_array_equal(deformer.base, V)


def test_concurrent_solves_on_one_deformer(bar):
    V, F = bar
    deformer = specdeform.SpectralDeformer(V, F, 30, energy="arap")
    deformer.set_selection([V[:, 0] > 3.5], V[:, 0] < 0.5)
    frames = [turn(a, V[V[:, 0] > 3.5].mean(axis=0)) for a in (10, 20, 30, 40)]
    expected = [deformer.solve(T) for T in frames]
    results = {}

    def work(i):
        results[i] = [deformer.solve(frames[(i + j) % 4]) for j in range(4)]

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for i in range(4):
        for j in range(4):
            np.testing.assert_allclose(results[i][j], expected[(i + j) % 4], atol=1e-12)


def test_coordinates_out_of_range_are_named():
    V, F = specdeform.icosphere(1)
    with pytest.raises(specdeform.InputError, match=r"coordinates reach 1e\+160"):
        specdeform.SpectralDeformer(V * 1e160, F, 10)
    with pytest.raises(specdeform.InputError, match="spans only"):
        specdeform.SpectralDeformer(V * 1e-300, F, 10)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda d, n: d.set_selection([1, 2, 3]), r"handles\[0\]: expected a 1-D array"),
        (lambda d, n: d.set_selection(np.arange(5)), r"handles\[0\]: expected a 1-D array"),
        (lambda d, n: d.set_selection([[1.0, 2.0]]), r"handles\[0\]: expected integer indices"),
        (lambda d, n: d.set_selection([[n]]), r"handles\[0\]: index 2594 out of range"),
        (lambda d, n: d.set_selection([[1]], [n + 5]), "fixed: index .* out of range"),
        (lambda d, n: d.set_selection([[1, 2]], [2]), "2"),
        (lambda d, n: d.set_selection([np.ones(n - 1, bool)]), "boolean mask needs one entry"),
        (lambda d, n: d.set_selection("abc"), "handles: expected a list"),
        # An empty group, no group, an empty second group: refused, not a silent identity.
        (lambda d, n: d.set_selection([np.array([], int)], [0]), r"handles\[0\]: an empty handle group"),
        (lambda d, n: d.set_selection([], [0]), "handles: no handle group"),
        (lambda d, n: d.set_selection([[1, 2], np.zeros(n, bool)]), r"handles\[1\]: an empty handle group"),
        (lambda d, n: d.solve([np.eye(4)] * 2), "transform"),
        (lambda d, n: d.solve(np.eye(3)), "4 x 4"),
        (lambda d, n: d.solve(np.diag([1, 1, 1, 2.0])), "transform 0"),
        (lambda d, n: d.solve(np.diag([1, 1, 0, 1.0])), "transform 0"),
        (lambda d, n: d.solve(np.full((4, 4), np.nan)), "not finite"),
    ],
)
def test_bad_selections_and_transforms(bar, call, message):
    V, F = bar
    deformer = specdeform.SpectralDeformer(V, F, 10)
    deformer.set_selection([V[:, 0] > 3.5], V[:, 0] < 0.5)
    with pytest.raises(specdeform.InputError, match=message):
        call(deformer, len(V))


@pytest.mark.parametrize(
    "options, message",
    [
        ({"energy": "nonlinear"}, "unknown .*'nonlinear'"),
        ({"stiffness": 1.0}, "unknown deformation option 'stiffness' .*energy"),
        ({"ks": "high"}, "ks: expected a number, got str"),
        ({"clusters": 2.5}, "clusters: expected an integer, got float"),
        ({"ks": 0.0, "kb": 0.0}, "not both 0"),
        ({"constraint_weight": -1.0}, "constraint weight"),
        ({"history": 51}, "history"),
        ({"mass": "diagonal"}, "mass"),
    ],
)
def test_bad_options(bar, options, message):
    with pytest.raises(specdeform.InputError, match=message):
        specdeform.SpectralDeformer(*bar, 10, **options)


def test_scene_errors(tmp_path, bar_scene):
    with pytest.raises(FileNotFoundError):
        specdeform.read_scene(tmp_path / "missing.json")
    (tmp_path / "nomesh.json").write_text('{"handles": []}')
    with pytest.raises(specdeform.InputError, match="names no mesh"):
        specdeform.read_scene(tmp_path / "nomesh.json")
    (tmp_path / "bad.json").write_text("{")
    with pytest.raises(specdeform.InputError, match="not valid JSON"):
        specdeform.read_scene(tmp_path / "bad.json")
    with pytest.raises(specdeform.InputError, match="needs its transforms"):
        specdeform.read_scene(bar_scene / "bar.sel", mesh=bar_scene / "bar.off")
    with pytest.raises(FileNotFoundError):
        specdeform.read_scene(bar_scene / "bar.sel", mesh=tmp_path / "x.off",
                              transforms=bar_scene / "bar.def")
    with pytest.raises(specdeform.InputError, match="vertex entries"):
        specdeform.read_scene(bar_scene / "bar.sel", mesh=specdeform_file(tmp_path),
                              transforms=bar_scene / "bar.def")


def specdeform_file(folder):
    specdeform.write_mesh(folder / "small.off", *specdeform.icosphere(1))
    return folder / "small.off"


def test_scene_vertices_the_reader_dropped(tmp_path):
    """A vertex no face uses is dropped by the reader: a handle group of such vertices only is an
    error, one with some of them a warning; the scene's settings come with the scene."""
    V, F = specdeform.icosphere(1)
    n = len(V)
    lines = [f"OFF\n{n + 1} {len(F)} 0"] + [" ".join(map(repr, p)) for p in V] + ["5 5 5"]
    lines += ["3 " + " ".join(map(str, f)) for f in F]
    (tmp_path / "m.off").write_text("\n".join(lines) + "\n")
    scene = {"mesh": "m.off", "handles": [{"vertices": [n]}], "fixed": [1]}
    (tmp_path / "all.json").write_text(json.dumps(scene))
    with pytest.raises(specdeform.InputError, match="handle group 0: all 1 of its vertices"):
        specdeform.read_scene(tmp_path / "all.json")
    scene["handles"] = [{"vertices": [0, n]}]
    scene["settings"] = {"unconstrained": "error", "iterations": 9, "arap_bending": 0.5}
    (tmp_path / "some.json").write_text(json.dumps(scene))
    with pytest.warns(UserWarning, match="handle group 0: 1 of its 2 vertices are used by no face"):
        s = specdeform.read_scene(tmp_path / "some.json")
    assert [list(h) for h in s.handles] == [[0]] and list(s.fixed) == [1]
    assert s.options["unconstrained"] == "error" and s.options["iterations"] == 9
    assert s.options["arap_bending"] == 0.5


def test_background_transfer_adds_displacements_until_it_is_ready(bar):
    """background_transfer: set_selection returns before the transfer is factored; once it is
    (wait_for_detail), the frame is the one a deformer without it solves."""
    V, F = bar
    evals, evecs = specdeform.manifold_harmonics(V, F, 20)
    handle, fixed = V[:, 0] > 3.5, V[:, 0] < 0.5
    T = turn(50, V[handle].mean(axis=0))
    background = specdeform.SpectralDeformer(V, F, basis=(evals, evecs), background_transfer=True)
    plain = specdeform.SpectralDeformer(V, F, basis=(evals, evecs))
    assert background.options["background_transfer"] and not plain.options["background_transfer"]
    for d in (background, plain):
        d.set_selection([handle], fixed)
    early = background.solve(T)
    background.wait_for_detail()
    assert not background.detail_pending and not plain.detail_pending
    expected = plain.solve(T)
    np.testing.assert_allclose(background.solve(T), expected, atol=1e-9)
    # Before it was ready (unless a fast machine was ready already) the details were added as
    # displacements: the same base, the details not turned with it.
    assert relative_difference(early, expected, V) < 0.05
    plain.wait_for_detail()  # at once


def test_basis_cache_file_is_the_file_manifold_harmonics_writes(tmp_path, bar):
    V, F = bar
    path = specdeform.basis_cache_file(V, F, 8, cache=tmp_path)
    assert not path.exists() and path.parent == tmp_path
    specdeform.manifold_harmonics(V, F, 8, cache=tmp_path)
    assert path.exists()
    # A multilevel request is served by the exact basis when the folder has it.
    assert specdeform.basis_cache_file(V, F, 8, cache=tmp_path, eigensolver="multilevel") == path
    other = specdeform.basis_cache_file(V, F, 9, cache=tmp_path, eigensolver="multilevel")
    assert other.name.endswith("-m9-lumped-multilevel.sdbasis")


def test_preview_is_the_frame_with_the_details_as_displacements(bar):
    """preview(T) at every vertex, or at some: the pose's base plus x - s, as a Displacement
    deformer solves it; solve() afterwards still gives the transfer's frame."""
    V, F = bar
    basis = specdeform.manifold_harmonics(V, F, 20)
    handle, fixed = V[:, 0] > 3.5, V[:, 0] < 0.5
    T = turn(50, V[handle].mean(axis=0))
    transfer = specdeform.SpectralDeformer(V, F, basis=basis)
    displaced = specdeform.SpectralDeformer(V, F, basis=basis, detail="displacement")
    for d in (transfer, displaced):
        d.set_selection([handle], fixed)
    quick, expected = transfer.preview(T), displaced.solve(T)
    assert quick.shape == V.shape
    np.testing.assert_allclose(quick, expected, atol=1e-9)
    at = [len(V) - 1, 0, 5]
    np.testing.assert_allclose(transfer.preview(T, at), expected[at], atol=1e-9)
    assert relative_difference(transfer.solve(T), quick, V) > 1e-4  # the details turned
    with pytest.raises(specdeform.InputError):
        transfer.preview(T, [len(V)])


def test_frames_into_a_float32_buffer(bar):
    """preview(T, out=buffer) and solve(T, out=buffer) write the frame into the caller's float32
    rows and return them; anything else for out is an InputError."""
    V, F = bar
    d = specdeform.SpectralDeformer(V, F, basis=specdeform.manifold_harmonics(V, F, 20))
    d.set_selection([V[:, 0] > 3.5], V[:, 0] < 0.5)
    T = turn(50, V[V[:, 0] > 3.5].mean(axis=0))
    buffer = np.zeros(V.shape, np.float32)
    assert d.preview(T, out=buffer) is buffer
    assert relative_difference(buffer, d.preview(T), V) < 1e-6
    for wrong in (np.zeros(V.shape), np.zeros((len(V) - 1, 3), np.float32),
                  np.zeros((3, len(V)), np.float32).T):
        with pytest.raises(specdeform.InputError, match="out must be"):
            d.preview(T, out=wrong)
    with pytest.raises(specdeform.InputError, match="every vertex"):
        d.preview(T, [0], out=buffer)
    assert d.solve(T, out=buffer) is buffer  # the frame with the transfer's details
    assert relative_difference(buffer, d.solve(T), V) < 1e-6
    assert relative_difference(buffer, d.preview(T), V) > 1e-4
    with pytest.raises(specdeform.InputError, match="solve: out must be"):
        d.solve(T, out=np.zeros(V.shape))
