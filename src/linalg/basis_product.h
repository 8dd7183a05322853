// Internal: out = base + H C for a tall basis H (n x m, column-major, double or float) and C (m x
// 3), the inverse manifold-harmonics transform of one deformation frame. Memory-bound (H is read
// once): rows are processed in blocks whose three accumulators stay in the L1 cache, and the
// blocks are split between two threads. Plain loops rather than a BLAS call, which would pack
// (copy) all of H first. The result into column-major doubles, or into rows of three floats
// (the layout of a front end's vertex buffer, written in place).
// A factored basis H = P Z (spectral/manifold_harmonics.h): base + P (Z C), Z C first (N x 3),
// then each row of P gathers its dozen rows of it, on two threads.
#pragma once

#include <Eigen/Core>

#include "specdeform/mesh/triangle_mesh.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform::detail {

// `out` is resized to n x 3.
void add_basis_product(const Eigen::MatrixX3d& base, const Eigen::MatrixXd& H,
                       const Eigen::MatrixX3d& C, Eigen::MatrixX3d& out);
void add_basis_product(const Eigen::MatrixX3d& base, const Eigen::MatrixXf& H,
                       const Eigen::MatrixX3d& C, Eigen::MatrixX3d& out);
// `out` has n rows (InputError otherwise).
void add_basis_product(const Eigen::MatrixX3d& base, const Eigen::MatrixXd& H,
                       const Eigen::MatrixX3d& C, Eigen::Ref<FloatVertices> out);
void add_basis_product(const Eigen::MatrixX3d& base, const Eigen::MatrixXf& H,
                       const Eigen::MatrixX3d& C, Eigen::Ref<FloatVertices> out);

void add_basis_product(const Eigen::MatrixX3d& base, const FactoredBasis& H,
                       const Eigen::MatrixX3d& C, Eigen::MatrixX3d& out);
void add_basis_product(const Eigen::MatrixX3d& base, const FactoredBasis& H,
                       const Eigen::MatrixX3d& C, Eigen::Ref<FloatVertices> out);

// Row i of P Z over W columns of Z: sum[q] = sum_e P_ie Z(column_e, q), Z row-major with
// `stride` entries a row (from the first column wanted), P's entries in their order (as a plain
// sum takes them). The kernel of the product below and of the basis's residual check, inlined
// into each (and vectorised there: the sums stay in registers).
template <int W>
inline void sparse_row_product(const int* start, const int* column, const double* value,
                               const double* Z, Eigen::Index stride, Eigen::Index i, double* sum) {
  for (int q = 0; q < W; ++q) sum[q] = 0.0;
  for (int e = start[i]; e < start[i + 1]; ++e) {
    const double v = value[e];
    const double* z = Z + stride * Eigen::Index{column[e]};
    for (int q = 0; q < W; ++q) sum[q] += v * z[q];
  }
}

// H = P Z itself (n x m, column-major, on huge pages: linalg/huge_pages.h): per tile of 64 rows
// and 16 columns each row's sums in registers, stored into H's columns a tile at a time, on two
// threads. Into `storage`'s memory where it is n x m (pages touched beforehand: touched_matrix),
// else into a new matrix.
Eigen::MatrixXd factored_product(const FactoredBasis& H, Eigen::MatrixXd storage = {});

}  // namespace specdeform::detail
