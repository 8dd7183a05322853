#include "specdeform/operators/mass_matrix.h"

#include <vector>

#include <Eigen/Geometry>

namespace specdeform {

namespace {

// Area of triangle f, or 0 if it is degenerate.
double triangle_area(const TriangleMesh& mesh, int f) {
  const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0));
  const Eigen::Vector3d b = mesh.V.row(mesh.F(f, 1));
  const Eigen::Vector3d c = mesh.V.row(mesh.F(f, 2));
  return is_degenerate_triangle(a, b, c) ? 0.0 : 0.5 * (b - a).cross(c - a).norm();
}

}  // namespace

Eigen::VectorXd lumped_mass(const TriangleMesh& mesh) {
  Eigen::VectorXd m = Eigen::VectorXd::Zero(mesh.num_vertices());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const double third = triangle_area(mesh, f) / 3.0;
    for (int k = 0; k < 3; ++k) m[mesh.F(f, k)] += third;
  }
  return m;
}

Eigen::SparseMatrix<double> mass_matrix(const TriangleMesh& mesh, MassType type) {
  const int n = mesh.num_vertices();
  Eigen::SparseMatrix<double> M(n, n);
  if (type == MassType::Lumped) {
    const Eigen::VectorXd m = lumped_mass(mesh);
    M = Eigen::SparseMatrix<double>(m.asDiagonal());
  } else {
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(9 * size_t(mesh.num_faces()));
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const double area = triangle_area(mesh, f);
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          triplets.emplace_back(mesh.F(f, a), mesh.F(f, b), area / (a == b ? 6.0 : 12.0));
    }
    M.setFromTriplets(triplets.begin(), triplets.end());
  }
  M.makeCompressed();
  return M;
}

}  // namespace specdeform
