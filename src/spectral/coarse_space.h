// Internal: the coarse space of the multilevel eigensolver (Nasikun, Brandt & Hildebrandt, "Fast
// approximation of Laplace-Beltrami eigenproblems", SGP 2018): N seeds spread by farthest-point
// sampling in the graph distance d along the mesh's edges, and one locally supported function
// per seed, a truncated Gaussian psi(t) = exp(-4 t^2) - exp(-4) (t < 1) of the distance to the
// seed over the support radius rho = support * r (r the sampling's covering radius: every vertex
// lies within r of a seed), normalised to a partition of unity:
//     P_ij = psi(d_j(i) / rho) / sum_k psi(d_k(i) / rho)      (n x N, every row sums to 1).
// Farthest-point sampling (mesh/graph_distance.h) seeds every connected component, so P 1 = 1:
// the constants of each component are in the span exactly. Cost: one pruned Dijkstra per seed,
// O(n log n) in all for the sampling and O(n c log n) for the functions, c the vertices' average
// number of covering functions (about 2 support^2); the functions are built on two threads.
#pragma once

#include <Eigen/Core>
#include <Eigen/Sparse>

#include "mesh/graph_distance.h"

namespace specdeform::detail {

struct CoarseSpace {
  Eigen::SparseMatrix<double> prolongation;  // P, n x N, rows sum to 1, columns in the order
                                             // of their seeds' vertices
  Eigen::SparseMatrix<double, Eigen::RowMajor> rows;  // P again, row-major
  double radius = 0.0;                                // r, in the units of the edge lengths
};

// lengths: n x n, symmetric, the length of edge ij at (i, j) (K's pattern; the diagonal is
// ignored). samples: N, at least 1 (fewer if n is smaller, more if there are more connected
// components). support: rho / r, > 1.
CoarseSpace partition_of_unity(const Eigen::SparseMatrix<double>& lengths, int samples,
                               double support);
// The same in its two steps: the functions of `farthest`'s seeds (farthest_points on `graph`,
// the edge graph of the lengths).
CoarseSpace partition_of_unity(const EdgeGraph& graph, const Sampling& farthest, double support);

// The edges of K (its off-diagonal pattern) with the Euclidean lengths of the positions V (n x 3).
Eigen::SparseMatrix<double> edge_lengths(const Eigen::SparseMatrix<double>& K,
                                         const Eigen::MatrixX3d& V);

// Without positions: the length of edge ij estimated from the vertices' areas (M's row sums) as
// sqrt((a_i + a_j) / 2) (a regular triangulation's edge is about 1.6 times that: the scale does
// not matter, only the ratios).
Eigen::SparseMatrix<double> estimated_edge_lengths(const Eigen::SparseMatrix<double>& K,
                                                   const Eigen::SparseMatrix<double>& M);

}  // namespace specdeform::detail
