// Manifold-harmonics bases on the Python side: the Harmonics object that owns a basis (shared with
// every SpectralDeformer built on it) and the (evals, evecs) views it hands out, computing a
// basis with the GIL released (Ctrl-C and a progress callback checked while it runs), and the
// basis caches of the command-line program and the editor.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>

#include <pybind11/pybind11.h>

#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform::python {

namespace py = pybind11;

// The Python class specdeform.Harmonics.
struct Harmonics {
  std::shared_ptr<const ManifoldHarmonics> value;
};

// (evals, evecs): read-only views of `basis`, both owned by one new Harmonics object.
py::tuple eigenpairs(std::shared_ptr<const ManifoldHarmonics> basis);

// The basis `evecs` is the full view of, or null when it is another array.
std::shared_ptr<const ManifoldHarmonics> shared_basis(py::handle evecs);

// A basis argument: a Harmonics, or (evals, evecs) for `mesh`. Views of one Harmonics are used
// as they are; other arrays are copied and must be M-orthonormal for `mass` (default lumped).
// Only the first `modes` pairs, when given. InputError for a basis computed with another mass.
std::shared_ptr<const ManifoldHarmonics> to_basis(py::handle basis, const TriangleMesh& mesh,
                                                  std::optional<MassType> mass,
                                                  std::optional<int> modes);

// The library's progress callback for a computation that runs without the GIL: at most every
// 50 ms, and at the end, it takes the GIL, raises what a pending signal raises (KeyboardInterrupt
// for Ctrl-C) and calls `user(fraction, stage)` unless it is None; a Python exception aborts the
// computation. `user` must outlive it.
ProgressCallback python_progress(py::handle user);

// The basis from `cache` if it holds one for the mesh, else computed (and then written to
// `cache`). `cache`: a basis file (the CLI's --basis) or an existing directory of files named as
// the editor names them. Throws SolverError when the computation does not converge.
std::shared_ptr<const ManifoldHarmonics> obtain_basis(
    const TriangleMesh& mesh, const ManifoldHarmonicsOptions& options,
    const std::optional<std::filesystem::path>& cache, py::handle progress);

// "lumped" or "consistent".
MassType mass_from_name(const std::string& name);
std::string mass_name(MassType mass);

}  // namespace specdeform::python
