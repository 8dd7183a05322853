#include "deform/reduced_forms.h"

#include <algorithm>

#include "linalg/parallel.h"

namespace specdeform::detail {

ReducedForms reduced_forms(const Eigen::SparseMatrix<double>& K, const Eigen::VectorXd& area,
                           const Eigen::MatrixXd& U, Bending bending) {
  const bool fine = bending == Bending::Fine;
  const Eigen::Index n = U.rows(), m = U.cols();
  ReducedForms half[2];
  const auto accumulate = [&](Eigen::Index begin, Eigen::Index end, ReducedForms& out) {
    out.stiffness = Eigen::MatrixXd::Zero(m, m);
    out.bending = Eigen::MatrixXd::Zero(fine ? m : 0, fine ? m : 0);
    constexpr Eigen::Index kRows = 2048;
    Eigen::MatrixXd KU;
    for (Eigen::Index r = begin; r < end; r += kRows) {
      const Eigen::Index rows = std::min(kRows, end - r);
      KU.noalias() = K.middleCols(r, rows).transpose() * U;  // rows r.. of K U (K symmetric)
      out.stiffness.noalias() += U.middleRows(r, rows).transpose() * KU;
      if (!fine) continue;
      const Eigen::MatrixXd scaled =
          area.segment(r, rows).cwiseSqrt().cwiseInverse().asDiagonal() * KU;
      out.bending.selfadjointView<Eigen::Lower>().rankUpdate(scaled.transpose());
    }
  };
  run_pair([&] { accumulate(n / 2, n, half[1]); }, [&] { accumulate(0, n / 2, half[0]); });
  ReducedForms out;
  out.stiffness = half[0].stiffness + half[1].stiffness;
  out.stiffness = 0.5 * (out.stiffness + out.stiffness.transpose()).eval();
  if (fine) {
    const Eigen::MatrixXd lower = half[0].bending + half[1].bending;
    out.bending = lower.selfadjointView<Eigen::Lower>();
  } else {
    out.bending = out.stiffness * out.stiffness;
  }
  return out;
}

}  // namespace specdeform::detail
