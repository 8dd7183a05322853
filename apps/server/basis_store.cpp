#include "basis_store.h"

#include <chrono>
#include <cstdio>
#include <iostream>

#include "specdeform/exceptions.h"
#include "specdeform/spectral/basis_cache.h"

namespace specdeform::server {

namespace {

std::filesystem::path cache_file(const std::filesystem::path& dir, const TriangleMesh& mesh,
                                 int modes) {
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(mesh_hash(mesh)));
  return dir / (std::string(hash) + "-m" + std::to_string(modes) + "-lumped.sdbasis");
}

}  // namespace

PreparedBasis prepare_basis(const TriangleMesh& mesh, int modes,
                            const std::filesystem::path& cache_dir,
                            const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  PreparedBasis out;
  const std::filesystem::path cache =
      cache_dir.empty() ? std::filesystem::path() : cache_file(cache_dir, mesh, modes);
  if (!cache.empty() && std::filesystem::exists(cache)) {
    progress(0.0, "loading the basis");
    out.harmonics = std::make_shared<const ManifoldHarmonics>(load_basis(cache, mesh));
    out.source = "cache";
  } else {
    ManifoldHarmonicsOptions o;
    o.num_modes = modes;
    o.progress = progress;
    auto basis = std::make_shared<ManifoldHarmonics>(compute_manifold_harmonics(mesh, o));
    out.harmonics = basis;
    out.source = "computed";
    if (basis->status != SolveStatus::Converged) {
      // Short of the tolerance but far below what a deformation can show (nearly degenerate
      // triangles limit the attainable accuracy): usable, with a warning; not cached.
      if (!(basis->max_residual <= kUsableResidual)) {
        throw SolverError("the manifold harmonics did not converge: " + residual_summary(*basis));
      }
      out.warning = "the basis is less accurate than asked: " + residual_summary(*basis);
    } else if (!cache.empty()) {
      try {
        std::filesystem::create_directories(cache.parent_path());
        save_basis(cache, *basis, mesh, BasisPrecision::Float64);
      } catch (const std::exception& e) {
        std::cerr << "specdeform: warning: basis not cached: " << e.what() << "\n";
      }
    }
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace specdeform::server
