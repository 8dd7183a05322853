#include "linalg/mass_operator.h"

namespace specdeform::detail {

MassOperator::MassOperator(const Sparse& M) : M_(M) {
  diagonal_ = M.nonZeros() == M.rows();
  for (int j = 0; j < M.outerSize() && diagonal_; ++j)
    for (Sparse::InnerIterator it(M, j); it; ++it)
      if (it.row() != it.col()) diagonal_ = false;
  if (diagonal_) d_ = M.diagonal();
}

void MassOperator::apply(const RowMatrix& X, RowMatrix& out) const {
  if (diagonal_) {
    out.noalias() = d_.asDiagonal() * X;
  } else {
    out.noalias() = M_ * X;
  }
}

Eigen::VectorXd MassOperator::norms(const Mat& X) const {
  if (!diagonal_) return (M_ * X).cwiseProduct(X).colwise().sum().cwiseMax(0.0).cwiseSqrt();
  return (X.array().square().colwise() * d_.array()).colwise().sum().cwiseMax(0.0).sqrt();
}

void MassOperator::project(const RowMatrix& V, Eigen::Index k, RowMatrix& X, const RowMatrix* D,
                           RowMatrix* P, RowMatrix* G) const {
  if (diagonal_) {
    sweep_basis(V, k, X, {.subtract = D, .weights = &d_, .projection = P, .gram = G});
    return;
  }
  if (D != nullptr) sweep_basis(V, k, X, {.subtract = D});
  if (P == nullptr && G == nullptr) return;
  const RowMatrix Y = M_ * X;
  sweep_basis(V, k, X, {.weighted = &Y, .projection = P, .gram = G});
}

}  // namespace specdeform::detail
