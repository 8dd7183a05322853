// Internal: the Galerkin (triple) product P^T A P of a symmetric sparse A (n x n) and a sparse
// P (n x N), the coarse operators of the multilevel eigensolver (spectral/multilevel.cpp).
// Column by column: the sparse vector A P_j (P's column j), then P^T times it, each accumulated
// in a dense array with a list of the entries touched. The columns are split between two
// threads. Work: about nnz(P) (a + c) for a the entries per column of A and c per row of P, and
// O(n + N) memory per thread besides the result; Eigen's general sparse products, which sort and
// prune each intermediate, took about 7 times as long on a 692k-vertex mesh.
#pragma once

#include <Eigen/Sparse>

namespace specdeform::detail {

// N x N, symmetric (made exactly so).
Eigen::SparseMatrix<double> galerkin_product(const Eigen::SparseMatrix<double>& A,
                                             const Eigen::SparseMatrix<double>& P);

}  // namespace specdeform::detail
