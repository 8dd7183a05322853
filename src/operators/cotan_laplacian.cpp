#include "specdeform/operators/cotan_laplacian.h"

#include <vector>

#include <Eigen/Geometry>

namespace specdeform {

Eigen::SparseMatrix<double> cotan_stiffness(const TriangleMesh& mesh) {
  const int n = mesh.num_vertices();
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(12 * size_t(mesh.num_faces()));
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d p[3] = {mesh.V.row(mesh.F(f, 0)), mesh.V.row(mesh.F(f, 1)),
                                  mesh.V.row(mesh.F(f, 2))};
    if (is_degenerate_triangle(p[0], p[1], p[2])) continue;
    const double double_area = (p[1] - p[0]).cross(p[2] - p[0]).norm();
    for (int k = 0; k < 3; ++k) {
      // The angle at corner k is opposite to the edge (k+1, k+2).
      const int i = mesh.F(f, (k + 1) % 3), j = mesh.F(f, (k + 2) % 3);
      const Eigen::Vector3d u = p[(k + 1) % 3] - p[k], v = p[(k + 2) % 3] - p[k];
      const double half_cot = 0.5 * u.dot(v) / double_area;
      triplets.emplace_back(i, j, -half_cot);
      triplets.emplace_back(j, i, -half_cot);
      triplets.emplace_back(i, i, half_cot);
      triplets.emplace_back(j, j, half_cot);
    }
  }
  Eigen::SparseMatrix<double> K(n, n);
  K.setFromTriplets(triplets.begin(), triplets.end());
  K.makeCompressed();
  return K;
}

Eigen::SparseMatrix<double> gradient_operator(const TriangleMesh& mesh) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(9 * size_t(mesh.num_faces()));
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d p[3] = {mesh.V.row(mesh.F(f, 0)), mesh.V.row(mesh.F(f, 1)),
                                  mesh.V.row(mesh.F(f, 2))};
    if (is_degenerate_triangle(p[0], p[1], p[2])) continue;
    const Eigen::Vector3d normal = (p[1] - p[0]).cross(p[2] - p[0]);
    const double double_area_sq = normal.squaredNorm();
    for (int k = 0; k < 3; ++k) {
      // grad phi_k = (n x e_k) / (2 A), e_k the edge opposite to corner k, counter-clockwise.
      const Eigen::Vector3d e = p[(k + 2) % 3] - p[(k + 1) % 3];
      const Eigen::Vector3d g = normal.cross(e) / double_area_sq;
      for (int d = 0; d < 3; ++d) triplets.emplace_back(3 * f + d, mesh.F(f, k), g[d]);
    }
  }
  Eigen::SparseMatrix<double> G(3 * mesh.num_faces(), mesh.num_vertices());
  G.setFromTriplets(triplets.begin(), triplets.end());
  G.makeCompressed();
  return G;
}

}  // namespace specdeform
