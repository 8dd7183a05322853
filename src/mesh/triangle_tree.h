// Internal: CGAL's AABB tree over a mesh's triangles, for closest-point and distance queries
// (mesh/surface_distance.cpp, deform/free_pieces.cpp).
#pragma once

#include <vector>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform::detail {

using TreeKernel = CGAL::Simple_cartesian<double>;
using TreePoint = TreeKernel::Point_3;
using TreeTriangle = TreeKernel::Triangle_3;
using TriangleTree = CGAL::AABB_tree<CGAL::AABB_traits<
    TreeKernel,
    CGAL::AABB_triangle_primitive<TreeKernel, std::vector<TreeTriangle>::const_iterator>>>;

inline TreePoint tree_point(const Vertices& V, Eigen::Index i) {
  return {V(i, 0), V(i, 1), V(i, 2)};
}

}  // namespace specdeform::detail
