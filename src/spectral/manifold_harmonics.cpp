#include "specdeform/spectral/manifold_harmonics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

#include "linalg/basis_product.h"
#include "linalg/locality_order.h"
#include "linalg/mass_operator.h"
#include "linalg/parallel.h"
#include "specdeform/exceptions.h"
#include "spectral/coarse_space.h"
#include "spectral/eigen_residual.h"
#include "spectral/eigensolvers.h"
#include "spectral/piecewise.h"
#include "spectral/stage_clock.h"

namespace specdeform {

using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;
using Sparse = Eigen::SparseMatrix<double>;

namespace {
constexpr std::array<std::string_view, 3> kSolverNames{"krylov", "lanczos", "multilevel"};
}  // namespace

std::string_view name(EigenSolver solver) {
  return kSolverNames[static_cast<size_t>(solver)];
}

EigenSolver eigen_solver_from_name(std::string_view name) {
  for (size_t i = 0; i < kSolverNames.size(); ++i)
    if (kSolverNames[i] == name) return static_cast<EigenSolver>(i);
  throw InputError("unknown eigensolver '" + std::string(name) +
                   "' (krylov, lanczos or multilevel)");
}

EigenSolver default_eigensolver(int vertices, const ManifoldHarmonicsPolicy& policy) {
  return vertices >= policy.multilevel_from ? EigenSolver::Multilevel : EigenSolver::BlockKrylov;
}

void ManifoldHarmonicsPolicy::validate() const {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw InputError(std::string("manifold harmonics policy: ") + what);
  };
  require(dense_limit >= 0, "dense_limit must be >= 0");
  require(single_band_limit >= 1 && band_size >= 1, "band sizes must be >= 1");
  require(wide_block_from >= 1, "wide_block_from must be >= 1");
  require(shift_advance > 0.0 && shift_advance < 1.0, "shift_advance must be in (0, 1)");
  require(near_radius >= 0.0, "near_radius must be >= 0");
  require(krylov_margin > 0.0 && krylov_margin <= 1.0, "krylov_margin must be in (0, 1]");
  require(redo_factor >= 1.0 && floor_factor >= 1.0, "redo_factor and floor_factor must be >= 1");
  require(multilevel_samples_per_mode >= 1 && multilevel_min_samples >= 1,
          "multilevel sample counts must be >= 1");
  require(multilevel_support > 1.0, "multilevel_support must be > 1");
  require(multilevel_reduction >= 1, "multilevel_reduction must be >= 1");
  require(multilevel_from >= 0, "multilevel_from must be >= 0");
  require(reorder_from >= 0, "reorder_from must be >= 0");
  require(piece_min_modes >= 1 && piece_modes_limit >= 1,
          "piece_min_modes and piece_modes_limit must be >= 1");
  require(piece_basis_bytes > 0.0, "piece_basis_bytes must be > 0");
}

void ManifoldHarmonicsOptions::validate() const {
  if (num_modes < 1) throw InputError("manifold harmonics: the number of modes must be >= 1");
  if (!(shift < 0.0)) throw InputError("manifold harmonics: the shift must be negative");
  if (!(tolerance > 0.0)) throw InputError("manifold harmonics: the tolerance must be positive");
  if (block_size < 0 || band_size < 0) {
    throw InputError("manifold harmonics: block and band sizes must be >= 0 (0: automatic)");
  }
  if (max_restarts < 1) throw InputError("manifold harmonics: max_restarts must be >= 1");
  policy.validate();
}

double eigen_residual(const Sparse& K, const Sparse& M, const Mat& H, const Vec& lambda) {
  return H.cols() == 0 ? 0.0 : detail::pair_errors(K, M, H, lambda).residual.maxCoeff();
}

std::string residual_summary(const ManifoldHarmonics& h) {
  std::ostringstream s;
  s << std::setprecision(2);
  const ManifoldHarmonics::Pair& w = h.worst_pair;
  if (w.index < 0) {
    s << "residual " << h.max_residual << " (threshold " << h.threshold << ", rounding floor "
      << h.rounding_floor << ")";
    return s.str();
  }
  s << "pair " << w.index + 1 << " of " << h.basis.cols() << ": residual " << w.residual
    << " (its threshold " << w.threshold << ", rounding floor " << w.floor << ")";
  if (w.residual < h.max_residual) s << ", the largest residual " << h.max_residual;
  return s.str();
}

double orthonormality_error(const Sparse& M, const Mat& H) {
  // H^T M H in blocks of rows for a lumped M: no n x m temporary (2.2 GB at 2.77M vertices).
  const Mat G = detail::MassOperator(M).gram(H) - Mat::Identity(H.cols(), H.cols());
  return H.cols() == 0 ? 0.0 : G.cwiseAbs().maxCoeff();
}

