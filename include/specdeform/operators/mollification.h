// Intrinsic mollification of a triangle mesh's edge lengths (Sharp & Crane, "A Laplacian for
// nonmanifold triangle meshes", SGP 2020, section 4.5), the one repair every operator builds on.
//
// One length eps >= 0 is added to every edge, the smallest that makes each triangle meet its
// triangle inequalities by a margin delta = policy.margin x the mean edge length:
//     (l_ij + eps) + (l_jk + eps) - (l_ki + eps) >= delta   for every triangle and corner.
// The positions are not touched. Built on these lengths (laplacian.h), a zero-area triangle, a
// zero-length edge, a needle or a cap has a small positive area and finite cotangent weights: the
// operators stay finite and positive semidefinite, and a vertex that only such triangles touch
// has a positive mass and moves with the surface around it (its stiff edges tie it there). On a
// mesh whose every triangle already meets the margin (a clean mesh), eps = 0 and the
// operators are those of its positions, bit for bit. Units: the mesh's lengths.
#pragma once

#include <Eigen/Core>

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform {

struct MollificationPolicy {
  double margin = 1e-5;  // delta over the mean edge length (robust-laplacian's default; at 1e-6
                         // the eigensolver stalled at residuals of 2e-8 on scans with T-junctions)

  // Throws InputError for a margin that is not finite and positive.
  void validate() const;
};

// eps for `mesh` (0 for a mesh without faces). InputError for a face out of range.
double mollification(const TriangleMesh& mesh, const MollificationPolicy& policy = {});

// f x 3: length(t, c) of the edge from corner c to corner c + 1 of triangle t, plus eps.
Eigen::Matrix<double, Eigen::Dynamic, 3> mollified_lengths(const TriangleMesh& mesh, double eps);

// Twice the area of the triangle with sides a, b, c (Kahan's formula, accurate for slivers); 0
// where rounding breaks the triangle inequality.
double double_area_from_lengths(double a, double b, double c);

}  // namespace specdeform
