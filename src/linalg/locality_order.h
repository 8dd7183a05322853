// Internal: a breadth-first ordering of a sparse symmetric matrix's graph (Cuthill & McKee's,
// without their degree sort), to renumber a large mesh's vertices before work that walks its
// edges or multiplies by its matrices: neighbours end up close in memory, where a subdivided
// or concatenated mesh numbers them far apart (the armadillo subdivided twice, 692k vertices:
// its multilevel basis 7.8 s in the file's numbering, 6.4 s in this one).
#pragma once

#include <Eigen/Sparse>

namespace specdeform::detail {

using Permutation = Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int>;

// The permutation P (P.indices()[i]: the new number of vertex i) visiting A's graph breadth
// first, each connected component in turn from its lowest-numbered vertex; A is n x n with a
// symmetric pattern.
Permutation breadth_first_order(const Eigen::SparseMatrix<double>& A);
// The same for a graph given as compressed rows: vertex i's neighbours are
// neighbour[start[i] .. start[i + 1]), i < n.
Permutation breadth_first_order(int n, const int* start, const int* neighbour);

// P A P^T: entry (i, j) of A at (P[i], P[j]), compressed, each column's rows sorted (Eigen's
// own permuted product took ten times as long: 0.3 s for a 692k-vertex Laplacian).
Eigen::SparseMatrix<double> renumbered(const Eigen::SparseMatrix<double>& A, const Permutation& P);

// X.row(i) = X.row(P.indices()[i]) for every i, column by column with one column of scratch
// per thread (P.transpose() * X would need a second n x m matrix); two threads. A sparse X is
// rebuilt row by row.
void permute_rows_back(const Permutation& P, Eigen::MatrixXd& X);
void permute_rows_back(const Permutation& P, Eigen::SparseMatrix<double, Eigen::RowMajor>& X);

}  // namespace specdeform::detail
