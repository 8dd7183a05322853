// The Laplacian of a triangle mesh in one of two discretisations: its stiffness matrix K and its
// mass matrix M, for the manifold harmonics (K h = lambda M h) and the deformation energies.
//
//  - Cotan ("cotan"): linear finite elements on the mesh's own triangles (cotan_laplacian.h,
//    mass_matrix.h). An obtuse triangle gives its opposite edge a negative weight, and slivers
//    (angles near 0 or pi) make the elements a poor approximation of the surface's functions.
//  - IntrinsicDelaunay ("intrinsic-delaunay"): linear finite elements on the intrinsic Delaunay
//    triangulation of the same surface (intrinsic_delaunay.h; Bobenko & Springborn 2007, Fisher
//    et al. 2007): the same vertices and the same piecewise-flat surface, but edges flipped along
//    the surface until every interior edge is Delaunay, so that every interior edge weight is
//    >= 0. Meshes with non-manifold edges or inconsistently oriented neighbours go through Sharp
//    & Crane's tufted cover (2020).
//
// Both keep cotan_laplacian.h's contract: K is n x n, symmetric positive semidefinite, K 1 = 0,
// x^T K x the Dirichlet energy of the piecewise-linear x (the paper's Q is -K), independent of
// scale; M is lumped (diagonal, a third of the areas of the triangles at each vertex) or
// consistent (the finite-element mass), its entries sum to the surface area. Both are built on
// the mesh's mollified edge lengths (mollification.h) wherever a triangle breaks the margin of
// its triangle inequalities (a zero-area face, a zero-length edge, a cap): every triangle then
// has weights and mass, and no vertex has zero mass; on any other mesh the Cotan operators are
// those of the positions (cotan_laplacian.h, mass_matrix.h) bit for bit. Every solver takes its
// operators from here: the repair is made once. On a mesh whose
// triangulation is already Delaunay the two Laplacians are equal to rounding. Where the
// triangulation differs, K connects vertices that share no mesh edge (across a flipped edge).
#pragma once

#include <string_view>

#include <Eigen/Sparse>

#include "specdeform/mesh/triangle_mesh.h"
#include "specdeform/operators/mass_matrix.h"

namespace specdeform {

enum class LaplacianType {
  Cotan,              // the mesh's own triangles (the default)
  IntrinsicDelaunay,  // the intrinsic Delaunay triangulation of the same surface
};

// "cotan" or "intrinsic-delaunay"; laplacian_type_from_name throws InputError for another name.
std::string_view name(LaplacianType type);
LaplacianType laplacian_type_from_name(std::string_view name);

struct LaplacianOperators {
  Eigen::SparseMatrix<double> stiffness;  // K
  Eigen::SparseMatrix<double> mass;       // M
};

// K and M of the same triangulation (the intrinsic one is built once for both). Throws
// SolverError if the edge flips do not terminate (rounding on a pathological mesh).
LaplacianOperators laplacian_operators(const TriangleMesh& mesh, MassType mass, LaplacianType type);

Eigen::SparseMatrix<double> stiffness_matrix(const TriangleMesh& mesh, LaplacianType type);

// What every solver needs of K and M (n x n): finite entries and an area at every vertex (its
// row of M sums to more than 0). Throws InputError "<who>: ..." naming what fails; after
// mollification only a piece of coincident vertices has no area.
void check_operators(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M,
                     std::string_view who);

// The Cotan lumped mass's diagonal (n): each vertex's area, positive wherever mollification
// gives zero-area faces an area (the solvers' area weights; lumped_mass(mesh) of mass_matrix.h is
// the positions' own, 0 for a vertex of zero-area faces alone).
Eigen::VectorXd vertex_areas(const TriangleMesh& mesh);
Eigen::SparseMatrix<double> mass_matrix(const TriangleMesh& mesh, MassType mass,
                                        LaplacianType type);

}  // namespace specdeform
