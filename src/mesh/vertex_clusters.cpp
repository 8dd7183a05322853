#include "specdeform/mesh/vertex_clusters.h"

#include <algorithm>
#include <limits>
#include <queue>
#include <vector>

#include "linalg/locality_order.h"
#include "mesh/vertex_rings.h"

namespace specdeform {

VertexClusters vertex_clusters(const TriangleMesh& mesh, int count) {
  const int n = mesh.num_vertices();
  // The edge graph renumbered breadth first (neighbours close in memory: a subdivided mesh
  // numbers them far apart), with its edges' lengths.
  const detail::VertexRings rings = detail::vertex_rings(mesh);
  const detail::Permutation P =
      detail::breadth_first_order(n, rings.start.data(), rings.neighbour.data());
  const int* rank = P.indices().data();
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) order[rank[i]] = i;
  std::vector<int> first(n + 1, 0), next;
  std::vector<double> length;
  next.reserve(rings.neighbour.size());
  length.reserve(rings.neighbour.size());
  for (int k = 0; k < n; ++k) {
    const int v = order[k];
    for (int e = rings.start[v]; e < rings.start[v + 1]; ++e) {
      next.push_back(rank[rings.neighbour[e]]);
      length.push_back((mesh.V.row(v) - mesh.V.row(rings.neighbour[e])).norm());
    }
    first[k + 1] = static_cast<int>(next.size());
  }

  constexpr double kUnreached = std::numeric_limits<double>::infinity();
  VertexClusters out;
  Eigen::VectorXi label = Eigen::VectorXi::Constant(n, -1);  // in the new numbering
  std::vector<double> distance(n, kUnreached);
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  int seed = 0;  // then the farthest vertex from all seeds so far
  while (n > 0) {
    const int cluster = out.count++;
    distance[seed] = 0.0;
    label[seed] = cluster;
    queue.emplace(0.0, seed);
    while (!queue.empty()) {  // Dijkstra, only where this seed is nearer than earlier ones
      const auto [d, i] = queue.top();
      queue.pop();
      if (d > distance[i]) continue;
      for (int e = first[i]; e < first[i + 1]; ++e) {
        const int j = next[e];
        const double dj = d + length[e];
        if (dj < distance[j]) {
          distance[j] = dj;
          label[j] = cluster;
          queue.emplace(dj, j);
        }
      }
    }
    seed = static_cast<int>(std::max_element(distance.begin(), distance.end()) - distance.begin());
    const bool unreached = distance[seed] == kUnreached;
    if (out.count >= n || (out.count >= count && !unreached) || distance[seed] == 0.0) break;
  }
  out.label.resize(n);
  for (int k = 0; k < n; ++k) out.label[order[k]] = label[k];
  return out;
}

}  // namespace specdeform
