#include "spectral/eigensolvers.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>
#include <vector>

#include <Spectra/SymGEigsShiftSolver.h>
#include <Eigen/CholmodSupport>
#include <Eigen/Eigenvalues>

#include "linalg/blas_threads.h"
#include "linalg/krylov_schur.h"
#include "specdeform/exceptions.h"
#include "spectral/eigen_residual.h"

namespace specdeform::detail {

using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;
using Sparse = Eigen::SparseMatrix<double>;

namespace {

// Adapters that make a plain CHOLMOD shift-invert operator (supernodal LL^T, cholmod_solve) and
// M usable by Spectra: the baseline as the literature runs it.
class SpectraShiftInvertOp {
 public:
  using Scalar = double;
  SpectraShiftInvertOp(const Sparse& K, const Sparse& M) : K_(K), M_(M) {}
  Eigen::Index rows() const { return K_.rows(); }
  Eigen::Index cols() const { return K_.cols(); }
  void set_shift(double sigma) {
    llt_.compute(K_ - sigma * M_);
    if (llt_.info() != Eigen::Success) throw SolverError("factorization of K - sigma M failed");
  }
  void perform_op(const double* x, double* y) const {
    Eigen::Map<Vec>(y, rows()) = llt_.solve(Eigen::Map<const Vec>(x, rows()));
    ++solves_;
  }
  long long solves() const { return solves_; }

 private:
  const Sparse& K_;
  const Sparse& M_;
  Eigen::CholmodSupernodalLLT<Sparse, Eigen::Lower> llt_;
  mutable long long solves_ = 0;
};

class SpectraMassOp {
 public:
  using Scalar = double;
  explicit SpectraMassOp(const Sparse& M) : M_(M) {}
  Eigen::Index rows() const { return M_.rows(); }
  Eigen::Index cols() const { return M_.cols(); }
  void perform_op(const double* x, double* y) const {
    Eigen::Map<Vec>(y, rows()) = M_ * Eigen::Map<const Vec>(x, rows());
  }

