#include "specdeform/spectral/manifold_harmonics.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <cholmod.h>

#include <Spectra/SymGEigsShiftSolver.h>
#include <Eigen/CholmodSupport>
#include <Eigen/Eigenvalues>

#include "linalg/basis_sweep.h"
#include "linalg/parallel.h"
#include "linalg/triangular_solver.h"
#include "specdeform/exceptions.h"
#include "specdeform/operators/cotan_laplacian.h"

namespace specdeform {

namespace {

using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;
using Sparse = Eigen::SparseMatrix<double>;
using detail::RowMatrix;

// Meshes this small (or bases this close to complete) are solved densely.
constexpr int kDenseLimit = 1200;

// M X, with a fast path for a diagonal (lumped) M.
class MassOperator {
 public:
  explicit MassOperator(const Sparse& M) : M_(M) {
    diagonal_ = M.nonZeros() == M.rows();
    for (int j = 0; j < M.outerSize() && diagonal_; ++j)
      for (Sparse::InnerIterator it(M, j); it; ++it)
        if (it.row() != it.col()) diagonal_ = false;
    if (diagonal_) d_ = M.diagonal();
  }
  template <typename Derived>
  Mat apply(const Eigen::MatrixBase<Derived>& X) const {
    if (diagonal_) return d_.asDiagonal() * X;
    return M_ * X;
  }
  // out = M X, in out's memory.
  void apply(const RowMatrix& X, RowMatrix& out) const {
    if (diagonal_) {
      out.noalias() = d_.asDiagonal() * X;
    } else {
      out.noalias() = M_ * X;
    }
  }
  // X^T M X; for a diagonal M in blocks of rows, without an n x k temporary.
  template <typename Derived>
  Mat gram(const Eigen::MatrixBase<Derived>& X) const {
    if (!diagonal_) return X.transpose() * (M_ * X);
    constexpr Eigen::Index kRows = 4096;
    Mat G = Mat::Zero(X.cols(), X.cols());
    for (Eigen::Index r = 0; r < X.rows(); r += kRows) {
      const Eigen::Index rows = std::min(kRows, X.rows() - r);
      const auto block = X.middleRows(r, rows);
      G.noalias() += block.transpose() * (d_.segment(r, rows).asDiagonal() * block);
    }
    return G;
  }
  // The M-norm of each column of X.
  Vec norms(const Mat& X) const {
    if (!diagonal_) return (M_ * X).cwiseProduct(X).colwise().sum().cwiseMax(0.0).cwiseSqrt();
    return (X.array().square().colwise() * d_.array()).colwise().sum().cwiseMax(0.0).sqrt();
  }
  // X -= V D (when D is given), then P = V^T M X and G = X^T M X (those given), V's first k
  // columns: one pass over V for a lumped mass (linalg/basis_sweep.h).
  void project(const RowMatrix& V, Eigen::Index k, RowMatrix& X, const RowMatrix* D, RowMatrix* P,
               RowMatrix* G) const {
    if (diagonal_) {
      detail::sweep_basis(V, k, X, {.subtract = D, .weights = &d_, .projection = P, .gram = G});
      return;
    }
    if (D != nullptr) detail::sweep_basis(V, k, X, {.subtract = D});
    if (P == nullptr && G == nullptr) return;
    const RowMatrix Y = M_ * X;
    detail::sweep_basis(V, k, X, {.weighted = &Y, .projection = P, .gram = G});
  }
  const Sparse& matrix() const { return M_; }

