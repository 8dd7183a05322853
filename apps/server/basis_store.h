// The editor's bases: loaded from the cache folder when there, computed (and cached) otherwise.
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "specdeform/mesh/triangle_mesh.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform::server {

// The largest basis residual (eigen_residual) the editor works with, warning, when the solver
// falls short of its tolerance.
inline constexpr double kUsableResidual = 1e-6;

struct PreparedBasis {
  std::shared_ptr<const ManifoldHarmonics> harmonics;  // null: to be prepared again
  double seconds = 0.0;
  std::string source;   // computed, cache, reused
  std::string warning;  // shown to the user
};

// The first `modes` manifold harmonics of `mesh` (lumped mass), from `cache_dir` (empty: no
// cache) or computed with `progress` (which may throw to abandon the computation) and then
// cached. Throws SolverError for a basis too inaccurate to use.
PreparedBasis prepare_basis(const TriangleMesh& mesh, int modes,
                            const std::filesystem::path& cache_dir,
                            const ProgressCallback& progress);

}  // namespace specdeform::server
