// Internal: the products A_j H of a few wide sparse matrices A_j (k_j x n, column-major, k_j
// much smaller than n) and a tall basis H (n x m, column-major): ARAP's reduced operators, whose
// rows are its rotation clusters' (deform/arap_solver.cpp). One pass over H: its rows are
// copied in blocks to a small row-major buffer, so that each entry A_j(i, r) adds one contiguous
// row of H to row i of the result; the blocks are split between two threads, each with its own
// accumulators, summed at the end. Eigen's sparse-times-dense product reads all of A once per
// column of H instead (100 passes over A for m = 100), and H by strided rows.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Sparse>

namespace specdeform::detail {

// One k_j x m result per A_j; throws InputError where A_j.cols() != H.rows().
std::vector<Eigen::MatrixXd> sparse_basis_products(
    const std::vector<const Eigen::SparseMatrix<double>*>& A, const Eigen::MatrixXd& H);

}  // namespace specdeform::detail
