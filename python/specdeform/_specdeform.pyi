# Types of the compiled module (python/src). Arrays in: anything numpy.asarray takes; V real
# (n, 3), F and index arrays integer (never float). Arrays out: float64 V and int32 F in Fortran
# order, moved out of the library without a copy; views of a basis are read-only.
import os
import pathlib
from collections.abc import Callable, Sequence
from typing import Any, Literal, overload

import numpy as np
import numpy.typing as npt
import scipy.sparse

__version__: str

_Path = str | os.PathLike[str]
_Float = npt.NDArray[np.float64]
_Int = npt.NDArray[np.int32]
_Mass = Literal["lumped", "consistent"]
_Basis = tuple[npt.ArrayLike, npt.ArrayLike] | Harmonics
_Progress = Callable[[float, str], object]

class Error(Exception): ...
class InputError(Error, ValueError): ...
class SolverError(Error, RuntimeError): ...

class MeshReadInfo:
    @property
    def file_vertices(self) -> _Float: ...
    @property
    def vertex_to_file(self) -> _Int: ...
    @property
    def face_to_file(self) -> _Int: ...
    @property
    def file_faces(self) -> int: ...
    @property
    def unused_vertices(self) -> int: ...
    @property
    def collapsed_faces(self) -> int: ...
    @property
    def duplicate_faces(self) -> int: ...
    @property
    def file_to_vertex(self) -> _Int: ...
    @property
    def welded_corners(self) -> int: ...
    @property
    def welded_vertices(self) -> int: ...

class MeshFile:
    def write(
        self,
        path: _Path,
        V: npt.ArrayLike,
        normals: str = "follow",
        morph_targets: str = "turn",
        joints: str = "follow",
    ) -> list[str]: ...
    @property
    def info(self) -> MeshReadInfo: ...
    @property
    def format(self) -> str: ...
    def summary(self) -> dict[str, object]: ...
    @property
    def uv(self) -> _Float: ...
    @property
    def corner_uv(self) -> _Int: ...
    @property
    def corners(self) -> _Int: ...
    @property
    def offsets(self) -> _Int: ...
    @property
    def corner_normal(self) -> _Int: ...
    @property
    def normals(self) -> _Float: ...
    @property
    def colours(self) -> npt.NDArray[np.float32]: ...

@overload
def read_mesh(
    path: _Path, return_info: Literal[False] = ..., keep: Literal[False] = ...
) -> tuple[_Float, _Int]: ...
@overload
def read_mesh(
    path: _Path, return_info: Literal[True], keep: Literal[False] = ...
) -> tuple[_Float, _Int, MeshReadInfo]: ...
@overload
def read_mesh(
    path: _Path, return_info: bool = ..., keep: Literal[True] = ...
) -> tuple[_Float, _Int, MeshFile]: ...
def write_mesh(
    path: _Path, V: npt.ArrayLike, F: npt.ArrayLike, info: MeshReadInfo | None = None
) -> None: ...
def bumpy_bar(
    length: float = 4.0,
    thickness: float = 1.0,
    cells_per_unit: int = 24,
    bumps_per_unit: int = 3,
    bump_height: float = 0.04,
) -> tuple[_Float, _Int]: ...
def bumpy_plane(
    size: float = 1.0, resolution: int = 64, bumps: int = 8, bump_height: float = 0.02
) -> tuple[_Float, _Int]: ...
def icosphere(subdivisions: int = 3, radius: float = 1.0) -> tuple[_Float, _Int]: ...
def torus(
    major_radius: float = 1.0,
    minor_radius: float = 0.35,
    major_segments: int = 96,
    minor_segments: int = 32,
) -> tuple[_Float, _Int]: ...
def cotan_stiffness(V: npt.ArrayLike, F: npt.ArrayLike) -> scipy.sparse.csc_matrix: ...
def mass_matrix(
    V: npt.ArrayLike, F: npt.ArrayLike, kind: _Mass = "lumped"
) -> scipy.sparse.csc_matrix: ...

class Harmonics:
    @property
    def eigenvalues(self) -> _Float: ...
    @property
    def vectors(self) -> _Float: ...
    @property
    def mass(self) -> _Mass: ...
    @property
    def converged(self) -> bool: ...
    @property
    def max_residual(self) -> float: ...
    @property
    def residuals(self) -> _Float: ...
    @property
    def approximate(self) -> bool: ...
    @property
    def coarse_functions(self) -> int: ...
    @property
    def rounding_floor(self) -> float: ...
    @property
    def threshold(self) -> float: ...
    @property
    def max_orthogonality_error(self) -> float: ...
    @property
    def cluster_truncated(self) -> bool: ...
    @property
    def pieces(self) -> int: ...
    @property
    def requested_modes(self) -> int: ...
    @property
    def stages(self) -> list[tuple[str, float]]: ...
    @property
    def bands(self) -> int: ...
    @property
    def restarts(self) -> int: ...
    @property
    def solves(self) -> int: ...

