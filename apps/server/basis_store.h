// The editor's bases: the library's compute-or-load (spectral/basis_store.h) in the cache folder,
// except that a computed basis is not written there at once: the editor saves it in the
// background (`save_to`), after the page can edit.
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "specdeform/mesh/triangle_mesh.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform::server {

struct PreparedBasis {
  std::shared_ptr<const ManifoldHarmonics> harmonics;  // null: to be prepared again
  double seconds = 0.0;
  std::string source;             // computed, cache, reused
  std::string warning;            // shown to the user
  std::filesystem::path save_to;  // the cache file a computed basis is to be saved in; empty: none
};

// The first `modes` manifold harmonics of `mesh` (lumped mass) by `solver`, from `cache_dir`
// (created if missing; empty: no cache) or computed with `progress` (which may throw to abandon
// the computation), with the file to cache it in. Throws SolverError for a basis too inaccurate
// to use.
PreparedBasis prepare_basis(const TriangleMesh& mesh, int modes, EigenSolver solver,
                            const std::filesystem::path& cache_dir,
                            const ProgressCallback& progress);

}  // namespace specdeform::server
