#include "specdeform/deform/influence.h"

#include <cmath>
#include <string>
#include <vector>

#include "mesh/graph_distance.h"
#include "specdeform/exceptions.h"

namespace specdeform {

Eigen::VectorXd handle_distances(const TriangleMesh& mesh, const Selection& selection) {
  const int n = mesh.num_vertices();
  std::vector<int> sources;
  for (const std::vector<int>& group : selection.handles) {
    for (const int v : group) {
      if (v < 0 || v >= n) {
        throw InputError("influence: handle vertex " + std::to_string(v) + " is out of range");
      }
      sources.push_back(v);
    }
  }
  std::vector<float> distance(n, detail::kFar);
  detail::DistanceHeap heap;
  detail::pruned_dijkstra(detail::edge_graph(mesh), sources, detail::kFar, distance, heap,
                          [](int, float) {});
  return Eigen::Map<const Eigen::VectorXf>(distance.data(), n).cast<double>();
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