 private:
  const Sparse& M_;
};

// lambda_m and the next eigenvalue are equal up to round-off and discretisation noise.
bool same_eigenvalue(double a, double b) {
  return std::abs(a - b) <= 1e-6 * std::max(1.0, std::abs(b));
}

}  // namespace

void report(const ManifoldHarmonicsOptions& o, double fraction, std::string_view stage) {
  if (o.progress) o.progress(std::clamp(fraction, 0.0, 1.0), stage);
}

Spectrum solve_dense(const Sparse& K, const Sparse& M, int m) {
  Eigen::GeneralizedSelfAdjointEigenSolver<Mat> eig{Mat(K), Mat(M)};
  if (eig.info() != Eigen::Success) throw SolverError("dense generalized eigensolver failed");
  Spectrum out;
  out.lambda = eig.eigenvalues().head(m);
  out.H = eig.eigenvectors().leftCols(m);
  // K's null space (one constant per connected component) has the eigenvalue 0 exactly, not
  // the solver's +-1e-16.
  const Eigen::Index zeros = std::min<Eigen::Index>(m, stiffness_null_space(K, M).cols());
  out.lambda.head(zeros).setZero();
  out.bands = 1;
  out.cluster_truncated = m < K.rows() && same_eigenvalue(out.lambda[m - 1], eig.eigenvalues()[m]);
  return out;
}

Spectrum solve_lanczos(const Sparse& K, const Sparse& M, const ManifoldHarmonicsOptions& o) {
  const int m = o.num_modes;
  SpectraShiftInvertOp op(K, M);
  SpectraMassOp mass(M);
  const int n = static_cast<int>(K.rows());
  const int ncv = std::min(n, 2 * m + 1);
  Spectra::SymGEigsShiftSolver<SpectraShiftInvertOp, SpectraMassOp, Spectra::GEigsMode::ShiftInvert>
      eigs(op, mass, m, ncv, o.shift);
  eigs.init();
  report(o, 0.1, "Lanczos");
  eigs.compute(Spectra::SortRule::LargestMagn, 10 * o.max_restarts, o.tolerance,
               Spectra::SortRule::SmallestAlge);
  Spectrum out;
  out.lambda = eigs.eigenvalues();
  out.H = eigs.eigenvectors();
  out.status = eigs.info() == Spectra::CompInfo::Successful ? SolveStatus::Converged
                                                            : SolveStatus::NotConverged;
  out.bands = 1;
  out.restarts = static_cast<int>(eigs.num_iterations());
  out.solves = op.solves();
  return out;
}

int stiffness_components(const Sparse& K, std::vector<int>& label) {
  const int n = static_cast<int>(K.rows());
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (int col = 0; col < K.outerSize(); ++col)
    for (Sparse::InnerIterator it(K, col); it; ++it)
      parent[find(static_cast<int>(it.row()))] = find(col);
  label.assign(n, -1);
  int count = 0;
  for (int i = 0; i < n; ++i) {
    int& l = label[find(i)];
    if (l < 0) l = count++;
    label[i] = l;
  }
  return count;
}

Mat stiffness_null_space(const Sparse& K, const Sparse& M) {
  const int n = static_cast<int>(K.rows());
  std::vector<int> label;
  const int count = stiffness_components(K, label);
  Mat Z = Mat::Zero(n, count);
  for (int i = 0; i < n; ++i) Z(i, label[i]) = 1.0;
  const Vec norms = (Z.transpose() * (M * Z)).diagonal().cwiseSqrt();
  return Z * norms.cwiseInverse().asDiagonal();
}

Spectrum solve_block_krylov(const Sparse& K, const Sparse& Mmat,
                            const ManifoldHarmonicsOptions& o) {
  const int n = static_cast<int>(K.rows());
  const int m = o.num_modes;
  const ManifoldHarmonicsPolicy& policy = o.policy;
  const MassOperator M(Mmat);
  ShiftInvertAnalysis analysis(K, Mmat);
  const SingleThreadedBlas blas;  // the loops' two threads are ours
  std::mt19937_64 rng(o.seed);
  const int band =
      o.band_size > 0 ? o.band_size : (m <= policy.single_band_limit ? m : policy.band_size);
  Spectrum out;
  out.H.resize(n, m);
  out.lambda.resize(m);
  // The zero eigenvalues are known: start from them, and keep the Krylov spaces clear of them
  // (their Ritz values 1/|sigma| would otherwise dwarf the others and magnify round-off).
  const Mat null_space = stiffness_null_space(K, Mmat);
  int count = std::min<int>(m, static_cast<int>(null_space.cols()));
  out.H.leftCols(count) = null_space.leftCols(count);
  out.lambda.head(count).setZero();
  if (count == m && null_space.cols() > m) out.cluster_truncated = true;
  double sigma = o.shift;
  double spacing = 4.0 * std::numbers::pi;  // Weyl's law on a closed unit-area surface
  int retries = 0;
  const auto retry = [&](double new_sigma) {
    if (++retries > 8) throw SolverError("band-by-band eigensolver: cannot place the shift");
    sigma = new_sigma;
  };
  while (count < m) {
    const bool last_band = count + band >= m;
    KrylovSchurSettings set;
    set.wanted = std::min(std::min(band, m - count) + (last_band ? 2 : 0), n - count);  // +2: gap
    set.block = o.block_size > 0 ? o.block_size : (set.wanted < policy.wide_block_from ? 4 : 8);
    set.subspace = std::min(n - count, set.wanted + std::max(set.wanted, 4 * set.block));
    set.subspace = std::max(set.block, set.subspace / set.block * set.block);
    set.tolerance = policy.krylov_margin * o.tolerance;
    set.max_restarts = o.max_restarts;
    report(o, double(count) / m, "factorization");
    ShiftInvert op(analysis, sigma, rng);
    ++out.bands;
    if (!op.usable()) {  // the shift sits on an eigenvalue: move it a little
      retry(sigma + 0.1 * spacing);
      continue;
    }
    report(o, double(count) / m, "eigenvectors");
    // Found pairs close to the shift are amplified by the shift-invert as much as the wanted
    // ones: keep the Krylov space clear of them.
    const double last =
        count > 0 ? out.lambda[count - 1] : -std::numeric_limits<double>::infinity();
    int near = count;
    while (near > 0 && out.lambda[near - 1] >= sigma - policy.near_radius * set.wanted * spacing)
      --near;
    const int band_pairs = std::min(set.wanted, m - count);
    KrylovSchurResult r = krylov_schur(
        op, M, out.H.leftCols(count), out.H.middleCols(near, count - near), set, rng,
        [&](double fraction) { report(o, (count + fraction * band_pairs) / m, "eigenvectors"); });
    out.restarts += r.restarts;
    out.solves += r.solves;
    rayleigh_ritz(K, M, r.H, r.lambda);
    std::vector<double> seen(1, count > 0 ? last : sigma);
    seen.insert(seen.end(), r.lambda.begin(), r.lambda.end());
    if (sigma > 0.0 && r.converged) {  // an interior shift: check the band
      const PairErrors errors = pair_errors(K, Mmat, r.H, r.lambda);
      if (!errors.within(o.tolerance, policy.floor_factor, policy.redo_factor)) {
        // Inaccurate solves broke the Krylov relation (a shift close to an eigenvalue): redo
        // the band with the shift in a gap between the eigenvalues seen.
        retry(clear_shift(sigma, seen));
        continue;
      }
    }
    double radius = 0.0;
    for (int i = 0; i < r.lambda.size(); ++i)
      radius = std::max(radius, std::abs(r.lambda[i] - sigma));
    if (sigma > 0.0 && r.converged &&
        sigma - radius > last + 1e-9 * std::max(1.0, std::abs(last))) {
      // The band does not reach down to the pairs already found: eigenvalues in between could
      // be missed. Move the shift down and redo the band.
      retry(clear_shift(last + 0.5 * (sigma - last), seen));
      continue;
    }
    retries = 0;
    if (!r.converged) out.status = SolveStatus::NotConverged;
    const int first_new = count;
    const int take = std::min<int>(static_cast<int>(r.lambda.size()), m - count);
    out.H.middleCols(count, take) = r.H.leftCols(take);
    out.lambda.segment(count, take) = r.lambda.head(take);
    count += take;
    if (count == m && take < r.lambda.size()) {
      out.cluster_truncated = same_eigenvalue(out.lambda[m - 1], r.lambda[take]);
    }
    if (count > first_new + 1) {
      spacing = (out.lambda[count - 1] - out.lambda[first_new]) / (count - first_new - 1);
    }
    // The next band's window (radius about band/2 spacings) reaches below the last pair found.
    sigma = out.lambda[count - 1] + policy.shift_advance * band * std::max(spacing, 1e-6);
  }
  return out;
}

}  // namespace specdeform::detail
