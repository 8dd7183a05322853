// Internal: the Gram-Schmidt products of a block Krylov method, one pass over the rows of a
// tall basis V (n x k of an n x s row-major matrix) and a thin block X (n x w, row-major, w a
// multiple of 8). For each row i, in this order:
//     X_i -= V_i D                 when `subtract` is given (D: k x w),
//     P   += V_i^T Y_i             when `projection` is given (P: k x w),
//     G   += X_i^T Y_i             when `gram` is given (G: w x w),
// with Y = diag(weights) X (a lumped mass), or Y = `weighted` (a mass matrix times X, formed by
// the caller), or Y = X. Fusing the subtraction of one Gram-Schmidt pass with the projections of
// the next reads V (far larger than the caches) once instead of twice; plain loops on two threads
// instead of BLAS calls, which would pack (copy) V each time and whose idle worker threads spin.
#pragma once

#include <Eigen/Core>

namespace specdeform::detail {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

struct SweepProducts {
  const RowMatrix* subtract = nullptr;       // D, k x w
  const Eigen::VectorXd* weights = nullptr;  // n
  const RowMatrix* weighted = nullptr;       // Y, n x w
  RowMatrix* projection = nullptr;           // P, resized to k x w
  RowMatrix* gram = nullptr;                 // G, resized to w x w
};

// V's first k columns against X; throws InputError on mismatched sizes.
void sweep_basis(const RowMatrix& V, Eigen::Index k, RowMatrix& X, const SweepProducts& products);

}  // namespace specdeform::detail
