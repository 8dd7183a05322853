#include "basis_store.h"

#include <iostream>

#include "specdeform/spectral/basis_store.h"

namespace specdeform::server {

PreparedBasis prepare_basis(const TriangleMesh& mesh, int modes, EigenSolver solver,
                            const std::filesystem::path& cache_dir,
                            const ProgressCallback& progress) {
  if (!cache_dir.empty()) {
    std::error_code error;
    std::filesystem::create_directories(cache_dir, error);
    if (error) std::cerr << "specdeform: warning: no basis cache: " << error.message() << "\n";
  }
  ManifoldHarmonicsOptions o;
  o.num_modes = modes;
  o.solver = solver;
  o.progress = progress;
  const bool cache = std::filesystem::is_directory(cache_dir);
  // A basis in the cache (this one, or the exact one for a multilevel request) is loaded.
  const std::filesystem::path file = cache ? cached_basis_file(mesh, o, cache_dir) : "";
  const bool cached = cache && std::filesystem::exists(file);
  ObtainedBasis basis = obtain_basis(mesh, o, cached ? cache_dir : "");
  const bool save = cache && !basis.loaded && basis.warning.empty();  // a converged basis
  return {std::move(basis.harmonics), basis.seconds, basis.loaded ? "cache" : "computed",
          std::move(basis.warning), save ? file : ""};
}

}  // namespace specdeform::server
