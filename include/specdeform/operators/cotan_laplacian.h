// Cotangent stiffness matrix and the per-face gradient operator of piecewise-linear functions.
//
// Convention (stated once, tested in tests/operators/cotan_laplacian_test.cpp): K is the
// positive semidefinite stiffness matrix of linear finite elements,
//     K_ij = -(cot a_ij + cot b_ij) / 2   for an edge ij with opposite angles a_ij, b_ij,
//     K_ii = -sum_{j != i} K_ij,
// so K 1 = 0 and x^T K x = sum_f area_f |grad x|_f^2 (the Dirichlet energy). The paper's Q (Rong,
// Cao & Guo 2008, eq. 5) is -K; libigl's and pmp's cotmatrix is -K as well. K is independent of
// scale. Degenerate triangles (is_degenerate_triangle) contribute nothing.
#pragma once

#include <Eigen/Core>
#include <Eigen/Sparse>

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform {

// n x n, symmetric positive semidefinite, compressed.
Eigen::SparseMatrix<double> cotan_stiffness(const TriangleMesh& mesh);

// 3 x 3: row k the (constant) gradient on triangle f of the hat function of its corner k
// (zero for a degenerate triangle); the same for the triangle (a, b, c).
Eigen::Matrix3d hat_gradients(const TriangleMesh& mesh, int f);
Eigen::Matrix3d hat_gradients(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                              const Eigen::Vector3d& c);

// 3f x n: rows 3t, 3t+1, 3t+2 hold the x, y, z components of the (constant) gradient of a
// piecewise-linear function on triangle t. With D = diag(area_t repeated three times),
// G^T D G = K. Degenerate triangles have zero rows.
Eigen::SparseMatrix<double> gradient_operator(const TriangleMesh& mesh);

}  // namespace specdeform