def manifold_harmonics(
    V: npt.ArrayLike,
    F: npt.ArrayLike,
    k: int,
    *,
    mass: _Mass = "lumped",
    cache: _Path | None = None,
    tolerance: float = 1e-8,
    eigensolver: Literal["krylov", "lanczos", "multilevel", "auto"] = "krylov",
    progress: _Progress | None = None,
    seed: int = 1,
) -> tuple[_Float, _Float]: ...
def basis_cache_file(
    V: npt.ArrayLike,
    F: npt.ArrayLike,
    k: int,
    *,
    cache: _Path,
    mass: _Mass = "lumped",
    eigensolver: Literal["krylov", "lanczos", "multilevel", "auto"] = "krylov",
) -> pathlib.Path: ...
def load_basis(path: _Path, V: npt.ArrayLike, F: npt.ArrayLike) -> tuple[_Float, _Float]: ...
def save_basis(
    path: _Path,
    basis: _Basis,
    V: npt.ArrayLike,
    F: npt.ArrayLike,
    *,
    float32: bool | None = None,
    mass: _Mass | None = None,
) -> None: ...
def harmonics_forward(
    V: npt.ArrayLike,
    F: npt.ArrayLike,
    evecs: npt.ArrayLike,
    X: npt.ArrayLike | None = None,
    *,
    mass: _Mass | None = None,
) -> _Float: ...
def harmonics_inverse(evecs: npt.ArrayLike, C: npt.ArrayLike, k: int | None = None) -> _Float: ...
def low_pass(
    V: npt.ArrayLike,
    F: npt.ArrayLike,
    evecs: npt.ArrayLike,
    k: int | None = None,
    X: npt.ArrayLike | None = None,
    *,
    mass: _Mass | None = None,
) -> _Float: ...
def spectral_filter(
    V: npt.ArrayLike,
    F: npt.ArrayLike,
    evecs: npt.ArrayLike,
    gains: npt.ArrayLike,
    X: npt.ArrayLike | None = None,
    *,
    residual_gain: float = 0.0,
    mass: _Mass | None = None,
) -> _Float: ...

class SpectralDeformer:
    def __init__(
        self,
        V: npt.ArrayLike,
        F: npt.ArrayLike,
        modes: int | None = None,
        basis: _Basis | None = None,
        *,
        mass: _Mass | None = None,
        cache: _Path | None = None,
        progress: _Progress | None = None,
        tolerance: float = 1e-8,
        energy: Literal["linear", "arap"] = ...,
        ks: float = ...,
        kb: float = ...,
        constraint_weight: float = ...,
        detail: Literal["none", "displacement", "frames", "transfer"] = ...,
        solver: Literal["spectral", "spatial"] = ...,
        constraints: Literal["soft", "hard"] = ...,
        unconstrained: Literal["follow", "keep", "error"] = ...,
        float32_basis: bool = ...,
        background_transfer: bool = ...,
        iterations: int = ...,
        clusters: int = ...,
        arap_tolerance: float = ...,
        history: int = ...,
        arap_bending: float = ...,
        warm_start: bool = ...,
    ) -> None: ...
    def set_selection(
        self, handles: Sequence[npt.ArrayLike], fixed: npt.ArrayLike = ()
    ) -> None: ...
    def solve(
        self,
        transforms: npt.ArrayLike | Sequence[npt.ArrayLike],
        out: npt.NDArray[np.float32] | None = None,
    ) -> npt.NDArray[np.floating]: ...
    def preview(
        self,
        transforms: npt.ArrayLike | Sequence[npt.ArrayLike],
        vertices: npt.ArrayLike | None = None,
        out: npt.NDArray[np.float32] | None = None,
    ) -> npt.NDArray[np.floating]: ...
    def base_miss(self) -> dict[str, float]: ...
    def constraint_error(self, X: npt.ArrayLike) -> dict[str, float]: ...
    @property
    def detail_pending(self) -> bool: ...
    def wait_for_detail(self) -> None: ...
    @property
    def base(self) -> _Float: ...
    @property
    def deformed_base(self) -> _Float: ...
    @property
    def basis(self) -> tuple[_Float, _Float] | None: ...
    @property
    def options(self) -> dict[str, Any]: ...
    @property
    def timings(self) -> dict[str, Any]: ...
    @property
    def report(self) -> dict[str, Any]: ...

def _read_scene(path: _Path, mesh: _Path, transforms: _Path | None = None) -> dict[str, Any]: ...
