#include "spectral/eigen_residual.h"

#include <cmath>
#include <limits>

#include "linalg/basis_product.h"
#include "linalg/huge_pages.h"
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

namespace {

constexpr int kColumns = 16;
using Block = Eigen::Matrix<double, Eigen::Dynamic, kColumns, Eigen::RowMajor>;
using Rows = Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor>>;

// Sums over the rows [begin, end) of d_i (K h - l M h)_i^2 and, with kFloors,
// d_i (|K||h| + |l| |M||h|)_i^2 for the kColumns columns of `block` (n x kColumns, row-major),
// added to residual2 and floor2.
template <bool kFloors>
[[gnu::always_inline]] inline void block_sums(const Rows& K, const Rows& M, const double* block,
                                              const double* l, const double* d_inv,
                                              Eigen::Index begin, Eigen::Index end,
                                              double* residual2, double* floor2) {
  // Row i of A times the block into ah, and of |A| times |block| into ah_abs (kFloors).
  const auto row_product = [block](const Rows& A, Eigen::Index i, double* ah, double* ah_abs) {
    for (int e = A.outerIndexPtr()[i]; e < A.outerIndexPtr()[i + 1]; ++e) {
      const double v = A.valuePtr()[e], a = std::abs(v);
      const double* h = block + kColumns * A.innerIndexPtr()[e];
      for (int q = 0; q < kColumns; ++q) {
        ah[q] += v * h[q];
        if constexpr (kFloors) ah_abs[q] += a * std::abs(h[q]);
      }
    }
  };
  for (Eigen::Index i = begin; i < end; ++i) {
    double kh[kColumns] = {}, mh[kColumns] = {}, kh_abs[kColumns] = {}, mh_abs[kColumns] = {};
    row_product(K, i, kh, kh_abs);
    row_product(M, i, mh, mh_abs);
    for (int q = 0; q < kColumns; ++q) {
      const double r = kh[q] - l[q] * mh[q];
      residual2[q] += d_inv[i] * r * r;
      if constexpr (kFloors) {
        const double f = kh_abs[q] + std::abs(l[q]) * mh_abs[q];
        floor2[q] += d_inv[i] * f * f;
      }
    }
  }
}

__attribute__((target_clones("avx2", "default"))) void sums_with_floors(
    const Rows& K, const Rows& M, const double* block, const double* l, const double* d_inv,
    Eigen::Index begin, Eigen::Index end, double* residual2, double* floor2) {
  block_sums<true>(K, M, block, l, d_inv, begin, end, residual2, floor2);
}

__attribute__((target_clones("avx2", "default"))) void sums(const Rows& K, const Rows& M,
                                                            const double* block, const double* l,
                                                            const double* d_inv, Eigen::Index begin,
                                                            Eigen::Index end, double* residual2,
                                                            double* floor2) {
  block_sums<false>(K, M, block, l, d_inv, begin, end, residual2, floor2);
}

// Rows [begin, end) of P Z into `block` (row-major, kColumns wide), Z row-major kColumns wide,
// and into `extreme` each column's entry of largest magnitude among them (signed).
__attribute__((target_clones("avx2", "default"))) void gather_rows(
    const int* start, const int* column, const double* value, const double* Z, Eigen::Index begin,
    Eigen::Index end, double* block, double* extreme) {
  for (Eigen::Index i = begin; i < end; ++i) {
    double row[kColumns];
    sparse_row_product<kColumns>(start, column, value, Z, kColumns, i, row);
    for (int q = 0; q < kColumns; ++q) {
      block[kColumns * i + q] = row[q];
      if (std::abs(row[q]) > std::abs(extreme[q])) extreme[q] = row[q];
    }
  }
}

// In blocks of kColumns pairs, each gathered row-major by fill(first column, columns, block),
// rows split between two threads: per row of K (CSR) one pass over its entries serves all the
// block's residuals and floors.
template <typename Fill>
PairErrors block_errors(const Sparse& K, const Sparse& M, Eigen::Index n, const Vec& lambda,
                        bool floors, Fill&& fill) {
  using Sums = Eigen::Array<double, kColumns, 1>;
  if (!K.isCompressed() || !M.isCompressed()) {
    Sparse Kc = K, Mc = M;
    Kc.makeCompressed();
    Mc.makeCompressed();
    return block_errors(Kc, Mc, n, lambda, floors, fill);
  }
  // K and M are symmetric: their compressed columns, read as rows, are their rows (no copy).
  const auto rows = [](const Sparse& A) {
    return Rows(A.rows(), A.cols(), A.nonZeros(), A.outerIndexPtr(), A.innerIndexPtr(),
                A.valuePtr());
  };
  const Rows Kr = rows(K), Mr = rows(M);
  const double area = M.sum();
  const Vec d_inv = (M * Vec::Ones(M.rows())).cwiseInverse();
  const Eigen::Index m = lambda.size();
  PairErrors out{Vec(m), Vec(m)};
  Block block(n, kColumns);
  advise_huge_pages(block.data(), sizeof(double) * static_cast<std::size_t>(block.size()));
  for (Eigen::Index j = 0; j < m; j += kColumns) {
    const Eigen::Index c = std::min<Eigen::Index>(kColumns, m - j);
    fill(j, c, block);
    Sums l = Sums::Zero();
    l.head(c) = lambda.segment(j, c).array();
    Sums residual2[2] = {Sums::Zero(), Sums::Zero()}, floor2[2] = {Sums::Zero(), Sums::Zero()};
    split_in_two(n, [&](Eigen::Index begin, Eigen::Index end) {
      const int t = begin == 0 ? 0 : 1;
      (floors ? sums_with_floors : sums)(Kr, Mr, block.data(), l.data(), d_inv.data(), begin, end,
                                         residual2[t].data(), floor2[t].data());
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

}  // namespace

PairErrors pair_errors(const Sparse& K, const Sparse& M, const Mat& H, const Vec& lambda,
                       bool floors) {
  return block_errors(K, M, H.rows(), lambda, floors,
                      [&H](Eigen::Index j, Eigen::Index c, Block& block) {
                        block.setZero();
                        block.leftCols(c) = H.middleCols(j, c);
                      });
}

PairErrors pair_errors(const Sparse& K, const Sparse& M, const FactoredBasis& H, const Vec& lambda,
                       Vec& largest) {
  const auto& P = H.prolongation;
  largest = Vec::Zero(H.coarse.cols());
  return block_errors(
      K, M, P.rows(), lambda, false, [&](Eigen::Index j, Eigen::Index c, Block& block) {
        Block Z = Block::Zero(H.coarse.rows(), kColumns);  // the block's columns of Z, row-major
        Z.leftCols(c) = H.coarse.middleCols(j, c);
        double extreme[2][kColumns] = {};
        split_in_two(P.rows(), [&](Eigen::Index begin, Eigen::Index end) {
          gather_rows(P.outerIndexPtr(), P.innerIndexPtr(), P.valuePtr(), Z.data(), begin, end,
                      block.data(), extreme[begin == 0 ? 0 : 1]);
        });
        for (Eigen::Index q = 0; q < c; ++q) {
          largest[j + q] =
              std::abs(extreme[1][q]) > std::abs(extreme[0][q]) ? extreme[1][q] : extreme[0][q];
        }
      });
}

}  // namespace specdeform::detail
