#include "specdeform/mesh/surface_distance.h"

#include <cmath>
#include <vector>

#include "mesh/triangle_tree.h"
#include "specdeform/exceptions.h"

namespace specdeform {

namespace {

using Triangle = detail::TreeTriangle;
using Tree = detail::TriangleTree;
using detail::tree_point;

}  // namespace

Eigen::VectorXd distances_to_surface(const Vertices& points, const TriangleMesh& surface) {
  std::vector<Triangle> triangles;
  triangles.reserve(surface.num_faces());
  for (int f = 0; f < surface.num_faces(); ++f) {
    const Triangle t(tree_point(surface.V, surface.F(f, 0)), tree_point(surface.V, surface.F(f, 1)),
                     tree_point(surface.V, surface.F(f, 2)));
    if (!t.is_degenerate()) triangles.push_back(t);
  }
  if (triangles.empty()) throw InputError("surface distance: the surface has no triangle");
  Tree tree(triangles.begin(), triangles.end());
  tree.accelerate_distance_queries();
  Eigen::VectorXd d(points.rows());
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    d[i] = std::sqrt(tree.squared_distance(tree_point(points, i)));
  }
  return d;
}

double hausdorff_distance(const TriangleMesh& a, const TriangleMesh& b) {
  return std::max(distances_to_surface(a.V, b).maxCoeff(), distances_to_surface(b.V, a).maxCoeff());
}

}  // namespace specdeform
