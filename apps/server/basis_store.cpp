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
  ObtainedBasis basis =
      obtain_basis(mesh, o, std::filesystem::is_directory(cache_dir) ? cache_dir : "");
  return {std::move(basis.harmonics), basis.seconds, basis.loaded ? "cache" : "computed",
          std::move(basis.warning)};
}

}  // namespace specdeform::server