 private:
  const Sparse& M_;
  bool diagonal_ = false;
  Vec d_;
};

Mat random_block(int rows, int cols, std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Mat X(rows, cols);
  for (Eigen::Index j = 0; j < X.size(); ++j) X.data()[j] = normal(rng);
  return X;
}

// Factorization of S = K - sigma M with CHOLMOD: supernodal LL^T when sigma is below the
// spectrum (S positive definite), simplicial LDL^T for an interior shift; then solved with
// linalg/triangular_solver.h (two threads, a block of right-hand sides interleaved). A shift
// that falls (nearly) on an eigenvalue makes S (nearly) singular: `usable()` tells, and the
// caller moves the shift.
class ShiftInvert {
 public:
  ShiftInvert(const Sparse& K, const Sparse& M, double sigma, std::mt19937_64& rng)
      : sigma_(sigma), S_(K - sigma * M) {
    cholmod_common common;
    cholmod_start(&common);
    common.supernodal = definite() ? CHOLMOD_SUPERNODAL : CHOLMOD_SIMPLICIAL;
    common.final_ll = definite();
    Sparse lower = S_.triangularView<Eigen::Lower>();
    cholmod_sparse A = Eigen::viewAsCholmod(lower);
    A.stype = -1;
    cholmod_factor* factor = cholmod_analyze(&A, &common);
    ok_ = factor != nullptr && cholmod_factorize(&A, factor, &common) &&
          common.status == CHOLMOD_OK && factor->minor == factor->n;
    if (ok_) {
      try {
        solver_.assign(factor);
      } catch (const SolverError&) {
        ok_ = false;
      }
    }
    cholmod_free_factor(&factor, &common);
    cholmod_finish(&common);
    if (ok_ && !definite()) {
      const RowMatrix b = random_block(static_cast<int>(S_.rows()), 1, rng);
      RowMatrix x;
      solve(b, x);
      ok_ = x.allFinite() && (b - S_ * x).norm() <= 1e-10 * b.norm();
    }
  }
  bool usable() const { return ok_; }
  // X = (K - sigma M)^-1 B, in X's memory. LDL^T of an indefinite matrix is computed without
  // pivoting; one step of iterative refinement brings its solves from ~1e-10 back to round-off,
  // which the Krylov relation needs.
  void solve(const RowMatrix& B, RowMatrix& X) {
    solver_.solve(B, X, workspace_);
    if (definite()) return;
    residual_ = B;
    residual_.noalias() -= S_ * X;
    solver_.solve(residual_, correction_, workspace_);
    X += correction_;
  }
  double sigma() const { return sigma_; }

