#include "deform/reduced_forms.h"

#include <algorithm>

#include "linalg/mass_operator.h"
#include "linalg/parallel.h"

namespace specdeform::detail {

Eigen::MatrixXd reduced_stiffness(const Eigen::SparseMatrix<double>& K, const Eigen::MatrixXd& U) {
  const Eigen::Index n = U.rows(), m = U.cols();
  Eigen::MatrixXd half[2];
  const auto accumulate = [&](Eigen::Index begin, Eigen::Index end, Eigen::MatrixXd& out) {
    out = Eigen::MatrixXd::Zero(m, m);
    constexpr Eigen::Index kRows = 2048;
    Eigen::MatrixXd KU;
    for (Eigen::Index r = begin; r < end; r += kRows) {
      const Eigen::Index rows = std::min(kRows, end - r);
      KU.noalias() = K.middleCols(r, rows).transpose() * U;  // rows r.. of K U (K symmetric)
      out.noalias() += U.middleRows(r, rows).transpose() * KU;
    }
  };
  run_pair([&] { accumulate(n / 2, n, half[1]); }, [&] { accumulate(0, n / 2, half[0]); });
  const Eigen::MatrixXd S = half[0] + half[1];
  return 0.5 * (S + S.transpose());
}

Eigen::MatrixXd reduced_bending(const Eigen::MatrixXd& S, const Eigen::VectorXd& area,
                                const Eigen::MatrixXd& U, bool orthonormal) {
  if (orthonormal) return S * S;
  const Eigen::SparseMatrix<double> M(area.asDiagonal());
  return S * MassOperator(M).gram(U) * S;
}

}  // namespace specdeform::detail
