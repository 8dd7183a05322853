#include "specdeform/mesh/triangle_mesh.h"

#include <algorithm>
#include <cstdio>
#include <string>

#include <Eigen/Geometry>

#include "specdeform/exceptions.h"

namespace specdeform {

bool is_degenerate_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c) {
  const double longest =
      std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  return (b - a).cross(c - a).norm() <= kDegenerateTolerance * longest;
}

void check_coordinate_range(const Eigen::Ref<const Eigen::MatrixXd>& V, std::string_view name) {
  if (V.size() == 0) return;
  const auto number = [](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return std::string(text);
  };
  const double largest = V.cwiseAbs().maxCoeff();
  if (largest > kLargestCoordinate) {
    throw InputError(std::string(name) + ": coordinates reach " + number(largest) +
                     ", beyond the range computed in (extents of 1e-100 to 1e100): rescale the "
                     "mesh");
  }
  const double extent = (V.colwise().maxCoeff() - V.colwise().minCoeff()).maxCoeff();
  if (extent > 0 && extent < kSmallestExtent) {
    throw InputError(std::string(name) + ": the mesh spans only " + number(extent) +
                     ", below the range computed in (extents of 1e-100 to 1e100): rescale the "
                     "mesh");
  }
}

double bounding_box_diagonal(const Vertices& V) {
  if (V.rows() == 0) return 0.0;
  return (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
}

Eigen::VectorXd face_areas(const TriangleMesh& mesh) {
  Eigen::VectorXd areas(mesh.num_faces());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0));
    const Eigen::Vector3d b = mesh.V.row(mesh.F(f, 1));
    const Eigen::Vector3d c = mesh.V.row(mesh.F(f, 2));
    areas[f] = 0.5 * (b - a).cross(c - a).norm();
  }
  return areas;
}

double surface_area(const TriangleMesh& mesh) {
  return face_areas(mesh).sum();
}

Eigen::Matrix<double, Eigen::Dynamic, 3> face_normals(const TriangleMesh& mesh) {
  Eigen::Matrix<double, Eigen::Dynamic, 3> N(mesh.num_faces(), 3);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0));
    const Eigen::Vector3d b = mesh.V.row(mesh.F(f, 1));
    const Eigen::Vector3d c = mesh.V.row(mesh.F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double len = n.norm();
    N.row(f) = len > 0.0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
  }
  return N;
}

Eigen::Matrix<double, Eigen::Dynamic, 3> vertex_normals(const TriangleMesh& mesh) {
  Eigen::Matrix<double, Eigen::Dynamic, 3> N = Eigen::MatrixX3d::Zero(mesh.num_vertices(), 3);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0));
    const Eigen::Vector3d b = mesh.V.row(mesh.F(f, 1));
    const Eigen::Vector3d c = mesh.V.row(mesh.F(f, 2));
    const Eigen::RowVector3d n = (b - a).cross(c - a).transpose();  // length = 2 * area
    for (int k = 0; k < 3; ++k) N.row(mesh.F(f, k)) += n;
  }
  for (int i = 0; i < N.rows(); ++i) {
    const double len = N.row(i).norm();
    if (len > 0.0) N.row(i) /= len;
  }
  return N;
}

}  // namespace specdeform