 private:
  bool definite() const { return sigma_ < 0.0; }
  double sigma_;
  Sparse S_;
  bool ok_ = false;
  detail::TriangularSolver solver_;
  std::vector<double> workspace_;
  RowMatrix residual_, correction_;
};

// Cholesky QR, twice (Fukaya et al. 2014): per pass W := W U^-1 with U^T U = W^T M W, and
// R := U R, so that W R stays the same. `gram` is W^T M W where already known. BLAS-3; accurate
// when W is not too ill-conditioned, false (W R still the same) where it is.
template <typename Derived>
bool cholesky_qr2(const Eigen::MatrixBase<Derived>& block, const MassOperator& M, Mat& R,
                  Mat gram = Mat()) {
  auto& W = const_cast<Eigen::MatrixBase<Derived>&>(block);  // Eigen's idiom for writable blocks
  for (int pass = 0; pass < 2; ++pass) {
    if (pass > 0 || gram.size() == 0) gram = M.gram(W);
    const Eigen::LLT<Mat> llt(0.5 * (gram + gram.transpose()));
    if (llt.info() != Eigen::Success) return false;
    const Vec r = llt.matrixLLT().diagonal();
    if (!(r.minCoeff() > 1e-6 * r.maxCoeff())) return false;
    llt.matrixU().solveInPlace<Eigen::OnTheRight>(W);
    R = Mat(llt.matrixU()) * R;
  }
  return true;
}

bool cholesky_qr2(Mat& W, const MassOperator& M) {
  Mat R = Mat::Identity(W.cols(), W.cols());
  return cholesky_qr2(W, M, R);
}

using Basis = Eigen::Ref<const Mat>;

// Makes the columns of W M-orthogonal to the columns of each basis in `against` (each
// M-orthonormal): block classical Gram-Schmidt (BLAS-3), repeated only when it cancelled most of
// a column (Kahan-Parlett "twice is enough").
void project_out(Mat& W, std::initializer_list<Basis> against, const MassOperator& M) {
  if (std::all_of(against.begin(), against.end(), [](const Basis& B) { return B.cols() == 0; }))
    return;
  Vec before = M.norms(W);
  for (int pass = 0; pass < 2; ++pass) {
    for (const Basis& B : against) {  // B^T M W, with M applied to the thinner of the two
      if (B.cols() == 0) continue;
      const Mat C =
          B.cols() < W.cols() ? Mat(M.apply(B).transpose() * W) : Mat(B.transpose() * M.apply(W));
      W.noalias() -= B * C;
    }
    const Vec after = M.norms(W);
    if ((after.array() > 0.5 * before.array()).all()) break;
    before = after;
  }
}

// Gram-Schmidt of W's columns in order, each against the ones before it twice, then normalised:
// W (before) = W (after) R, R upper triangular (overwritten). A column left with less than
// `vanish` of its M-norm is handed to replace(j) instead (its column of R zero), which puts
// another direction there.
template <typename Replace>
void column_gram_schmidt(Mat& W, const MassOperator& M, double vanish, Mat& R, Replace replace) {
  R.setZero();
  for (int j = 0; j < W.cols(); ++j) {
    const double norm0 = std::sqrt(std::max(0.0, W.col(j).dot(M.apply(W.col(j)).col(0))));
    for (int pass = 0; pass < 2 && j > 0; ++pass) {
      const Vec c = W.leftCols(j).transpose() * M.apply(W.col(j)).col(0);
      W.col(j) -= W.leftCols(j) * c;
      R.col(j).head(j) += c;
    }
    const double norm = std::sqrt(std::max(0.0, W.col(j).dot(M.apply(W.col(j)).col(0))));
    if (norm > vanish * norm0 && norm > 0.0) {
      R(j, j) = norm;
      W.col(j) /= norm;
    } else {
      R.col(j).setZero();
      replace(j);
    }
  }
}

// Makes the columns of W M-orthonormal and M-orthogonal to the bases in `against`: project_out,
// then Cholesky QR within the block, or Gram-Schmidt where W is ill-conditioned. A column that
// vanishes is replaced by a random one.
void orthonormalize(Mat& W, std::initializer_list<Basis> against, const MassOperator& M,
                    std::mt19937_64& rng) {
  for (int attempt = 0; attempt < 3; ++attempt) {
    project_out(W, against, M);
    if (cholesky_qr2(W, M)) return;
    bool replaced = false;
    Mat R = Mat::Zero(W.cols(), W.cols());
    column_gram_schmidt(W, M, 1e-8, R, [&](int j) {
      W.col(j) = random_block(static_cast<int>(W.rows()), 1, rng);
      replaced = true;
    });
    if (!replaced) return;
  }
  throw SolverError("cannot extend the Krylov basis (the problem is smaller than the basis)");
}

struct BandResult {
  Vec lambda;  // unit-area scale, ascending
  Mat H;       // M-orthonormal, orthogonal to the kept pairs
  bool converged = true;
  int restarts = 0;
  long long solves = 0;
};

struct BandSettings {
  int wanted;    // pairs nearest sigma to converge
  int block;     // columns per block
  int subspace;  // maximal basis size
  double tolerance;
  int max_restarts;
};

// Replaces the first k columns of V by V[:, :k] Z (k x c), c <= k, in place, a block of rows at a
// time, so that no second n x k buffer is needed.
template <typename Matrix>
void multiply_in_place(Matrix& V, Eigen::Index k, const Mat& Z) {
  constexpr int kRows = 2048;
  Mat chunk;
  for (Eigen::Index r = 0; r < V.rows(); r += kRows) {
    const Eigen::Index rows = std::min<Eigen::Index>(kRows, V.rows() - r);
    chunk.noalias() = V.block(r, 0, rows, k) * Z;
    V.block(r, 0, rows, Z.cols()) = chunk;
  }
}

// Shift-invert block Krylov-Schur (Stewart 2001, in block form) for the `wanted` eigenpairs of
// K h = lambda M h nearest to op.sigma(), in the M-orthogonal complement of the pairs already
// found. Every block is deflated against `near` (found pairs close enough to sigma to be
// amplified by the shift-invert); the result is made orthogonal to all of `found` at the end.
// With A = (K - sigma M)^-1 M it maintains the Krylov relation
//     A V = V T + Q F^T,    V^T M V = I,  Q^T M Q = I,  V^T M Q = 0,
// so Ritz pairs (theta, y = V z) of T have the residual A y - theta y = Q F^T z for free, and
// A y / theta = y + Q F^T z / theta is one step of inverse iteration, also for free.
// `progress(fraction)` is called before every block step with the fraction of the work done,
// estimated from the steps taken and the pairs each restart converged (the first pass is
// taken for half of the work until the first restart tells).
BandResult solve_band(ShiftInvert& op, const MassOperator& M, const Basis& found, const Basis& near,
                      const BandSettings& set, std::mt19937_64& rng,
                      const std::function<void(double)>& progress) {
  const int n = static_cast<int>(M.matrix().rows());
  const int b = set.block, s = set.subspace;
  const int width = (b + 7) / 8 * 8;  // basis_sweep's blocks: a multiple of 8 columns
  const double sigma = op.sigma();
  RowMatrix V(n, s);
  Mat T(0, 0), F(0, b);
  int k = 0;
  Mat start = random_block(n, b, rng);
  orthonormalize(start, {found}, M, rng);
  RowMatrix Q = start;
  BandResult out;
  // Buffers kept from step to step: no page faults for large meshes. Row-major: the solver's
  // permutation then moves whole rows.
  RowMatrix X = RowMatrix::Zero(n, width), D1, D2, gram, MQ, solved;
  Mat W;
  int steps = 0, last_converged = 0;
  double estimate = 2.0 * (s / b), done = 0.0;  // total block steps, fraction reported
  for (;;) {
    while (k + b <= s) {
      done = std::max(done, std::min(0.99, steps++ / estimate));
      progress(done);
      V.middleCols(k, b) = Q;
      M.apply(Q, MQ);
      op.solve(MQ, solved);
      out.solves += b;
      // W = V C + Q' R: block classical Gram-Schmidt against V, twice, each pass's subtraction
      // fused with the next one's projection; then Cholesky QR within the block.
      X.leftCols(b) = solved;
      M.project(V, k + b, X, nullptr, &D1, nullptr);
      M.project(V, k + b, X, &D1, &D2, nullptr);
      M.project(V, k + b, X, &D2, nullptr, near.cols() > 0 ? nullptr : &gram);
      const Mat C = (D1 + D2).leftCols(b);
      if (near.cols() > 0) {
        W = X.leftCols(b);
        project_out(W, {near}, M);
        X.leftCols(b) = W;
        gram = M.gram(W);
      }
      Mat R = Mat::Identity(b, b);
      if (!cholesky_qr2(X.leftCols(b), M, R, gram.topLeftCorner(b, b))) {  // ill-conditioned
        W = X.leftCols(b);
        Mat Rg = Mat::Zero(b, b);
        column_gram_schmidt(W, M, 1e-10, Rg, [&](int j) {
          // invariant subspace found: continue with a fresh direction
          Mat fresh = random_block(n, 1, rng);
          orthonormalize(fresh, {found, Mat(V.leftCols(k + b)), W.leftCols(j)}, M, rng);
          W.col(j) = fresh.col(0);
        });
        X.leftCols(b) = W;
        R = Rg * R;
      }
      Q = X.leftCols(b);
      Mat Tn = Mat::Zero(k + b, k + b);
      Tn.topLeftCorner(k, k) = T;
      Tn.bottomLeftCorner(b, k) = F.transpose();
      Tn.rightCols(b) = C;
      T = 0.5 * (Tn + Tn.transpose());
      F = Mat::Zero(k + b, b);
      F.bottomRows(b) = R.transpose();
      k += b;
    }
    Eigen::SelfAdjointEigenSolver<Mat> eig(T);
    std::vector<int> order(k);
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int i, int j) {
      return std::abs(eig.eigenvalues()[i]) > std::abs(eig.eigenvalues()[j]);
    });
    const int keep = std::min(s - b, std::max(set.wanted + b, (set.wanted + s) / 2));
    Mat Z(k, keep);
    Vec theta(keep);
    for (int i = 0; i < keep; ++i) {
      Z.col(i) = eig.eigenvectors().col(order[i]);
      theta[i] = eig.eigenvalues()[order[i]];
    }
    const Mat FZ = F.transpose() * Z;  // b x keep: Ritz residuals in the basis Q
    int converged = 0;
    while (converged < keep) {
      // The refined vector A y / theta has the residual ||r||_M / theta^2 (see eigen_residual).
      const double t = theta[converged];
      const double lambda = sigma + 1.0 / t;
      if (!(FZ.col(converged).norm() <= set.tolerance * std::max(std::abs(lambda), 1.0) * t * t))
        break;
      ++converged;
    }
    const int gained = converged - last_converged;
    last_converged = converged;
    const double restarts_left =
        gained > 0 ? double(set.wanted - converged) / gained : set.max_restarts - out.restarts;
    estimate = steps + std::max(0.0, restarts_left) * ((s - keep) / b);
    if (converged >= set.wanted || out.restarts >= set.max_restarts) {
      out.converged = converged >= set.wanted;
      const int count = std::max(converged, std::min(set.wanted, keep));
      Mat G = V.leftCols(k) * Z.leftCols(count);
      G.noalias() += Q * (FZ.leftCols(count) * theta.head(count).cwiseInverse().asDiagonal());
      project_out(G, {found}, M);  // Rayleigh-Ritz makes G M-orthonormal
      out.H = std::move(G);
      out.lambda = (sigma + theta.head(count).cwiseInverse().array()).matrix();
      return out;
    }
    ++out.restarts;  // thick restart with the `keep` best Ritz vectors
    multiply_in_place(V, k, Z);
    T = theta.asDiagonal();
    F = FZ.transpose();
    k = keep;
  }
}

