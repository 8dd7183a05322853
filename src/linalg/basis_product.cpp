#include "basis_product.h"

#include <algorithm>

#include "huge_pages.h"
#include "parallel.h"
#include "specdeform/exceptions.h"

namespace specdeform::detail {

namespace {

constexpr int kBlockRows = 256;

// Rows [begin, end) of base + H C (base and H column-major with leading dimension n), each
// row's three sums handed to store(row, x, y, z).
template <typename Scalar, typename Store>
[[gnu::always_inline]] inline void add_rows(const double* base, const Scalar* H, Eigen::Index n,
                                            int m, const double* C, Eigen::Index begin,
                                            Eigen::Index end, Store store) {
  for (Eigen::Index r0 = begin; r0 < end; r0 += kBlockRows) {
    const int rows = static_cast<int>(std::min<Eigen::Index>(kBlockRows, end - r0));
    double acc[3][kBlockRows] = {};
    for (int k = 0; k < m; ++k) {
      const Scalar* h = H + k * n + r0;
      const double c0 = C[k], c1 = C[m + k], c2 = C[2 * m + k];
      for (int r = 0; r < rows; ++r) {
        const double v = h[r];
        acc[0][r] += v * c0;
        acc[1][r] += v * c1;
        acc[2][r] += v * c2;
      }
    }
    for (int r = 0; r < rows; ++r) {
      const Eigen::Index i = r0 + r;
      store(i, base[i] + acc[0][r], base[n + i] + acc[1][r], base[2 * n + i] + acc[2][r]);
    }
  }
}

// Output: column-major doubles (leading dimension n), or rows of three floats `stride` apart.
struct Doubles {
  double* out;
  Eigen::Index n;
  void operator()(Eigen::Index i, double x, double y, double z) const {
    out[i] = x;
    out[n + i] = y;
    out[2 * n + i] = z;
  }
};
struct FloatRows {
  float* out;
  Eigen::Index stride;
  void operator()(Eigen::Index i, double x, double y, double z) const {
    float* row = out + i * stride;
    row[0] = static_cast<float>(x);
    row[1] = static_cast<float>(y);
    row[2] = static_cast<float>(z);
  }
};

// Compiled for AVX2 as well, chosen at run time: no -march flag is needed (one function per
// basis and output type: clang multiversions no templates).
__attribute__((target_clones("avx2", "default"))) void add_rows_double(
    const double* base, const double* H, Eigen::Index n, int m, const double* C, Eigen::Index begin,
    Eigen::Index end, Doubles store) {
  add_rows(base, H, n, m, C, begin, end, store);
}
__attribute__((target_clones("avx2", "default"))) void add_rows_float(
    const double* base, const float* H, Eigen::Index n, int m, const double* C, Eigen::Index begin,
    Eigen::Index end, Doubles store) {
  add_rows(base, H, n, m, C, begin, end, store);
}
__attribute__((target_clones("avx2", "default"))) void add_rows_double_to_floats(
    const double* base, const double* H, Eigen::Index n, int m, const double* C, Eigen::Index begin,
    Eigen::Index end, FloatRows store) {
  add_rows(base, H, n, m, C, begin, end, store);
}
__attribute__((target_clones("avx2", "default"))) void add_rows_float_to_floats(
    const double* base, const float* H, Eigen::Index n, int m, const double* C, Eigen::Index begin,
    Eigen::Index end, FloatRows store) {
  add_rows(base, H, n, m, C, begin, end, store);
}

template <typename Matrix, typename Store, typename Kernel>
void add_product(const Eigen::MatrixX3d& base, const Matrix& H, const Eigen::MatrixX3d& C,
                 Store store, Kernel kernel) {
  if (C.rows() != H.cols() || base.rows() != H.rows()) {
    throw InputError("basis product: the sizes do not match");
  }
  const Eigen::Index blocks = (H.rows() + kBlockRows - 1) / kBlockRows;
  split_in_two(blocks, [&](Eigen::Index begin, Eigen::Index end) {
    kernel(base.data(), H.data(), H.rows(), static_cast<int>(H.cols()), C.data(),
           begin * kBlockRows, std::min(end * kBlockRows, H.rows()), store);
  });
}

template <typename Store>
void add_factored_product(const Eigen::MatrixX3d& base, const FactoredBasis& H,
                          const Eigen::MatrixX3d& C, Store store) {
  const auto& P = H.prolongation;
  if (C.rows() != H.coarse.cols() || base.rows() != P.rows() || P.cols() != H.coarse.rows() ||
      !P.isCompressed()) {
    throw InputError("basis product: the sizes do not match");
  }
  const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> ZC = H.coarse * C;
  const int* start = P.outerIndexPtr();
  const int* column = P.innerIndexPtr();
  const double* value = P.valuePtr();
  const double* b = base.data();
  const Eigen::Index n = P.rows();
  split_in_two(n, [&](Eigen::Index begin, Eigen::Index end) {
    for (Eigen::Index i = begin; i < end; ++i) {
      double x = 0.0, y = 0.0, z = 0.0;
      for (int k = start[i]; k < start[i + 1]; ++k) {
        const double* row = ZC.data() + 3 * Eigen::Index{column[k]};
        x += value[k] * row[0];
        y += value[k] * row[1];
        z += value[k] * row[2];
      }
      store(i, b[i] + x, b[n + i] + y, b[2 * n + i] + z);
    }
  });
}

// H = P Z's rows [begin, end) into H (column-major, leading dimension n), Z row-major with
// `padded` columns (zeros past m): per tile of kTile rows and chunk of kChunk columns, each row's
// kChunk sums kept in registers, then stored a column of the tile at a time.
constexpr int kTile = 64;
constexpr int kChunk = 16;
using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
__attribute__((target_clones("avx2", "default"))) void prolongate_rows(
    const int* start, const int* column, const double* value, const double* Z, Eigen::Index padded,
    Eigen::Index m, double* H, Eigen::Index n, Eigen::Index begin, Eigen::Index end) {
  alignas(64) double tile[kChunk][kTile];
  for (Eigen::Index first = begin; first < end; first += kTile) {
    const int rows = static_cast<int>(std::min<Eigen::Index>(kTile, end - first));
    for (Eigen::Index c = 0; c < m; c += kChunk) {
      for (int r = 0; r < rows; ++r) {
        double sum[kChunk];
        sparse_row_product<kChunk>(start, column, value, Z + c, padded, first + r, sum);
        for (int q = 0; q < kChunk; ++q) tile[q][r] = sum[q];
      }
      const int width = static_cast<int>(std::min<Eigen::Index>(kChunk, m - c));
      for (int q = 0; q < width; ++q) std::copy_n(tile[q], rows, H + (c + q) * n + first);
    }
  }
}

}  // namespace

void add_basis_product(const Eigen::MatrixX3d& base, const Eigen::MatrixXd& H,
                       const Eigen::MatrixX3d& C, Eigen::MatrixX3d& out) {
  out.resize(H.rows(), 3);
  add_product(base, H, C, Doubles{out.data(), H.rows()}, add_rows_double);
}

void add_basis_product(const Eigen::MatrixX3d& base, const Eigen::MatrixXf& H,
                       const Eigen::MatrixX3d& C, Eigen::MatrixX3d& out) {
  out.resize(H.rows(), 3);
  add_product(base, H, C, Doubles{out.data(), H.rows()}, add_rows_float);
}

void add_basis_product(const Eigen::MatrixX3d& base, const Eigen::MatrixXd& H,
                       const Eigen::MatrixX3d& C, Eigen::Ref<FloatVertices> out) {
  if (out.rows() != H.rows()) throw InputError("basis product: the sizes do not match");
  add_product(base, H, C, FloatRows{out.data(), out.outerStride()}, add_rows_double_to_floats);
}

void add_basis_product(const Eigen::MatrixX3d& base, const Eigen::MatrixXf& H,
                       const Eigen::MatrixX3d& C, Eigen::Ref<FloatVertices> out) {
  if (out.rows() != H.rows()) throw InputError("basis product: the sizes do not match");
  add_product(base, H, C, FloatRows{out.data(), out.outerStride()}, add_rows_float_to_floats);
}

void add_basis_product(const Eigen::MatrixX3d& base, const FactoredBasis& H,
                       const Eigen::MatrixX3d& C, Eigen::MatrixX3d& out) {
  out.resize(H.prolongation.rows(), 3);
  add_factored_product(base, H, C, Doubles{out.data(), out.rows()});
}

void add_basis_product(const Eigen::MatrixX3d& base, const FactoredBasis& H,
                       const Eigen::MatrixX3d& C, Eigen::Ref<FloatVertices> out) {
  if (out.rows() != H.prolongation.rows()) {
    throw InputError("basis product: the sizes do not match");
  }
  add_factored_product(base, H, C, FloatRows{out.data(), out.outerStride()});
}

Eigen::MatrixXd factored_product(const FactoredBasis& H, Eigen::MatrixXd storage) {
  const auto& P = H.prolongation;
  const Eigen::Index m = H.coarse.cols();
  const Eigen::Index padded = (m + kChunk - 1) / kChunk * kChunk;
  RowMajor Z = RowMajor::Zero(H.coarse.rows(), padded);
  Z.leftCols(m) = H.coarse;
  Eigen::MatrixXd out = storage.rows() == P.rows() && storage.cols() == m
                            ? std::move(storage)
                            : large_matrix(P.rows(), m);
  split_in_two(P.rows(), [&](Eigen::Index begin, Eigen::Index end) {
    prolongate_rows(P.outerIndexPtr(), P.innerIndexPtr(), P.valuePtr(), Z.data(), padded, m,
                    out.data(), P.rows(), begin, end);
  });
  return out;
}

}  // namespace specdeform::detail
