// The multilevel approximation of the first m manifold harmonics (Nasikun, Brandt & Hildebrandt,
// "Fast approximation of Laplace-Beltrami eigenproblems", SGP 2018):
//  1. a coarse space of N locally supported partition-of-unity functions P (n x N,
//     coarse_space.h), N = max(samples_per_mode m, min_samples);
//  2. the Galerkin problem P^T K P z = lambda P^T M P z (N x N, sparse) solved exactly by the
//     block Krylov-Schur solver, its first m + 1 pairs (Z, Lambda; the last tells a truncated
//     cluster);
//  3. U = P Z: exactly M-orthonormal in the fine M (Z^T P^T M P Z = I) and U^T K U = Lambda,
//     returned as its factors (the caller forms U once, in the mesh's numbering, into the
//     memory returned in Spectrum::H).
// Measured on the armadillo (43k, m = 100): two Jacobi steps on the fine residuals and a
// Rayleigh-Ritz halved the eigenvalue error of a Wendland bump at support 2 (17% to 8.8%) for 3.3
// times the time; a wider, smoother bump did better for less (1.9%), so there is no fine step.
// The result is not made of eigenvectors of the fine problem: K U - M U Lambda is what the
// caller's verification measures and reports.
#include <algorithm>
#include <cmath>
#include <string>

#include "linalg/galerkin_product.h"
#include "linalg/huge_pages.h"
#include "linalg/parallel.h"
#include "specdeform/exceptions.h"
#include "spectral/coarse_space.h"
#include "spectral/eigensolvers.h"

namespace specdeform::detail {

using Sparse = Eigen::SparseMatrix<double>;

Spectrum solve_multilevel(const Sparse& K, const Sparse& M, const Sparse& lengths,
                          const ManifoldHarmonicsOptions& o) {
  const ManifoldHarmonicsPolicy& p = o.policy;
  const int m = o.num_modes;
  report(o, 0.0, "sampling");
  const EdgeGraph graph = edge_graph(lengths);
  const int samples = std::max(p.multilevel_min_samples, p.multilevel_samples_per_mode * m);
  // H = P Z is formed last, into fresh memory whose first touch costs its writer about as much
  // as the product (the kernel zeroing 553 MB at 692k vertices: 0.4-0.5 s on a virtual
  // machine): touched now, on the core the serial sampling leaves idle.
  Sampling farthest;
  Eigen::MatrixXd storage;
  run_pair([&] { farthest = farthest_points(graph, std::clamp(samples, 1, graph.size())); },
           [&] { storage = touched_matrix(K.rows(), m); });
  report(o, 0.03, "coarse space");
  CoarseSpace coarse = partition_of_unity(graph, farthest, p.multilevel_support);
  const Sparse& P = coarse.prolongation;
  const int N = static_cast<int>(P.cols());
  report(o, 0.05, "coarse operators");
  const auto [Kc, Mc] = galerkin_products(K, M, P, coarse.rows);

  // One pair more than m tells whether m ends inside a cluster.
  ManifoldHarmonicsOptions co = o;
  co.solver = EigenSolver::BlockKrylov;
  co.num_modes = std::min(N - 1, m + 1);
  if (co.num_modes < m) {
    throw InputError("multilevel eigensolver: " + std::to_string(N) +
                     " coarse functions cannot hold " + std::to_string(m) + " modes");
  }
  co.progress = [&o](double fraction, std::string_view stage) {
    report(o, 0.1 + 0.6 * fraction, "coarse " + std::string(stage));
  };
  ManifoldHarmonics h = compute_manifold_harmonics(Kc, Mc, co);
  Spectrum out;
  out.H.swap(storage);
  out.factored.prolongation.swap(coarse.rows);
  out.factored.prolongation.makeCompressed();
  out.factored.coarse = h.basis.leftCols(m);
  out.orthonormality_error = h.max_orthogonality_error;
  out.lambda = std::move(h.eigenvalues);
  out.cluster_truncated =
      out.lambda.size() > m &&
      std::abs(out.lambda[m] - out.lambda[m - 1]) <= 1e-6 * std::max(1.0, std::abs(out.lambda[m]));
  out.lambda.conservativeResize(m);
  out.status = h.status;
  out.bands = h.bands;
  out.restarts = h.restarts;
  out.solves = h.solves;
  out.coarse_functions = N;
  return out;
}

}  // namespace specdeform::detail
