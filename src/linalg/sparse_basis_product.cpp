#include "sparse_basis_product.h"

#include <algorithm>

#include "parallel.h"
#include "specdeform/exceptions.h"

namespace specdeform::detail {

namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using Sparse = Eigen::SparseMatrix<double>;

constexpr Eigen::Index kBlockRows = 64;  // 64 rows of m = 100 doubles: 51 KB, in the L2 cache

// out.row(i) += value * row (m entries).
__attribute__((target_clones("avx2", "default"))) void add_scaled(double* out, const double* row,
                                                                  double value, int m) {
  for (int c = 0; c < m; ++c) out[c] += value * row[c];
}

// Rows [begin, end) of H into the accumulators.
void accumulate(const std::vector<const Sparse*>& A, const Eigen::MatrixXd& H, Eigen::Index begin,
                Eigen::Index end, std::vector<RowMatrix>& out) {
  const int m = static_cast<int>(H.cols());
  RowMatrix block(kBlockRows, m);
  for (Eigen::Index r0 = begin; r0 < end; r0 += kBlockRows) {
    const Eigen::Index rows = std::min(kBlockRows, end - r0);
    block.topRows(rows) = H.middleRows(r0, rows);
    for (size_t j = 0; j < A.size(); ++j) {
      for (Eigen::Index r = 0; r < rows; ++r) {
        for (Sparse::InnerIterator it(*A[j], r0 + r); it; ++it) {
          add_scaled(out[j].row(it.row()).data(), block.row(r).data(), it.value(), m);
        }
      }
    }
  }
}

}  // namespace

std::vector<Eigen::MatrixXd> sparse_basis_products(const std::vector<const Sparse*>& A,
                                                   const Eigen::MatrixXd& H) {
  std::vector<RowMatrix> first, second;
  for (const Sparse* a : A) {
    if (a->cols() != H.rows()) {
      throw InputError("sparse basis product: " + std::to_string(a->cols()) + " columns against " +
                       std::to_string(H.rows()) + " rows");
    }
    first.push_back(RowMatrix::Zero(a->rows(), H.cols()));
    second.push_back(RowMatrix::Zero(a->rows(), H.cols()));
  }
  const Eigen::Index n = H.rows();
  const Eigen::Index half = (n / 2 + kBlockRows - 1) / kBlockRows * kBlockRows;
  run_pair([&] { accumulate(A, H, std::min(half, n), n, second); },
           [&] { accumulate(A, H, 0, std::min(half, n), first); });
  std::vector<Eigen::MatrixXd> out;
  for (size_t j = 0; j < A.size(); ++j) out.emplace_back(first[j] + second[j]);
  return out;
}

}  // namespace specdeform::detail