// Rayleigh-Ritz of (K, M) on the span of H (independent columns): an M-orthonormal basis of
// eigenvector approximations, sorted ascending.
void rayleigh_ritz(const Sparse& K, const MassOperator& M, Mat& H, Vec& lambda) {
  const Mat A = H.transpose() * (K * H);
  const Mat B = M.gram(H);
  Eigen::GeneralizedSelfAdjointEigenSolver<Mat> eig(0.5 * (A + A.transpose()),
                                                    0.5 * (B + B.transpose()));
  if (eig.info() != Eigen::Success) throw SolverError("Rayleigh-Ritz step failed");
  multiply_in_place(H, H.cols(), eig.eigenvectors());
  lambda = eig.eigenvalues();
}

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

void report(const ManifoldHarmonicsOptions& o, double fraction, std::string_view stage) {
  if (o.progress) o.progress(std::clamp(fraction, 0.0, 1.0), stage);
}

// Unit-area scale: eigenvalues and basis for K, M / area.
struct Spectrum {
  Vec lambda;
  Mat H;
  SolveStatus status = SolveStatus::Converged;
  int bands = 0, restarts = 0;
  long long solves = 0;
  bool cluster_truncated = false;
};

// lambda_m and the next eigenvalue are equal up to round-off and discretisation noise.
bool same_eigenvalue(double a, double b) {
  return std::abs(a - b) <= 1e-6 * std::max(1.0, std::abs(b));
}

