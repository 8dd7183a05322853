// Internal: the mass matrix M (n x n, symmetric positive definite) as the eigensolvers apply it:
// products M X, Gram matrices X^T M X and M-norms, with a fast path for a lumped (diagonal) M
// that never forms M X. The matrix is referenced, not copied: it must outlive the operator.
#pragma once

#include <algorithm>

#include <Eigen/Core>
#include <Eigen/Sparse>

#include "linalg/basis_sweep.h"

namespace specdeform::detail {

class MassOperator {
 public:
  using Mat = Eigen::MatrixXd;
  using Sparse = Eigen::SparseMatrix<double>;

  explicit MassOperator(const Sparse& M);

  bool diagonal() const { return diagonal_; }
  const Sparse& matrix() const { return M_; }

  // M X.
  template <typename Derived>
  Mat apply(const Eigen::MatrixBase<Derived>& X) const {
    if (diagonal_) return d_.asDiagonal() * X;
    return M_ * X;
  }
  // out = M X, in out's memory.
  void apply(const RowMatrix& X, RowMatrix& out) const;

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
  Eigen::VectorXd norms(const Mat& X) const;

  // With V's first k columns (M-orthonormal): X -= V D when D is given, then P = V^T M X and
  // G = X^T M X where given; one pass over V for a lumped mass (linalg/basis_sweep.h), one more
  // product M X otherwise.
  void project(const RowMatrix& V, Eigen::Index k, RowMatrix& X, const RowMatrix* D, RowMatrix* P,
               RowMatrix* G) const;

 private:
  const Sparse& M_;
  bool diagonal_ = false;
  Eigen::VectorXd d_;
};

}  // namespace specdeform::detail