namespace {

// One connected piece (or the whole mesh), M of unit area: the solver the options and the
// size ask for. `lengths`: the multilevel solver's distances (coarse_space.h).
detail::Spectrum solve_connected(const Sparse& K, const Sparse& M_unit, const Sparse* lengths,
                                 const ManifoldHarmonicsOptions& o) {
  const int n = static_cast<int>(K.rows());
  const int m = o.num_modes;
  const ManifoldHarmonicsPolicy& p = o.policy;
  const int first_band = std::min(m, p.single_band_limit) + 2;
  const bool dense = n <= p.dense_limit || 3 * m > 2 * n || 4 * first_band > n;
  const int samples = std::max(p.multilevel_min_samples, p.multilevel_samples_per_mode * m);
  if (o.solver == EigenSolver::Multilevel &&
      static_cast<double>(n) >= double(p.multilevel_reduction) * samples) {
    return detail::solve_multilevel(K, M_unit, *lengths, o);
  }
  if (dense) {
    if (n > 6000) {
      throw InputError("manifold harmonics: m = " + std::to_string(m) + " is too close to n = " +
                       std::to_string(n) + " for an iterative solver; use m <= 2n/3");
    }
    detail::report(o, 0.0, "dense eigensolver");
    return detail::solve_dense(K, M_unit, m);
  }
  if (o.solver == EigenSolver::Lanczos) return detail::solve_lanczos(K, M_unit, o);
  return detail::solve_block_krylov(K, M_unit, o);
}

ManifoldHarmonics harmonics_in_order(const Sparse& K, const Sparse& M, const Sparse* lengths,
                                     const ManifoldHarmonicsOptions& o);

// A factored basis's H = P Z, formed once, in the numbering it is returned in (into the memory
// the solver left in h.basis for it: detail::Spectrum::H).
void prolongate(ManifoldHarmonics& h, const ManifoldHarmonicsOptions& o) {
  detail::report(o, 1.0, "prolongation");
  h.basis = detail::factored_product(h.factored, std::move(h.basis));
}

// Both overloads: `lengths` gives the multilevel solver's distances, or null. Meshes of
// policy.reorder_from vertices or more are solved in a breadth-first numbering
// (linalg/locality_order.h), the basis's rows put back in theirs.
ManifoldHarmonics harmonics(const Sparse& K, const Sparse& M, const Sparse* lengths,
                            const ManifoldHarmonicsOptions& o) {
  o.validate();
  if (K.rows() != K.cols() || M.rows() != K.rows() || M.cols() != K.rows()) {
    throw InputError("manifold harmonics: K and M must be square matrices of the same size");
  }
  if (K.rows() < o.policy.reorder_from) {
    ManifoldHarmonics h = harmonics_in_order(K, M, lengths, o);
    if (!h.factored.empty()) prolongate(h, o);
    return h;
  }
  detail::report(o, 0.0, "ordering");
  const auto P = detail::breadth_first_order(K);
  // Swapped in: Eigen's sparse matrices are copied when assigned, even from a temporary.
  Sparse K_ordered, M_ordered, lengths_ordered;
  const auto renumber = [&P](const Sparse& A, Sparse& out) {
    Sparse renumbered = detail::renumbered(A, P);
    out.swap(renumbered);
  };
  detail::run_pair([&] { renumber(K, K_ordered); },
                   [&] {
                     renumber(M, M_ordered);
                     if (lengths) renumber(*lengths, lengths_ordered);
                   });
  ManifoldHarmonics h =
      harmonics_in_order(K_ordered, M_ordered, lengths ? &lengths_ordered : nullptr, o);
  detail::report(o, 1.0, "numbering back");
  if (h.factored.empty()) detail::permute_rows_back(P, h.basis);
  if (!h.factored.empty()) {
    detail::permute_rows_back(P, h.factored.prolongation);
    prolongate(h, o);
  }
  return h;
}

ManifoldHarmonics harmonics_in_order(const Sparse& K, const Sparse& M, const Sparse* lengths,
                                     const ManifoldHarmonicsOptions& o) {
  const int n = static_cast<int>(K.rows());
  const int m = o.num_modes;
  if (K.rows() != K.cols() || M.rows() != n || M.cols() != n) {
    throw InputError("manifold harmonics: K and M must be square matrices of the same size");
  }
  if (m > n) {
    throw InputError("manifold harmonics: the number of modes must be in [1, " + std::to_string(n) +
                     "] for this mesh, got " + std::to_string(m));
  }
  detail::report(o, 0.0, "checks");
  check_operators(K, M, "manifold harmonics");
  const Vec row_sums = M * Vec::Ones(n);
  const double area = row_sums.sum();
  const Sparse M_unit = M / area;
  const ManifoldHarmonicsPolicy& p = o.policy;

  std::vector<int> label;
  const int pieces = detail::stiffness_components(K, label);
  bool multilevel = false;
  const detail::ConnectedSolver connected = [&](const Sparse& K_piece, const Sparse& M_piece,
                                                const Sparse* lengths_piece,
                                                const ManifoldHarmonicsOptions& op) {
    detail::Spectrum piece = solve_connected(K_piece, M_piece, lengths_piece, op);
    multilevel = multilevel || piece.coarse_functions > 0;
    return piece;
  };
  const Sparse estimated = o.solver == EigenSolver::Multilevel && !lengths
                               ? detail::estimated_edge_lengths(K, M_unit)
                               : Sparse();
  if (!lengths && o.solver == EigenSolver::Multilevel) lengths = &estimated;
  detail::Spectrum s = pieces > 1
                           ? detail::solve_by_piece(K, M_unit, lengths, label, pieces, o, connected)
                           : connected(K, M_unit, lengths, o);
  const int columns = static_cast<int>(s.lambda.size());
  ManifoldHarmonics out;
  out.status = s.status;
  out.cluster_truncated = s.cluster_truncated;
  out.approximate = multilevel;
  out.rayleigh_ritz = multilevel;
  out.coarse_functions = s.coarse_functions;
  out.pieces = pieces;
  out.requested_modes = m;
  out.bands = s.bands;
  out.restarts = s.restarts;
  out.solves = s.solves;
  out.eigenvalues = s.lambda / area;
  out.basis = std::move(s.H);
  out.factored = std::move(s.factored);
  // Unit area, and the sign convention: each column's largest-magnitude entry positive. A
  // factored basis is checked from its factors, which give the signs on the way, and its H is
  // left for the caller to form (in the mesh's numbering: one pass over n x m); a dense one's
  // columns are split between two threads (two passes over n x m).
  detail::PairErrors errors;
  if (!out.factored.empty()) {
    detail::report(o, 1.0, "verification");
    out.factored.coarse /= std::sqrt(area);
    Vec largest;
    errors = detail::pair_errors(K, M, out.factored, out.eigenvalues, largest);
    for (int j = 0; j < columns; ++j)
      if (largest[j] < 0) out.factored.coarse.col(j) *= -1.0;
    out.max_orthogonality_error = s.orthonormality_error;
  } else {
    detail::report(o, 1.0, "signs");
    detail::split_in_two(columns, [&](Eigen::Index begin, Eigen::Index end) {
      for (Eigen::Index j = begin; j < end; ++j) {
        Eigen::Index i;
        out.basis.col(j).cwiseAbs().maxCoeff(&i);
        out.basis.col(j) *= (out.basis(i, j) < 0 ? -1.0 : 1.0) / std::sqrt(area);
      }
    });
    detail::report(o, 1.0, "verification");
    errors = detail::pair_errors(K, M, out.basis, out.eigenvalues, !multilevel);
    detail::report(o, 1.0, "orthonormality");
    out.max_orthogonality_error = orthonormality_error(M, out.basis);
  }
  out.residuals = errors.residual;
  out.max_residual = errors.residual.maxCoeff();
  out.rounding_floor = errors.floor.maxCoeff();
  const Vec thresholds = errors.thresholds(o.tolerance, p.floor_factor);
  out.threshold = thresholds.maxCoeff();
  if (columns > 0) {
    Eigen::Index worst;
    errors.residual.cwiseQuotient(thresholds).maxCoeff(&worst);
    out.worst_pair = {static_cast<int>(worst), errors.residual[worst], thresholds[worst],
                      errors.floor[worst]};
  }
  // An approximate basis is not meant to meet the tolerance: its status is the coarse solve's.
  if (!multilevel && !errors.within(o.tolerance, p.floor_factor)) {
    out.status = SolveStatus::NotConverged;
  }
  return out;
}

}  // namespace

