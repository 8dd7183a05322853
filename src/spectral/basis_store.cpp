#include "specdeform/spectral/basis_store.h"

#include <chrono>
#include <cstdio>
#include <iostream>

#include "specdeform/exceptions.h"
#include "specdeform/mesh/mesh_info.h"
#include "specdeform/spectral/basis_cache.h"

namespace specdeform {

namespace {

// `h` cut to its first m pairs, or an InputError naming `file` when it cannot serve the request.
ManifoldHarmonics serving(ManifoldHarmonics h, const TriangleMesh& mesh,
                          const ManifoldHarmonicsOptions& o, const std::filesystem::path& file) {
  require_operators(file, h, o.mass, o.laplacian);
  if (h.pieces == 0) {
    int pieces = 1;
    vertex_components(mesh, &pieces);
    if (pieces > 1) {
      throw InputError(file.string() +
                       ": computed for the whole mesh at once by an older "
                       "version; a mesh of several pieces is now solved piece by piece: recompute "
                       "it");
    }
  }
  if (h.pieces > 1) {
    if (h.requested_modes != o.num_modes) {
      throw InputError(file.string() +
                       ": computed piece by piece for m = " + std::to_string(h.requested_modes) +
                       ", " + std::to_string(o.num_modes) + " are asked for");
    }
    return h;
  }
  if (h.basis.cols() < o.num_modes) {
    throw InputError(file.string() + ": holds " + std::to_string(h.basis.cols()) +
                     " frequencies, " + std::to_string(o.num_modes) + " are asked for");
  }
  if (h.approximate && o.solver != EigenSolver::Multilevel) {
    throw InputError(file.string() +
                     ": holds an approximate (multilevel) basis; ask for the multilevel "
                     "eigensolver or name another file for the exact one");
  }
  h.basis.conservativeResize(Eigen::NoChange, o.num_modes);
  h.eigenvalues.conservativeResize(o.num_modes);
  h.residuals.conservativeResize(o.num_modes);
  h.requested_modes = o.num_modes;
  return h;
}

}  // namespace

std::string basis_file_name(const TriangleMesh& mesh, const ManifoldHarmonicsOptions& o) {
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(mesh_hash(mesh)));
  std::string name = std::string(hash) + "-m" + std::to_string(o.num_modes) +
                     (o.mass == MassType::Lumped ? "-lumped" : "-consistent");
  if (o.laplacian == LaplacianType::IntrinsicDelaunay) name += "-intrinsic-delaunay";
  if (o.solver == EigenSolver::Multilevel) name += "-multilevel";
  return name + ".sdbasis";
}

std::filesystem::path cached_basis_file(const TriangleMesh& mesh, const ManifoldHarmonicsOptions& o,
                                        const std::filesystem::path& folder) {
  ManifoldHarmonicsOptions exact = o;
  exact.solver = EigenSolver::BlockKrylov;
  const std::filesystem::path better = folder / basis_file_name(mesh, exact);
  if (o.solver == EigenSolver::Multilevel && std::filesystem::exists(better)) return better;
  return folder / basis_file_name(mesh, o);
}

BasisPrecision cache_precision(const ManifoldHarmonics& basis) {
  return basis.approximate ? BasisPrecision::Float32 : BasisPrecision::Float64;
}

ObtainedBasis obtain_basis(const TriangleMesh& mesh, const ManifoldHarmonicsOptions& o,
                           const std::filesystem::path& cache) {
  const auto start = std::chrono::steady_clock::now();
  ObtainedBasis out;
  out.file = cache;
  if (!cache.empty() && std::filesystem::is_directory(cache)) {
    out.file = cached_basis_file(mesh, o, cache);
  }
  ManifoldHarmonics h;
  if (!out.file.empty() && std::filesystem::exists(out.file)) {
    if (o.progress) o.progress(0.0, "loading the basis");
    try {
      h = serving(load_basis(out.file, mesh), mesh, o, out.file);
      out.loaded = true;
    } catch (const InputError& e) {
      if (!std::filesystem::is_directory(cache)) throw;
      // A folder's file that cannot serve (an older format, a damaged file): computed anew.
      std::cerr << "specdeform: warning: " << e.what() << "; computing it anew\n";
      out.file = cache / basis_file_name(mesh, o);
    }
  }
  if (!out.loaded) {
    h = compute_manifold_harmonics(mesh, o);
    if (h.status != SolveStatus::Converged) {
      if (!(h.max_residual <= kUsableResidual)) {
        throw SolverError("the manifold harmonics did not converge: " + residual_summary(h));
      }
      out.warning = "the basis is less accurate than asked: " + residual_summary(h);
    } else if (!out.file.empty()) {
      try {
        save_basis(out.file, h, mesh, cache_precision(h));
      } catch (const std::exception& e) {
        std::cerr << "specdeform: warning: basis not cached: " << e.what() << "\n";
      }
    }
  }
  out.harmonics = std::make_shared<const ManifoldHarmonics>(std::move(h));
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace specdeform