Spectrum solve_dense(const Sparse& K, const Sparse& M, int m) {
  Eigen::GeneralizedSelfAdjointEigenSolver<Mat> eig{Mat(K), Mat(M)};
  if (eig.info() != Eigen::Success) throw SolverError("dense generalized eigensolver failed");
  Spectrum out{eig.eigenvalues().head(m), eig.eigenvectors().leftCols(m)};
  out.bands = 1;
  out.cluster_truncated = m < K.rows() && same_eigenvalue(out.lambda[m - 1], eig.eigenvalues()[m]);
  return out;
}

Spectrum solve_lanczos(const Sparse& K, const Sparse& M, int m, const ManifoldHarmonicsOptions& o) {
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
  Spectrum out{eigs.eigenvalues(), eigs.eigenvectors()};
  out.status = eigs.info() == Spectra::CompInfo::Successful ? SolveStatus::Converged
                                                            : SolveStatus::NotConverged;
  out.bands = 1;
  out.restarts = static_cast<int>(eigs.num_iterations());
  out.solves = op.solves();
  return out;
}

// Each pair's residual on the unit-area scale (see eigen_residual), and its rounding floor: the
// rounding error of forming K h - lambda M h in the same measure, eps A || |K||h| +
// |lambda| |M||h| ||_{D^-1} / max(A lambda, 1). No solver gets a residual below its floor; it
// matters on meshes with nearly degenerate triangles, whose huge cotangent weights and tiny
// areas put it above the tolerance.
struct PairErrors {
  Vec residual, floor;
};

