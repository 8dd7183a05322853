"""Spectral mesh deformation (Rong, Cao & Guo 2008) for numpy.

Meshes are plain arrays: V float64 (n, 3), F integer (f, 3). Operators come back as
scipy.sparse matrices (cotan_stiffness and mass_matrix: the only functions that need scipy, an
optional dependency), bases as read-only views that share the solver's memory.

    import specdeform
    V, F = specdeform.read_mesh("bar.off")      # or V, F, file = read_mesh("a.glb", keep=True)
    evals, evecs = specdeform.manifold_harmonics(V, F, 100, cache="bar.sdbasis")
    d = specdeform.SpectralDeformer(V, F, basis=(evals, evecs), energy="arap")
    d.set_selection(handles=[top], fixed=bottom)
    X = d.solve([T])  # one 4 x 4 transform per handle group
    file.write("out.glb", X)  # the file as it was, with X
Errors: InputError (a ValueError) for bad input, SolverError (a RuntimeError) for a numerical
failure, both specdeform.Error; OSError for a file that cannot be opened.
"""

from ._scene import Scene, read_scene
from ._specdeform import (
    Error,
    Harmonics,
    InputError,
    MeshFile,
    MeshReadInfo,
    SolverError,
    SpectralDeformer,
    __version__,
    basis_cache_file,
    bumpy_bar,
    bumpy_plane,
    cotan_stiffness,
    harmonics_forward,
    harmonics_inverse,
    icosphere,
    load_basis,
    low_pass,
    manifold_harmonics,
    mass_matrix,
    read_mesh,
    save_basis,
    spectral_filter,
    torus,
    write_mesh,
)

__all__ = [
    "Error",
    "Harmonics",
    "InputError",
    "MeshFile",
    "MeshReadInfo",
    "Scene",
    "SolverError",
    "SpectralDeformer",
    "__version__",
    "basis_cache_file",
    "bumpy_bar",
    "bumpy_plane",
    "cotan_stiffness",
    "harmonics_forward",
    "harmonics_inverse",
    "icosphere",
    "load_basis",
    "low_pass",
    "manifold_harmonics",
    "mass_matrix",
    "read_mesh",
    "read_scene",
    "save_basis",
    "spectral_filter",
    "torus",
    "write_mesh",
]
