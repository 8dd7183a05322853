// Internal: the Galerkin (triple) products P^T K P and P^T M P of two symmetric sparse matrices
// (n x n) and a sparse P (n x N), the coarse operators of the multilevel eigensolver
// (spectral/multilevel.cpp). Column by column: the sparse vectors K P_j and M P_j (P's column
// j), then the rows c <= j of P^T times both in one walk over P's rows (the upper triangle:
// the rest by symmetry), each accumulated in a dense array with a list of the entries touched.
// The columns are split between two threads. Work: about nnz(P) (a + c) for a the entries per
// column of K and M and c per row of P, and O(n + N) memory per thread besides the results;
// Eigen's general sparse products, which sort and prune each intermediate, took about 7 times
// as long on a 692k-vertex mesh.
#pragma once

#include <array>

#include <Eigen/Sparse>

namespace specdeform::detail {

// Both N x N, exactly symmetric. P_rows: P itself, row-major (each row's columns ascending).
std::array<Eigen::SparseMatrix<double>, 2> galerkin_products(
    const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M,
    const Eigen::SparseMatrix<double>& P,
    const Eigen::SparseMatrix<double, Eigen::RowMajor>& P_rows);

}  // namespace specdeform::detail