// In blocks of kColumns pairs, each copied row-major, rows split between two threads: per row
// of K (CSR) one pass over its entries serves all the block's residuals and floors.
PairErrors pair_errors(const Sparse& K, const Sparse& M, const Mat& H, const Vec& lambda) {
  constexpr int kColumns = 16;
  using RowSparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  using Block = Eigen::Matrix<double, Eigen::Dynamic, kColumns, Eigen::RowMajor>;
  using Sums = Eigen::Array<double, kColumns, 1>;
  const RowSparse Kr = K, Mr = M;
  const double area = M.sum();
  const Vec d_inv = (M * Vec::Ones(M.rows())).cwiseInverse();
  const Eigen::Index n = H.rows();
  PairErrors out{Vec(H.cols()), Vec(H.cols())};
  Block block(n, kColumns);
  for (Eigen::Index j = 0; j < H.cols(); j += kColumns) {
    const Eigen::Index c = std::min<Eigen::Index>(kColumns, H.cols() - j);
    block.setZero();
    block.leftCols(c) = H.middleCols(j, c);
    Sums l = Sums::Zero();
    l.head(c) = lambda.segment(j, c).array();
    Sums residual2[2] = {Sums::Zero(), Sums::Zero()}, floor2[2] = {Sums::Zero(), Sums::Zero()};
    detail::split_in_two(n, [&](Eigen::Index begin, Eigen::Index end) {
      const int t = begin == 0 ? 0 : 1;
      for (Eigen::Index i = begin; i < end; ++i) {
        Sums kh = Sums::Zero(), mh = Sums::Zero(), kh_abs = Sums::Zero(), mh_abs = Sums::Zero();
        for (RowSparse::InnerIterator it(Kr, i); it; ++it) {
          const Sums h = block.row(it.col()).transpose().array();
          kh += it.value() * h;
          kh_abs += std::abs(it.value()) * h.abs();
        }
        for (RowSparse::InnerIterator it(Mr, i); it; ++it) {
          const Sums h = block.row(it.col()).transpose().array();
          mh += it.value() * h;
          mh_abs += std::abs(it.value()) * h.abs();
        }
        residual2[t] += d_inv[i] * (kh - l * mh).square();
        floor2[t] += d_inv[i] * (kh_abs + l.abs() * mh_abs).square();
      }
    });
    for (Eigen::Index p = 0; p < c; ++p) {
      const double scale = area / std::max(area * lambda[j + p], 1.0);
      out.residual[j + p] = scale * std::sqrt(residual2[0][p] + residual2[1][p]);
      out.floor[j + p] =
          scale * std::numeric_limits<double>::epsilon() * std::sqrt(floor2[0][p] + floor2[1][p]);
    }
  }
  return out;
}

// Whether every pair's residual is within `factor` times the tolerance, or, where rounding
// alone exceeds the tolerance, within 100 times its rounding floor.
bool residuals_within(const Vec& residual, const Vec& floors, double tolerance, double factor) {
  for (Eigen::Index j = 0; j < residual.size(); ++j) {
    if (residual[j] > std::max(factor * tolerance, 100 * floors[j])) return false;
  }
  return true;
}

// The middle of the widest gap between consecutive values of `known` (sorted) around `target`,
// so that a shift placed there stays clear of eigenvalues already seen.
double clear_shift(double target, const std::vector<double>& known) {
  for (size_t i = 0; i + 1 < known.size(); ++i) {
    if (known[i] <= target && target <= known[i + 1]) return 0.5 * (known[i] + known[i + 1]);
  }
  return target;
}

