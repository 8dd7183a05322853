#include "linalg/krylov_schur.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include <Eigen/Eigenvalues>

#include "linalg/parallel.h"
#include "specdeform/exceptions.h"

namespace specdeform::detail {

using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;
using Sparse = Eigen::SparseMatrix<double>;

namespace {

// Replaces the first k columns of V by V[:, :k] Z (k x c), c <= k, in place, a block of rows at a
// time, so that no second n x k buffer is needed; the rows in two halves on two threads.
template <typename Matrix>
void multiply_in_place(Matrix& V, Eigen::Index k, const Mat& Z) {
  constexpr int kRows = 2048;
  split_in_two(V.rows(), [&](Eigen::Index begin, Eigen::Index end) {
    Mat chunk;
    for (Eigen::Index r = begin; r < end; r += kRows) {
      const Eigen::Index rows = std::min<Eigen::Index>(kRows, end - r);
      chunk.noalias() = V.block(r, 0, rows, k) * Z;
      V.block(r, 0, rows, Z.cols()) = chunk;
    }
  });
}

}  // namespace

KrylovSchurResult krylov_schur(ShiftInvert& op, const MassOperator& M, const Basis& found,
                               const Basis& near, const KrylovSchurSettings& set,
                               std::mt19937_64& rng, const std::function<void(double)>& progress) {
  const int n = static_cast<int>(M.matrix().rows());
  const int b = set.block, s = set.subspace;
  const int width = (b + 7) / 8 * 8;  // basis_sweep's blocks: a multiple of 8 columns
  const double sigma = op.sigma();
  // The basis is kept lagged: V's first k columns are V_true L (L unit upper triangular, V_true
  // the M-orthonormal Krylov basis of the relation), and the next block Q is Q_true + V_true E
  // (E: its second Gram-Schmidt pass's coefficients, never subtracted). The next block's
  // projections remove that part along V_true anyway; only their coefficients are corrected,
  // through the relation: two passes over V per block instead of three.
  RowMatrix V(n, s);
  Mat T(0, 0), F(0, b), L(0, 0), E(0, b);
  int k = 0;
  Mat start = random_block(n, b, rng);
  orthonormalize(start, {found}, M, rng);
  RowMatrix Q = start;
  KrylovSchurResult out;
  // Buffers kept from step to step: no page faults for large meshes. Row-major: the solver's
  // permutation then moves whole rows.
  RowMatrix X = RowMatrix::Zero(n, width), D1, D2, gram, MQ, solved;
  Mat W;
  // (x, in V_true's coordinates) -> the same in V's, and for the lagged projections
  // V^T M y = L^T V_true^T M y the way back.
  const auto to_stored = [](const Mat& l, const Mat& x) {
    return Mat(l.triangularView<Eigen::UnitUpper>().solve(x));
  };
  const auto to_true = [](const Mat& l, const RowMatrix& p, int cols) {
    return Mat(l.triangularView<Eigen::UnitUpper>().transpose().solve(p.leftCols(cols)));
  };
  const auto padded = [&](const Mat& x) {  // as basis_sweep takes coefficients
    RowMatrix p = RowMatrix::Zero(x.rows(), width);
    p.leftCols(x.cols()) = x;
    return p;
  };
  int steps = 0, last_converged = 0;
  double estimate = 2.0 * (s / b), done = 0.0;  // total block steps, fraction reported
  for (;;) {
    while (k + b <= s) {
      done = std::max(done, std::min(0.99, steps++ / estimate));
      progress(done);
      V.middleCols(k, b) = Q;
      Mat Lx = Mat::Identity(k + b, k + b);
      Lx.topLeftCorner(k, k) = L;
      Lx.topRightCorner(k, b) = E;
      M.apply(Q, MQ);
      op.solve(MQ, solved);
      out.solves += b;
      // Block classical Gram-Schmidt against V_true, twice, each pass's subtraction fused with
      // the next one's projection; the second pass's subtraction is lagged (E) where the block
      // can be normalised by Cholesky QR alone. A Q_true = A Q - A V_true E = A Q - V_true
      // (T E) - Q_true (F^T E) by the relation: a part in the span of V_true, which the
      // projections take out anyway, so only its coefficients change.
      X.leftCols(b) = solved;
      if (near.cols() > 0) {
        W = X.leftCols(b);
        project_out(W, {near}, M);
        X.leftCols(b) = W;
      }
      M.project(V, k + b, X, nullptr, &D1, nullptr);
      Mat C1 = to_true(Lx, D1, b);
      D1 = padded(to_stored(Lx, C1));
      C1.topRows(k) -= T * E;
      C1.bottomRows(b) -= F.transpose() * E;
      M.project(V, k + b, X, &D1, &D2, &gram);
      Mat C2 = to_true(Lx, D2, b);
      const Mat C = C1 + C2;
      Mat R = Mat::Identity(b, b);
      if (!cholesky_qr2(X.leftCols(b), M, R, gram.topLeftCorner(b, b), &C2)) {
        D2 = padded(to_stored(Lx, C2));  // the second pass's subtraction, now
        M.project(V, k + b, X, &D2, nullptr, nullptr);
        C2.setZero();
        W = X.leftCols(b);
        if (!cholesky_qr2(W, M, R)) {  // ill-conditioned
          Mat Rg = Mat::Zero(b, b);
          column_gram_schmidt(W, M, 1e-10, Rg, [&](int j) {
            // invariant subspace found: continue with a fresh direction
            Mat fresh = random_block(n, 1, rng);
            orthonormalize(fresh, {found, Mat(V.leftCols(k + b)), W.leftCols(j)}, M, rng);
            W.col(j) = fresh.col(0);
          });
          R = Rg * R;
        }
        X.leftCols(b) = W;
      }
      Q = X.leftCols(b);
      E = C2;
      L = std::move(Lx);
      Mat Tn = Mat::Zero(k + b, k + b);
      Tn.topLeftCorner(k, k) = T;
      Tn.bottomLeftCorner(b, k) = F.transpose();
      Tn.rightCols(b) = C;
      T = 0.5 * (Tn + Tn.transpose());
      F = Mat::Zero(k + b, b);
      F.bottomRows(b) = R.transpose();
      k += b;
    }
    if (!E.isZero(0.0)) {  // the block waiting outside V: Q_true = Q - V_true E
      X.leftCols(b) = Q;
      D2 = padded(to_stored(L, E));
      M.project(V, k, X, &D2, nullptr, nullptr);
      Q = X.leftCols(b);
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
    const Mat stored_Z = to_stored(L, Z);
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
      Mat G = V.leftCols(k) * stored_Z.leftCols(count);
      G.noalias() += Q * (FZ.leftCols(count) * theta.head(count).cwiseInverse().asDiagonal());
      project_out(G, {found}, M);  // Rayleigh-Ritz makes G M-orthonormal
      out.H = std::move(G);
      out.lambda = (sigma + theta.head(count).cwiseInverse().array()).matrix();
      return out;
    }
    ++out.restarts;  // thick restart with the `keep` best Ritz vectors
    multiply_in_place(V, k, stored_Z);
    T = theta.asDiagonal();
    F = FZ.transpose();
    L = Mat::Identity(keep, keep);
    E = Mat::Zero(keep, b);
    k = keep;
  }
}

void rayleigh_ritz(const Sparse& K, const MassOperator& M, Mat& H, Vec& lambda) {
  const Mat A = H.transpose() * (K * H);
  const Mat B = M.gram(H);
  Eigen::GeneralizedSelfAdjointEigenSolver<Mat> eig(0.5 * (A + A.transpose()),
                                                    0.5 * (B + B.transpose()));
  if (eig.info() != Eigen::Success) throw SolverError("Rayleigh-Ritz step failed");
  multiply_in_place(H, H.cols(), eig.eigenvectors());
  lambda = eig.eigenvalues();
}

}  // namespace specdeform::detail
