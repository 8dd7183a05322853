#include "specdeform/mesh/vertex_clusters.h"

#include <algorithm>
#include <limits>
#include <queue>
#include <vector>

namespace specdeform {

VertexClusters vertex_clusters(const TriangleMesh& mesh, int count) {
  const int n = mesh.num_vertices();
  // Edge lists per vertex (compressed rows; an edge listed once per face is harmless).
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

  constexpr double kUnreached = std::numeric_limits<double>::infinity();
  VertexClusters out;
  out.label = Eigen::VectorXi::Constant(n, -1);
  std::vector<double> distance(n, kUnreached);
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  int seed = 0;  // then the farthest vertex from all seeds so far
  while (n > 0) {
    const int cluster = out.count++;
    distance[seed] = 0.0;
    out.label[seed] = cluster;
    queue.emplace(0.0, seed);
    while (!queue.empty()) {  // Dijkstra, only where this seed is nearer than earlier ones
      const auto [d, i] = queue.top();
      queue.pop();
      if (d > distance[i]) continue;
      for (int e = start[i]; e < start[i + 1]; ++e) {
        const int j = neighbour[e];
        const double dj = d + (mesh.V.row(i) - mesh.V.row(j)).norm();
        if (dj < distance[j]) {
          distance[j] = dj;
          out.label[j] = cluster;
          queue.emplace(dj, j);
        }
      }
    }
    seed = static_cast<int>(std::max_element(distance.begin(), distance.end()) - distance.begin());
    const bool unreached = distance[seed] == kUnreached;
    if (out.count >= n || (out.count >= count && !unreached) || distance[seed] == 0.0) break;
  }
  return out;
}

}  // namespace specdeform
