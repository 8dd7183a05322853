// Mass matrices of linear finite elements on a triangle mesh.
//
// Lumped (the default): diagonal, M_ii = (sum of the areas of the triangles at i) / 3, the
// paper's D (Rong, Cao & Guo 2008, eq. 6). Consistent: M_ii = sum area_t / 6,
// M_ij = (area_t + area_t') / 12 over the triangles t, t' sharing edge ij, the paper's B (eq. 5).
// Both are symmetric positive semidefinite, n x n, in units of area, and their entries sum to
// the surface area. A vertex touched only by degenerate triangles has zero mass.
#pragma once

#include <Eigen/Sparse>

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform {

enum class MassType { Lumped, Consistent };

Eigen::SparseMatrix<double> mass_matrix(const TriangleMesh& mesh, MassType type);

// Diagonal of the lumped mass matrix (n).
Eigen::VectorXd lumped_mass(const TriangleMesh& mesh);

}  // namespace specdeform
