#include "deform/reduced_forms.h"

#include <algorithm>

#include "linalg/blas_threads.h"
#include "linalg/mass_operator.h"
#include "linalg/parallel.h"

namespace specdeform::detail {

Eigen::MatrixXd reduced_stiffness(const Eigen::SparseMatrix<double>& K, const Eigen::MatrixXd& U) {
  const Eigen::Index m = U.cols();
  // Column blocks of K U (K column-major times contiguous columns of U: no strided rows), each
  // thread its own blocks, then U^T times the block.
  constexpr Eigen::Index kColumns = 16;
  Eigen::MatrixXd S(m, m);
  const SingleThreadedBlas blas;  // the two threads are ours
  const auto columns = [&](Eigen::Index first, Eigen::Index step) {
    Eigen::MatrixXd KU;
    for (Eigen::Index c = first * kColumns; c < m; c += step * kColumns) {
      const Eigen::Index w = std::min(kColumns, m - c);
      KU.noalias() = K * U.middleCols(c, w);
      S.middleCols(c, w).noalias() = U.transpose() * KU;
    }
  };
  run_pair([&] { columns(1, 2); }, [&] { columns(0, 2); });
  return 0.5 * (S + S.transpose());
}

Eigen::MatrixXd reduced_stiffness(const Eigen::SparseMatrix<double>& K,
                                  const ManifoldHarmonics& basis) {
  if (basis.rayleigh_ritz) return basis.eigenvalues.asDiagonal();
  return reduced_stiffness(K, basis.basis);
}

Eigen::MatrixXd reduced_bending(const Eigen::MatrixXd& S, const Eigen::VectorXd& area,
                                const Eigen::MatrixXd& U, bool orthonormal) {
  if (orthonormal) return S * S;
  const Eigen::SparseMatrix<double> M(area.asDiagonal());
  return S * MassOperator(M).gram(U) * S;
}

}  // namespace specdeform::detail
