#include "basis_product.h"

#include <algorithm>

#include "parallel.h"
#include "specdeform/exceptions.h"

namespace specdeform::detail {

namespace {

constexpr int kBlockRows = 256;

// Rows [begin, end) of out = base + H C, all column-major with leading dimension n.
template <typename Scalar>
[[gnu::always_inline]] inline void add_rows(const double* base, const Scalar* H, Eigen::Index n,
                                            int m, const double* C, double* out, Eigen::Index begin,
                                            Eigen::Index end) {
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
    for (int d = 0; d < 3; ++d)
      for (int r = 0; r < rows; ++r) out[d * n + r0 + r] = base[d * n + r0 + r] + acc[d][r];
  }
}

// Compiled for AVX2 as well, chosen at run time: no -march flag is needed.
__attribute__((target_clones("avx2", "default"))) void add_rows_double(
    const double* base, const double* H, Eigen::Index n, int m, const double* C, double* out,
    Eigen::Index begin, Eigen::Index end) {
  add_rows(base, H, n, m, C, out, begin, end);
}

__attribute__((target_clones("avx2", "default"))) void add_rows_float(
    const double* base, const float* H, Eigen::Index n, int m, const double* C, double* out,
    Eigen::Index begin, Eigen::Index end) {
  add_rows(base, H, n, m, C, out, begin, end);
}

template <typename Matrix, typename Kernel>
void add_product(const Eigen::MatrixX3d& base, const Matrix& H, const Eigen::MatrixX3d& C,
                 Eigen::MatrixX3d& out, Kernel kernel) {
  if (C.rows() != H.cols() || base.rows() != H.rows()) {
    throw InputError("basis product: the sizes do not match");
  }
  out.resize(H.rows(), 3);
  const Eigen::Index blocks = (H.rows() + kBlockRows - 1) / kBlockRows;
  split_in_two(blocks, [&](Eigen::Index begin, Eigen::Index end) {
    kernel(base.data(), H.data(), H.rows(), static_cast<int>(H.cols()), C.data(), out.data(),
           begin * kBlockRows, std::min(end * kBlockRows, H.rows()));
  });
}

}  // namespace

void add_basis_product(const Eigen::MatrixX3d& base, const Eigen::MatrixXd& H,
                       const Eigen::MatrixX3d& C, Eigen::MatrixX3d& out) {
  add_product(base, H, C, out, add_rows_double);
}

void add_basis_product(const Eigen::MatrixX3d& base, const Eigen::MatrixXf& H,
                       const Eigen::MatrixX3d& C, Eigen::MatrixX3d& out) {
  add_product(base, H, C, out, add_rows_float);
}

}  // namespace specdeform::detail
