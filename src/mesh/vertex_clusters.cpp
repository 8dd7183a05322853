#include "specdeform/mesh/vertex_clusters.h"

#include <algorithm>
#include <limits>
#include <queue>
#include <vector>

namespace specdeform {

VertexClusters vertex_clusters(const TriangleMesh& mesh, int count) {
  const int n = mesh.num_vertices();
  // Neighbour lists per vertex (compressed rows, each edge once per end).
  std::vector<int> start(n + 1, 0);
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) start[mesh.F(f, k) + 1] += 2;
  for (int i = 0; i < n; ++i) start[i + 1] += start[i];
  std::vector<int> neighbour(start[n]);
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int i = mesh.F(f, k);
      neighbour[fill[i]++] = mesh.F(f, (k + 1) % 3);
      neighbour[fill[i]++] = mesh.F(f, (k + 2) % 3);
    }
  }
  // Renumbered breadth first (neighbours close in memory: a subdivided mesh numbers them far
  // apart), the lists deduplicated, with their edges' lengths.
  std::vector<int> order, rank(n, -1);
  order.reserve(n);
  for (int root = 0; root < n; ++root) {
    if (rank[root] >= 0) continue;
    rank[root] = static_cast<int>(order.size());
    order.push_back(root);
    for (size_t head = order.size() - 1; head < order.size(); ++head) {
      for (int e = start[order[head]]; e < start[order[head] + 1]; ++e) {
        const int j = neighbour[e];
        if (rank[j] < 0) {
          rank[j] = static_cast<int>(order.size());
          order.push_back(j);
        }
      }
    }
  }
  std::vector<int> first(n + 1, 0), next;
  std::vector<double> length;
  next.reserve(neighbour.size());
  length.reserve(neighbour.size());
  for (int k = 0; k < n; ++k) {
    const int v = order[k];
    const size_t begin = next.size();
    for (int e = start[v]; e < start[v + 1]; ++e) next.push_back(rank[neighbour[e]]);
    std::sort(next.begin() + begin, next.end());
    next.erase(std::unique(next.begin() + begin, next.end()), next.end());
    for (size_t e = begin; e < next.size(); ++e)
      length.push_back((mesh.V.row(v) - mesh.V.row(order[next[e]])).norm());
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
