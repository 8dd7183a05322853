#include "specdeform/deform/influence.h"

#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <vector>

#include "mesh/vertex_rings.h"
#include "specdeform/exceptions.h"

namespace specdeform {

Eigen::VectorXd handle_distances(const TriangleMesh& mesh, const Selection& selection) {
  const int n = mesh.num_vertices();
  const detail::VertexRings rings = detail::vertex_rings(mesh);
  Eigen::VectorXd distance = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  for (const std::vector<int>& group : selection.handles) {
    for (const int v : group) {
      if (v < 0 || v >= n) {
        throw InputError("influence: handle vertex " + std::to_string(v) + " is out of range");
      }
      distance[v] = 0.0;
      queue.emplace(0.0, v);
    }
  }
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > distance[v]) continue;
    for (int e = rings.start[v]; e < rings.start[v + 1]; ++e) {
      const int w = rings.neighbour[e];
      const double through = d + (mesh.V.row(w) - mesh.V.row(v)).norm();
      if (through < distance[w]) {
        distance[w] = through;
        queue.emplace(through, w);
      }
    }
  }
  return distance;
}

Selection limit_influence(const TriangleMesh& mesh, const Selection& selection, double radius) {
  if (!(radius > 0.0) || !std::isfinite(radius)) {
    throw InputError("influence: the radius must be a positive number");
  }
  const Eigen::VectorXd distance = handle_distances(mesh, selection);
  std::vector<char> taken(mesh.num_vertices(), 0);
  for (const std::vector<int>& group : selection.handles)
    for (const int v : group) taken[v] = 1;
  for (const int v : selection.fixed)
    if (v >= 0 && v < mesh.num_vertices()) taken[v] = 1;
  Selection out = selection;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    if (!taken[v] && distance[v] > radius && std::isfinite(distance[v])) out.fixed.push_back(v);
  }
  return out;
}

}  // namespace specdeform
