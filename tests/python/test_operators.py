"""The operators as scipy.sparse matrices: K and M against their defining formulas."""

import subprocess
import sys

import numpy as np
import pytest
import scipy.sparse

import specdeform


def triangle_areas(V, F):
    return 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)


def test_stiffness_is_the_dirichlet_energy(lumpy_sphere):
    V, F = lumpy_sphere
    K = specdeform.cotan_stiffness(V, F)
    assert scipy.sparse.isspmatrix_csc(K) and K.shape == (len(V), len(V))
    assert abs(K - K.T).max() < 1e-12
    np.testing.assert_allclose(K @ np.ones(len(V)), 0, atol=1e-12)
    # x^T K x = sum over triangles of area |grad x|^2, x piecewise linear.
    x = np.random.default_rng(1).standard_normal(len(V))
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    n = np.cross(b - a, c - a)
    area2 = np.linalg.norm(n, axis=1, keepdims=True)
    n /= area2
    # grad x = sum_k x_k (n x e_k) / (2 area), e_k the edge opposite corner k.
    grad = sum(x[F[:, k], None] * np.cross(n, e) for k, e in enumerate((c - b, a - c, b - a)))
    grad /= area2
    energy = np.sum(0.5 * area2[:, 0] * np.sum(grad**2, axis=1))
    assert x @ K @ x == pytest.approx(energy, rel=1e-10)


@pytest.mark.parametrize("kind", ["lumped", "consistent"])
def test_mass_sums_to_the_area(lumpy_sphere, kind):
    V, F = lumpy_sphere
    M = specdeform.mass_matrix(V, F, kind)
    assert scipy.sparse.isspmatrix_csc(M) and abs(M - M.T).max() == 0
    assert M.sum() == pytest.approx(triangle_areas(V, F).sum(), rel=1e-12)
    assert (M.nnz == len(V)) == (kind == "lumped")


def test_lumped_mass_is_a_third_of_the_areas_around_a_vertex(bar):
    V, F = bar
    expected = np.bincount(F.ravel(), np.repeat(triangle_areas(V, F) / 3, 3), minlength=len(V))
    np.testing.assert_allclose(specdeform.mass_matrix(V, F).diagonal(), expected, rtol=1e-12)


def test_unknown_mass_kind_is_refused(bar):
    with pytest.raises(specdeform.InputError, match="'diagonal' is not one of lumped"):
        specdeform.mass_matrix(*bar, kind="diagonal")


def test_matrices_own_their_arrays(bar):
    # The arrays are moved out of the library, not copied, and live as long as the matrix.
    K = specdeform.cotan_stiffness(*bar)
    data = K.data
    del K
    assert np.isfinite(data).all() and data.flags.writeable


def test_without_scipy_only_the_matrices_need_it(tmp_path):
    """scipy is optional: with it out of sight, the matrices' functions say what to install and
    the rest deforms with numpy alone."""
    script = """
import sys
sys.modules["scipy"] = None  # an import of scipy now fails, as where it is not installed
import numpy as np
import specdeform
V, F = specdeform.bumpy_bar()
try:
    specdeform.cotan_stiffness(V, F)
    raise SystemExit("cotan_stiffness without scipy did not fail")
except ImportError as e:
    assert "scipy is not installed" in str(e) and "specdeform[scipy]" in str(e), e
d = specdeform.SpectralDeformer(V, F, modes=20)
top, bottom = np.flatnonzero(V[:, 0] > V[:, 0].max() - 0.05), np.flatnonzero(V[:, 0] < V[:, 0].min() + 0.05)
d.set_selection(handles=[top], fixed=bottom)
T = np.eye(4)
T[2, 3] = 0.2
assert np.isfinite(d.solve([T])).all()
print("ok")
"""
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 0 and run.stdout.strip() == "ok", run.stderr
