#include "spectral/eigen_residual.h"

#include <cmath>
#include <limits>

#include "linalg/parallel.h"

namespace specdeform::detail {

using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;
using Sparse = Eigen::SparseMatrix<double>;

Vec PairErrors::thresholds(double tolerance, double floor_factor) const {
  return (floor_factor * floor.array()).max(tolerance).matrix();
}

bool PairErrors::within(double tolerance, double floor_factor, double factor) const {
  return (residual.array() <= factor * thresholds(tolerance, floor_factor).array()).all();
}

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
    split_in_two(n, [&](Eigen::Index begin, Eigen::Index end) {
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

}  // namespace specdeform::detail
