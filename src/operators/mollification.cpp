#include "specdeform/operators/mollification.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "specdeform/exceptions.h"

namespace specdeform {

void MollificationPolicy::validate() const {
  if (!(margin > 0.0) || !std::isfinite(margin)) {
    throw InputError("mollification: the margin must be finite and > 0");
  }
}

Eigen::Matrix<double, Eigen::Dynamic, 3> mollified_lengths(const TriangleMesh& mesh, double eps) {
  const int n = mesh.num_vertices();
  if (mesh.num_faces() > 0 && (mesh.F.minCoeff() < 0 || mesh.F.maxCoeff() >= n)) {
    throw InputError("mollification: a face refers to a vertex outside 0.." +
                     std::to_string(n - 1));
  }
  Eigen::Matrix<double, Eigen::Dynamic, 3> length(mesh.num_faces(), 3);
  for (int t = 0; t < mesh.num_faces(); ++t)
    for (int c = 0; c < 3; ++c)
      length(t, c) = (mesh.V.row(mesh.F(t, (c + 1) % 3)) - mesh.V.row(mesh.F(t, c))).norm() + eps;
  return length;
}

double mollification(const TriangleMesh& mesh, const MollificationPolicy& policy) {
  policy.validate();
  if (mesh.num_faces() == 0) return 0.0;
  const Eigen::Matrix<double, Eigen::Dynamic, 3> length = mollified_lengths(mesh, 0.0);
  const double delta = policy.margin * length.mean();
  double eps = 0.0;
  for (int t = 0; t < length.rows(); ++t)
    for (int c = 0; c < 3; ++c)
      eps = std::max(eps, delta - (length(t, c) + length(t, (c + 1) % 3) - length(t, (c + 2) % 3)));
  return eps;
}

double double_area_from_lengths(double a, double b, double c) {
  if (a < b) std::swap(a, b);
  if (a < c) std::swap(a, c);
  if (b < c) std::swap(b, c);
  const double p = (a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c));
  return p > 0.0 ? 0.5 * std::sqrt(p) : 0.0;
}

}  // namespace specdeform
