#include "fold_zone.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "linalg/parallel.h"
#include "mesh/vertex_rings.h"
#include "specdeform/operators/cotan_laplacian.h"

namespace specdeform::detail {

namespace {

Eigen::Matrix3d corners_of(const FaceRows& faces, const RowVertices& V, int f) {
  Eigen::Matrix3d corners;
  for (int k = 0; k < 3; ++k) corners.row(k) = V.row(faces(f, k));
  return corners;
}

// The larger singular value of the in-plane map of triangle (rest -> deformed) over the
// smaller; infinite where the deformed triangle is degenerate.
double stretch_ratio(const Eigen::Matrix3d& rest, const Eigen::Matrix3d& deformed) {
  Eigen::Matrix<double, 3, 2> E0, E1;
  E0 << (rest.row(2) - rest.row(0)).transpose(), (rest.row(1) - rest.row(0)).transpose();
  E1 << (deformed.row(2) - deformed.row(0)).transpose(),
      (deformed.row(1) - deformed.row(0)).transpose();
  const Eigen::Matrix2d metric = E0.transpose() * E0;
  if (!(metric.determinant() > 0.0)) return 0.0;  // a degenerate rest triangle: not grown into
  const Eigen::Matrix2d C = metric.inverse() * (E1.transpose() * E1);  // eigenvalues sigma^2
  const double half_trace = 0.5 * C.trace();
  const double root = std::sqrt(std::max(0.0, half_trace * half_trace - C.determinant()));
  const double smaller = half_trace - root;
  return smaller > 0.0 ? std::sqrt((half_trace + root) / smaller)
                       : std::numeric_limits<double>::infinity();
}

// Unit normals (b - a) x (c - a) of the faces [begin, end); zero where degenerate. Positions
// and normals are row-major n x 3 and faces x 3.
__attribute__((target_clones("avx2", "default"))) void unit_normals(const int* faces,
                                                                    const double* positions,
                                                                    int begin, int end,
                                                                    double* normals) {
  for (int f = begin; f < end; ++f) {
    const double* a = positions + 3 * faces[3 * f];
    const double* b = positions + 3 * faces[3 * f + 1];
    const double* c = positions + 3 * faces[3 * f + 2];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                         u[0] * v[1] - u[1] * v[0]};
    const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const double scale = length > 0.0 ? 1.0 / length : 0.0;
    for (int d = 0; d < 3; ++d) normals[3 * f + d] = n[d] * scale;
  }
}

// Appends to `out` the faces of [begin, end) that fold: they agreed with their edge neighbours at
// rest, and their unit normal now points against the sum of the neighbours' (-1: none).
__attribute__((target_clones("avx2", "default"))) void folded_faces(const int* neighbours,
                                                                    const char* agreed,
                                                                    const double* normals,
                                                                    int begin, int end,
                                                                    std::vector<int>& out) {
  for (int f = begin; f < end; ++f) {
    if (!agreed[f]) continue;
    double sum[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < 3; ++k) {
      const int g = neighbours[3 * f + k];
      if (g < 0) continue;
      for (int d = 0; d < 3; ++d) sum[d] += normals[3 * g + d];
    }
    const double* n = normals + 3 * f;
    if (n[0] * sum[0] + n[1] * sum[1] + n[2] * sum[2] < 0.0) out.push_back(f);
  }
}

}  // namespace

Eigen::Matrix3d triangle_frame(const Eigen::Matrix3d& corners) {
  const Eigen::Vector3d a = corners.row(0), b = corners.row(1), c = corners.row(2);
  Eigen::Matrix3d m;
  m.col(0) = c - a;
  m.col(1) = b - a;
  const Eigen::Vector3d n = (b - a).cross(c - a);
  m.col(2) = n.norm() > 0.0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero();
  return m;
}

Eigen::Matrix3d corner_gradients(const Eigen::Matrix3d& corners) {
  const Eigen::Vector3d a = corners.row(0), b = corners.row(1), c = corners.row(2);
  const double area = 0.5 * (b - a).cross(c - a).norm();
  const Eigen::Matrix3d g = hat_gradients(a, b, c);
  return area * g * (g.transpose() * corners);
}

void unit_face_normals(const FaceRows& faces, const RowVertices& V, RowVertices& normals) {
  normals.resize(faces.rows(), 3);
  split_in_two(faces.rows(), [&](Eigen::Index begin, Eigen::Index end) {
    unit_normals(faces.data(), V.data(), static_cast<int>(begin), static_cast<int>(end),
                 normals.data());
  });
}

FoldZone::FoldZone(FaceRows faces, RowVertices base)
    : faces_(std::move(faces)), base_(std::move(base)) {
  const int nf = static_cast<int>(faces_.rows());
  const VertexFaces incident = vertex_faces(faces_, static_cast<int>(base_.rows()));
  neighbours_ = FaceRows::Constant(nf, 3, -1);
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = faces_(f, k), b = faces_(f, (k + 1) % 3);
      for (int e = incident.start[a]; e < incident.start[a + 1] && neighbours_(f, k) < 0; ++e) {
        const int g = incident.face[e];
        if (g != f && (faces_(g, 0) == b || faces_(g, 1) == b || faces_(g, 2) == b))
          neighbours_(f, k) = g;
      }
    }
  }
  RowVertices normals;
  unit_face_normals(faces_, base_, normals);
  agreed_.assign(nf, 0);
  for (int f = 0; f < nf; ++f) {
    const Eigen::RowVector3d sum = neighbour_normals(normals, f);
    agreed_[f] = sum.norm() > 0.0 && normals.row(f).dot(sum) > 0.5 * sum.norm();
  }
}

Eigen::RowVector3d FoldZone::neighbour_normals(const RowVertices& normals, Eigen::Index f) const {
  Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
  for (int k = 0; k < 3; ++k)
    if (neighbours_(f, k) >= 0) sum += normals.row(neighbours_(f, k));
  return sum;
}

std::vector<int> FoldZone::find(const RowVertices& deformed, const RowVertices& normals) const {
  const int nf = static_cast<int>(faces_.rows());
  std::vector<int> folded[2];
  split_in_two(nf, [&](Eigen::Index begin, Eigen::Index end) {
    folded_faces(neighbours_.data(), agreed_.data(), normals.data(), static_cast<int>(begin),
                 static_cast<int>(end), folded[end == nf ? 1 : 0]);  // (half, nf), (0, half)
  });
  std::vector<int> zone = std::move(folded[0]);
  zone.insert(zone.end(), folded[1].begin(), folded[1].end());
  if (zone.empty()) return zone;
  std::vector<char> in_zone(nf, 0);
  for (const int f : zone) in_zone[f] = 1;
  // Grown through the stretched faces, then by the rings.
  for (size_t head = 0; head < zone.size(); ++head) {
    for (int k = 0; k < 3; ++k) {
      const int g = neighbours_(zone[head], k);
      if (g < 0 || in_zone[g]) continue;
      if (stretch_ratio(corners_of(faces_, base_, g), corners_of(faces_, deformed, g)) >
          kStretchRatio) {
        in_zone[g] = 1;
        zone.push_back(g);
      }
    }
  }
  for (int ring = 0; ring < kRings; ++ring) {
    const size_t size = zone.size();
    for (size_t i = 0; i < size; ++i) {
      for (int k = 0; k < 3; ++k) {
        const int g = neighbours_(zone[i], k);
        if (g >= 0 && !in_zone[g]) {
          in_zone[g] = 1;
          zone.push_back(g);
        }
      }
    }
  }
  return zone;
}

}  // namespace specdeform::detail
