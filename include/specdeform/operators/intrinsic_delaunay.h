// The intrinsic Delaunay triangulation of a triangle mesh and its Laplacian.
//
// Bobenko & Springborn, "A discrete Laplace-Beltrami operator for simplicial surfaces" (2007);
// Fisher, Springborn, Bobenko & Schroeder, "An algorithm for the construction of intrinsic
// Delaunay triangulations with applications to digital geometry processing" (2007); Sharp &
// Crane, "A Laplacian for nonmanifold triangle meshes" (2020) for the tufted cover.
//
// The triangulation is held by its edge lengths alone. It starts as the mesh's triangles with
// their Euclidean edge lengths, and an interior edge is flipped while the two angles opposite to
// it sum to more than pi (cot a + cot b < -1e-10, a margin against flipping back and forth on
// rounding): the edge is replaced by the other diagonal of its two triangles laid out flat, whose
// length follows from the five lengths of that quadrilateral. Such a flip is always possible
// (the quadrilateral is convex) and never changes the surface, only how it is cut into
// triangles; the flips end on the unique intrinsic Delaunay triangulation, on which every
// interior edge's cotangent weight is >= 0. Boundary edges (one triangle) are never flipped, so a
// boundary edge opposite an obtuse angle keeps its negative weight. The vertices stay the mesh's;
// a triangle may use a vertex twice and two triangles may share two edges, which the operators
// below handle as finite elements do (a vertex's basis function is the sum over its corners).
//
// A mesh with an edge of three or more triangles, or with neighbours oriented inconsistently
// (including non-orientable ones), is replaced by its tufted cover: each triangle has two sheets
// (its two sides, oppositely oriented); around every edge the triangles are ordered by angle and
// the two sides facing each other across each wedge between consecutive triangles are glued.
// The cover is edge-manifold and oriented and has the mesh's vertices; on it each triangle is
// present twice, so its operators are halved (`sheet_weight`). Where the mesh is manifold the
// cover is locally two copies of it, and the operators are the same as without the cover. (Sharp
// & Crane also glue the two sheets of a boundary triangle to each other, which lets boundary
// edges flip; we keep boundary edges on either path, so that both give Fisher et al.'s
// triangulation of a manifold mesh with boundary.)
//
// The lengths are mollified first (mollification.h): every triangle then meets its triangle
// inequalities by a margin, so that every angle is defined and no triangle is degenerate. Each
// flip then strictly lowers the Dirichlet energy of the piecewise-linear functions (Bobenko &
// Springborn, section 4), the triangulations of a surface with these vertices are finitely many,
// and the flips end (the test's margin of 1e-10 keeps rounding from flipping an edge back and
// forth; the cap of 100 flips per edge is a guard). Before mollification, zero-area triangles
// (angles of 0 and pi) flipped on and on: over 2e8 flips on a 332k-vertex room scene.
#pragma once

#include <Eigen/Core>
#include <Eigen/Sparse>

#include "specdeform/mesh/triangle_mesh.h"
#include "specdeform/operators/mass_matrix.h"

namespace specdeform {

struct IntrinsicTriangulation {
  int num_vertices = 0;  // the mesh's
  // Triangle t has the vertices F(t, 0..2) of the mesh, counter-clockwise on its sheet; a vertex
  // may repeat. Corner c's edge runs from F(t, c) to F(t, (c + 1) % 3); its length is
  // length(t, c), and twin(t, c) = 3 t' + c' is the same edge in the triangle across it, or -1
  // on the boundary.
  Faces F;
  Eigen::Matrix<double, Eigen::Dynamic, 3> length;
  Eigen::Matrix<int, Eigen::Dynamic, 3> twin;
  double sheet_weight = 1.0;  // 1/2 on the tufted cover (each mesh triangle present twice)
  bool tufted = false;
  long long flips = 0;
};

// Throws SolverError if the flips do not end within 100 flips per edge (rounding on a
// pathological mesh), InputError for a face with a vertex index out of range.
IntrinsicTriangulation intrinsic_delaunay(const TriangleMesh& mesh);

// The mesh's own triangles on their mollified lengths, unflipped and unglued (twin -1): the
// cotan Laplacian of a mesh that needs mollification (laplacian.h).
IntrinsicTriangulation mollified_triangulation(const TriangleMesh& mesh);

// The cotangent weight of the edge of corner c of triangle t: (cot a + cot b) / 2 with a, b the
// angles opposite to it (one on the boundary; a degenerate triangle's counts 0), times
// sheet_weight. K_ij is minus the sum of the weights of the edges between i and j.
double edge_weight(const IntrinsicTriangulation& tri, int t, int c);

// The operators of linear finite elements on the triangulation, under the contract of
// laplacian.h (n x n, the mesh's vertices).
Eigen::SparseMatrix<double> stiffness_matrix(const IntrinsicTriangulation& tri);
Eigen::SparseMatrix<double> mass_matrix(const IntrinsicTriangulation& tri, MassType type);

}  // namespace specdeform
