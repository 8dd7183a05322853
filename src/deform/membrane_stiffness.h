// Internal: the stiffness matrix of ARAP's membrane term. The cotangent weights of K that are
// negative (pairs of obtuse angles) are dropped: with them a cluster's rest covariance
// sum w_ij e_ij e_ij^T can be indefinite, and its best-fitting rotation at rest is then not the
// identity (the rest pose would not be a minimum). The dropped part K+ - K is a Laplacian with
// the negative weights' magnitudes: positive semidefinite.
#pragma once

#include <Eigen/Sparse>

namespace specdeform::detail {

// K+ (n x n): K's positive off-diagonal entries (negative weights) set to zero, the diagonal
// the negated sum of the rest, so K+ 1 = 0.
inline Eigen::SparseMatrix<double> membrane_stiffness(const Eigen::SparseMatrix<double>& K) {
  Eigen::SparseMatrix<double> out = K;
  for (int j = 0; j < out.outerSize(); ++j) {
    double diagonal = 0.0;
    for (Eigen::SparseMatrix<double>::InnerIterator it(out, j); it; ++it) {
      if (it.row() == j) continue;
      if (it.value() > 0.0) it.valueRef() = 0.0;
      diagonal -= it.value();
    }
    out.coeffRef(j, j) = diagonal;
  }
  out.prune(0.0);
  return out;
}

}  // namespace specdeform::detail