// K's null space, known exactly: the constants on each connected component of K's graph (the
// stiffness matrix's energy vanishes only there), M-normalised. n x (number of components).
Mat stiffness_null_space(const Sparse& K, const Sparse& M) {
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
  std::vector<int> label(n, -1);
  int count = 0;
  for (int i = 0; i < n; ++i) {
    int& l = label[find(i)];
    if (l < 0) l = count++;
    label[i] = l;
  }
  Mat Z = Mat::Zero(n, count);
  for (int i = 0; i < n; ++i) Z(i, label[i]) = 1.0;
  const Vec norms = (Z.transpose() * (M * Z)).diagonal().cwiseSqrt();
  return Z * norms.cwiseInverse().asDiagonal();
}

Spectrum solve_block_krylov(const Sparse& K, const Sparse& Mmat, int m,
                            const ManifoldHarmonicsOptions& o) {
  const int n = static_cast<int>(K.rows());
  const MassOperator M(Mmat);
  std::mt19937_64 rng(o.seed);
  // Up to 150 pairs in one band; beyond, bands of 90 (measured fastest on the armadillo at
  // m = 1000: the orthogonalisation grows with the square of the band, a factorisation is cheap).
  const int band = o.band_size > 0 ? o.band_size : (m <= 150 ? m : 90);
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
    BandSettings set;
    set.wanted = std::min(std::min(band, m - count) + (last_band ? 2 : 0), n - count);  // +2: gap
    // Blocks of 8 (the sweeps' width, so no padded columns), 4 for small bands: measured on the
    // armadillo, 8 beat 7 for the bands of 90 at m = 1000 and 12 or 16 at m = 100 and 150.
    set.block = o.block_size > 0 ? o.block_size : (set.wanted < 72 ? 4 : 8);
    set.subspace = std::min(n - count, set.wanted + std::max(set.wanted, 4 * set.block));
    set.subspace = std::max(set.block, set.subspace / set.block * set.block);
    set.tolerance = o.tolerance;
    set.max_restarts = o.max_restarts;
    report(o, double(count) / m, "factorization");
    ShiftInvert op(K, Mmat, sigma, rng);
    ++out.bands;
    if (!op.usable()) {  // the shift sits on an eigenvalue: move it a little
      retry(sigma + 0.1 * spacing);
      continue;
    }
    report(o, double(count) / m, "eigenvectors");
    // Found pairs within about twice the band's expected radius of the shift are amplified by
    // the shift-invert as much as the wanted ones: keep the Krylov space clear of them.
    const double last =
        count > 0 ? out.lambda[count - 1] : -std::numeric_limits<double>::infinity();
    int near = count;
    while (near > 0 && out.lambda[near - 1] >= sigma - 1.2 * set.wanted * spacing) --near;
    const int band_pairs = std::min(set.wanted, m - count);
    BandResult r = solve_band(
        op, M, out.H.leftCols(count), out.H.middleCols(near, count - near), set, rng,
        [&](double fraction) { report(o, (count + fraction * band_pairs) / m, "eigenvectors"); });
    out.restarts += r.restarts;
    out.solves += r.solves;
    rayleigh_ritz(K, M, r.H, r.lambda);
    std::vector<double> seen(1, count > 0 ? last : sigma);
    seen.insert(seen.end(), r.lambda.begin(), r.lambda.end());
    if (sigma > 0.0) {  // an interior shift: check the band (the caller checks all pairs)
      const auto [residual, floors] = pair_errors(K, Mmat, r.H, r.lambda);
      if (r.converged && !residuals_within(residual, floors, o.tolerance, 10)) {
        // Inaccurate solves broke the Krylov relation (a shift close to an eigenvalue): redo
        // the band with the shift in a gap between the eigenvalues seen.
        retry(clear_shift(sigma, seen));
        continue;
      }
      if (!residuals_within(residual, floors, o.tolerance, 100)) r.converged = false;
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
    sigma = out.lambda[count - 1] + 0.35 * band * std::max(spacing, 1e-6);
  }
  return out;
}

}  // namespace

double eigen_residual(const Sparse& K, const Sparse& M, const Mat& H, const Vec& lambda) {
  return H.cols() == 0 ? 0.0 : pair_errors(K, M, H, lambda).residual.maxCoeff();
}

