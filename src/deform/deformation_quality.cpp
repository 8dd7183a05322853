#include "specdeform/deform/deformation_quality.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "specdeform/exceptions.h"

namespace specdeform {

namespace {

void check_sizes(const Vertices& a, const Vertices& b) {
  if (a.rows() != b.rows()) {
    throw InputError("deformation measures: " + std::to_string(a.rows()) + " and " +
                     std::to_string(b.rows()) + " vertices");
  }
}

// Per face, the cosine between its normal and the area-weighted mean normal of its edge
// neighbours (0 where either is undefined).
std::vector<double> neighbour_agreement(const Vertices& V, const Faces& F,
                                        const std::vector<std::vector<int>>& neighbours) {
  const TriangleMesh mesh{V, F};
  const Eigen::MatrixX3d normals = face_normals(mesh);
  const Eigen::VectorXd areas = face_areas(mesh);
  std::vector<double> out(F.rows(), 0.0);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    Eigen::RowVector3d mean = Eigen::RowVector3d::Zero();
    for (const int g : neighbours[f]) mean += areas[g] * normals.row(g);
    const double length = mean.norm();
    if (length > 0.0) out[f] = normals.row(f).dot(mean) / length;
  }
  return out;
}

}  // namespace

std::vector<double> cross_section_ratios(const Vertices& rest, const Vertices& deformed, int axis) {
  check_sizes(rest, deformed);
  if (axis < 0 || axis > 2) throw InputError("cross sections: the axis is 0, 1 or 2");
  const double resolution = 1e-9 * bounding_box_diagonal(rest);
  std::vector<int> order(rest.rows());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return rest(a, axis) < rest(b, axis); });
  const auto radius = [](const Vertices& V, const std::vector<int>& ring) {
    Eigen::RowVector3d centroid = Eigen::RowVector3d::Zero();
    for (const int v : ring) centroid += V.row(v);
    centroid /= static_cast<double>(ring.size());
    double sum = 0.0;
    for (const int v : ring) sum += (V.row(v) - centroid).norm();
    return sum / static_cast<double>(ring.size());
  };
  std::vector<double> ratios;
  for (size_t begin = 0; begin < order.size();) {
    size_t end = begin + 1;
    while (end < order.size() && rest(order[end], axis) - rest(order[begin], axis) <= resolution) {
      ++end;
    }
    const std::vector<int> ring(order.begin() + begin, order.begin() + end);
    const double before = radius(rest, ring);
    if (ring.size() >= 8 && before > 0.0) ratios.push_back(radius(deformed, ring) / before);
    begin = end;
  }
  return ratios;
}

int inverted_faces(const TriangleMesh& rest, const Vertices& deformed) {
  check_sizes(rest.V, deformed);
  // Edge neighbours of each face, through a map of sorted edges.
  std::map<std::pair<int, int>, std::vector<int>> edge_faces;
  for (int f = 0; f < rest.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = rest.F(f, k), b = rest.F(f, (k + 1) % 3);
      edge_faces[{std::min(a, b), std::max(a, b)}].push_back(f);
    }
  }
  std::vector<std::vector<int>> neighbours(rest.num_faces());
  for (const auto& [edge, faces] : edge_faces)
    for (const int f : faces)
      for (const int g : faces)
        if (f != g) neighbours[f].push_back(g);
  const std::vector<double> before = neighbour_agreement(rest.V, rest.F, neighbours);
  const std::vector<double> after = neighbour_agreement(deformed, rest.F, neighbours);
  int count = 0;
  for (int f = 0; f < rest.num_faces(); ++f) count += before[f] > 0.5 && after[f] < 0.0;
  return count;
}

PointDistances point_distances(const Vertices& a, const Vertices& b) {
  check_sizes(a, b);
  const Eigen::VectorXd d = (a - b).rowwise().norm();
  if (d.size() == 0) return {};
  return {std::sqrt(d.squaredNorm() / static_cast<double>(d.size())), d.maxCoeff()};
}

}  // namespace specdeform
