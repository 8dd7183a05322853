#include "specdeform/mesh/surface_distance.h"

#include <cmath>
#include <vector>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include "specdeform/exceptions.h"

namespace specdeform {

namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Triangle = Kernel::Triangle_3;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, std::vector<Triangle>::const_iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

Point point(const Vertices& V, Eigen::Index i) {
  return {V(i, 0), V(i, 1), V(i, 2)};
}

}  // namespace

Eigen::VectorXd distances_to_surface(const Vertices& points, const TriangleMesh& surface) {
  std::vector<Triangle> triangles;
  triangles.reserve(surface.num_faces());
  for (int f = 0; f < surface.num_faces(); ++f) {
    const Triangle t(point(surface.V, surface.F(f, 0)), point(surface.V, surface.F(f, 1)),
                     point(surface.V, surface.F(f, 2)));
    if (!t.is_degenerate()) triangles.push_back(t);
  }
  if (triangles.empty()) throw InputError("surface distance: the surface has no triangle");
  Tree tree(triangles.begin(), triangles.end());
  tree.accelerate_distance_queries();
  Eigen::VectorXd d(points.rows());
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    d[i] = std::sqrt(tree.squared_distance(point(points, i)));
  }
  return d;
}

double hausdorff_distance(const TriangleMesh& a, const TriangleMesh& b) {
  return std::max(distances_to_surface(a.V, b).maxCoeff(), distances_to_surface(b.V, a).maxCoeff());
}

}  // namespace specdeform