std::string residual_summary(const ManifoldHarmonics& h, double tolerance) {
  std::ostringstream s;
  s << std::setprecision(2) << "residual " << h.max_residual << " (tolerance " << tolerance
    << ", rounding floor " << h.rounding_floor << ")";
  return s.str();
}

double orthonormality_error(const Sparse& M, const Mat& H) {
  const MassOperator op(M);
  double worst = 0.0;
  constexpr int kColumns = 128;  // lower triangle of H^T M H, a block column at a time
  for (Eigen::Index j = 0; j < H.cols(); j += kColumns) {
    const Eigen::Index c = std::min<Eigen::Index>(kColumns, H.cols() - j);
    Mat G = H.rightCols(H.cols() - j).transpose() * op.apply(H.middleCols(j, c));
    G.topRows(c) -= Mat::Identity(c, c);
    worst = std::max(worst, G.cwiseAbs().maxCoeff());
  }
  return worst;
}

ManifoldHarmonics compute_manifold_harmonics(const Sparse& K, const Sparse& M,
                                             const ManifoldHarmonicsOptions& o) {
  const int n = static_cast<int>(K.rows());
  const int m = o.num_modes;
  if (K.rows() != K.cols() || M.rows() != n || M.cols() != n) {
    throw InputError("manifold harmonics: K and M must be square matrices of the same size");
  }
  if (m < 1 || m > n) {
    throw InputError("manifold harmonics: the number of modes must be in [1, " + std::to_string(n) +
                     "] for this mesh, got " + std::to_string(m));
  }
  if (!(o.shift < 0.0)) throw InputError("manifold harmonics: the shift must be negative");
  if (!(o.tolerance > 0.0)) throw InputError("manifold harmonics: the tolerance must be positive");
  const Vec row_sums = M * Vec::Ones(n);
  const int massless = static_cast<int>((row_sums.array() <= 0.0).count());
  if (massless > 0) {
    throw InputError("manifold harmonics: " + std::to_string(massless) +
                     " vertices have zero area (only degenerate faces touch them)");
  }
  const double area = row_sums.sum();
  const Sparse M_unit = M / area;

  Spectrum s;
  const bool dense = n <= kDenseLimit || 3 * m > 2 * n;
  if (dense) {
    if (n > 6000) {
      throw InputError("manifold harmonics: m = " + std::to_string(m) + " is too close to n = " +
                       std::to_string(n) + " for an iterative solver; use m <= 2n/3");
    }
    report(o, 0.0, "dense eigensolver");
    s = solve_dense(K, M_unit, m);
  } else if (o.solver == EigenSolver::Lanczos) {
    s = solve_lanczos(K, M_unit, m, o);
  } else {
    s = solve_block_krylov(K, M_unit, m, o);
  }
  ManifoldHarmonics out;
  out.status = s.status;
  out.cluster_truncated = s.cluster_truncated;
  out.bands = s.bands;
  out.restarts = s.restarts;
  out.solves = s.solves;
  out.eigenvalues = s.lambda / area;
  out.basis = std::move(s.H);
  out.basis /= std::sqrt(area);
  for (int j = 0; j < m; ++j) {  // sign convention: largest-magnitude entry positive
    Eigen::Index i;
    out.basis.col(j).cwiseAbs().maxCoeff(&i);
    if (out.basis(i, j) < 0) out.basis.col(j) *= -1.0;
  }
  report(o, 1.0, "verification");
  const auto [residual, floors] = pair_errors(K, M, out.basis, out.eigenvalues);
  out.max_residual = residual.maxCoeff();
  out.rounding_floor = floors.maxCoeff();
  out.max_orthogonality_error = orthonormality_error(M, out.basis);
  if (!residuals_within(residual, floors, o.tolerance, 100)) out.status = SolveStatus::NotConverged;
  return out;
}

ManifoldHarmonics compute_manifold_harmonics(const TriangleMesh& mesh,
                                             const ManifoldHarmonicsOptions& options) {
  const LaplacianOperators L = laplacian_operators(mesh, options.mass, options.laplacian);
  ManifoldHarmonics h = compute_manifold_harmonics(L.stiffness, L.mass, options);
  h.mass = options.mass;
  h.laplacian = options.laplacian;
  return h;
}

}  // namespace specdeform