ManifoldHarmonics compute_manifold_harmonics(const Sparse& K, const Sparse& M,
                                             const ManifoldHarmonicsOptions& options) {
  detail::StageClock clock;
  ManifoldHarmonicsOptions o = options;
  o.progress = clock.wrap(options.progress);
  ManifoldHarmonics h = harmonics(K, M, nullptr, o);
  h.stages = clock.stop();
  return h;
}

ManifoldHarmonics compute_manifold_harmonics(const TriangleMesh& mesh,
                                             const ManifoldHarmonicsOptions& options) {
  detail::StageClock clock;
  ManifoldHarmonicsOptions o = options;
  o.progress = clock.wrap(options.progress);
  detail::report(o, 0.0, "the Laplacian");
  const LaplacianOperators L = laplacian_operators(mesh, o.mass, o.laplacian);
  const bool multilevel = o.solver == EigenSolver::Multilevel;
  if (multilevel) detail::report(o, 0.0, "edge lengths");
  const Sparse lengths = multilevel ? detail::edge_lengths(L.stiffness, mesh.V) : Sparse();
  ManifoldHarmonics h = harmonics(L.stiffness, L.mass, multilevel ? &lengths : nullptr, o);
  h.mass = o.mass;
  h.laplacian = o.laplacian;
  h.stages = clock.stop();
  return h;
}

int default_modes(int vertices) {
  return std::max(1, std::min(ManifoldHarmonicsOptions{}.num_modes, vertices - 1));
}

}  // namespace specdeform
