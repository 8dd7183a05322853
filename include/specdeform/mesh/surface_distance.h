// Distances between triangle surfaces, for comparing deformation results (the paper's Fig. 6).
//
// distances_to_surface() gives, for each point, the Euclidean distance to the nearest point of a
// triangle surface (any point of any triangle, not only its vertices), found with CGAL's AABB
// tree. hausdorff_distance() is the symmetric Hausdorff distance sampled at the vertices:
//     max( max_{a in vertices(A)} d(a, B), max_{b in vertices(B)} d(b, A) ),
// which is exact up to how well the vertices sample the surfaces (the Metro tool's measure,
// with the vertices as samples). Units: those of the meshes.
#pragma once

#include <Eigen/Core>

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform {

// One distance per row of `points` (k x 3). Throws InputError if the surface has no triangle.
Eigen::VectorXd distances_to_surface(const Vertices& points, const TriangleMesh& surface);

double hausdorff_distance(const TriangleMesh& a, const TriangleMesh& b);

}  // namespace specdeform
