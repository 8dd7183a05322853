// Compute-or-load of a manifold-harmonics basis with the on-disk cache (basis_cache.h): the one
// place where the command line, the editor, the Python module and the Blender add-on get a basis.
//
// A cache is a basis file, or a folder of files named by basis_file_name(): the mesh's hash, m,
// the mass matrix, then the Laplacian and the solver where they are not the defaults, e.g.
// "0123456789abcdef-m100-lumped.sdbasis" or "...-m100-lumped-multilevel.sdbasis" (the names the
// editor and the Python module have always used for the defaults). A file serves a request when
// it was computed for this mesh and these operators and holds at least m pairs (the first m are
// taken; a basis computed piece by piece serves only the m it was computed for). A folder's file
// that cannot serve (an older format, say) is computed anew and replaced. An exact basis serves any
// request (a folder's exact file is taken for a multilevel request too); an approximate
// (multilevel) one only a multilevel request: a folder keeps the two apart by name, a named file
// holding the wrong kind is an InputError rather than overwritten.
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "specdeform/mesh/triangle_mesh.h"
#include "specdeform/spectral/basis_cache.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform {

// The largest residual (eigen_residual) of a computed basis that is used although the solver
// fell short of its tolerance (nearly degenerate triangles limit what is attainable; far below
// what a deformation shows): with a warning, and not cached.
inline constexpr double kUsableResidual = 1e-6;

// The file name of the basis for `mesh` and `options` in a cache folder.
std::string basis_file_name(const TriangleMesh& mesh, const ManifoldHarmonicsOptions& options);

// The file of the cache folder `folder` that serves the request: the exact basis's where it
// exists and a multilevel one is asked for, else basis_file_name()'s (which may not exist yet).
std::filesystem::path cached_basis_file(const TriangleMesh& mesh,
                                        const ManifoldHarmonicsOptions& options,
                                        const std::filesystem::path& folder);

// The precision a cache keeps `basis` in: float32 for an approximate (multilevel) basis, whose
// own error (its residuals, 1e-4 and more) is far above float32's rounding (6e-8 of each entry):
// half the file, half its write; float64 for an exact basis. (A factored one is kept as its
// factors either way: basis_cache.h.)
BasisPrecision cache_precision(const ManifoldHarmonics& basis);

struct ObtainedBasis {
  std::shared_ptr<const ManifoldHarmonics> harmonics;  // options.num_modes pairs (more on
                                                       // several pieces)
  std::filesystem::path file;                          // read or written; empty: none
  bool loaded = false;                                 // read from the cache
  double seconds = 0.0;                                // to load or to compute
  std::string warning;  // a usable basis short of its tolerance (see kUsableResidual)
};

// The basis from `cache` (a file, or an existing folder: the file of basis_file_name() in it)
// when it holds one for the request; otherwise computed (options.progress is called, and may
// throw to abandon it) and, when it converged, written there (a failed write is a warning on
// stderr, not an error; in cache_precision()). No cache: computed. Throws InputError for a named
// file of another mesh, other operators, too few pairs or the wrong kind, SolverError for a
// computed basis whose residual exceeds kUsableResidual without converging.
ObtainedBasis obtain_basis(const TriangleMesh& mesh, const ManifoldHarmonicsOptions& options,
                           const std::filesystem::path& cache = {});

}  // namespace specdeform
