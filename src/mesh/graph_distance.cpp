#include "mesh/graph_distance.h"

#include <algorithm>
#include <numeric>

namespace specdeform::detail {

EdgeGraph edge_graph(const Eigen::SparseMatrix<double>& lengths) {
  EdgeGraph g;
  g.start.resize(lengths.outerSize() + 1);
  g.arcs.reserve(lengths.nonZeros());
  for (int i = 0; i < lengths.outerSize(); ++i) {
    g.start[i] = static_cast<int>(g.arcs.size());
    for (Eigen::SparseMatrix<double>::InnerIterator it(lengths, i); it; ++it)
      if (it.index() != i) g.arcs.push_back({it.index(), static_cast<float>(it.value())});
  }
  g.start.back() = static_cast<int>(g.arcs.size());
  return g;
}

EdgeGraph edge_graph(const TriangleMesh& mesh) {
  std::vector<int> same(mesh.num_vertices());
  std::iota(same.begin(), same.end(), 0);
  return edge_graph(vertex_rings(mesh), mesh.V, same);
}

EdgeGraph edge_graph(const VertexRings& rings, const Vertices& V, std::span<const int> new_number) {
  const int n = static_cast<int>(V.rows());
  std::vector<int> old_number(n);
  for (int i = 0; i < n; ++i) old_number[new_number[i]] = i;
  EdgeGraph g;
  g.start.resize(n + 1);
  g.arcs.reserve(rings.neighbour.size());
  for (int k = 0; k < n; ++k) {
    const int i = old_number[k];
    g.start[k] = static_cast<int>(g.arcs.size());
    for (int e = rings.start[i]; e < rings.start[i + 1]; ++e) {
      const int j = rings.neighbour[e];
      g.arcs.push_back({new_number[j], static_cast<float>((V.row(i) - V.row(j)).norm())});
    }
  }
  g.start[n] = static_cast<int>(g.arcs.size());
  return g;
}

float Sampling::covering_radius() const {
  return distance.empty() ? 0.0f : *std::max_element(distance.begin(), distance.end());
}

// Each vertex belongs to the cell of its nearest seed; each cell keeps its farthest vertex,
// recomputed (over the cell's member list, pruned of those a newer seed took) only when a new
// seed took some of its vertices, and a lazy max-heap over the cells yields the next seed: O(n)
// besides the pruned Dijkstras, no heap entry per vertex.
Sampling farthest_points(const EdgeGraph& graph, int samples) {
  const int n = graph.size();
  Sampling out;
  out.owner.assign(n, -1);
  out.distance.assign(n, kFar);
  std::vector<int>& owner = out.owner;
  std::vector<int>& seeds = out.seeds;
  std::vector<std::vector<int>> members;
  std::vector<std::pair<float, int>> farthest_of;    // per cell: its farthest member and distance
  std::priority_queue<std::pair<float, int>> cells;  // (distance, cell), lazy
  std::vector<int> dirty;
  std::vector<char> is_dirty;
  DistanceHeap heap;
  int unreached = 0;  // all vertices before it have an owner
  while (true) {
    while (unreached < n && owner[unreached] >= 0) ++unreached;
    int seed = unreached;
    if (seed == n) {  // every vertex reached: the farthest one of the farthest cell
      if (static_cast<int>(seeds.size()) >= samples) break;
      while (!cells.empty()) {
        const auto [d, c] = cells.top();
        if (d == farthest_of[c].first) break;
        cells.pop();
      }
      if (cells.empty() || cells.top().first == 0.0f) break;  // every vertex is a seed
      seed = farthest_of[cells.top().second].second;
    }
    const int cell = static_cast<int>(seeds.size());
    seeds.push_back(seed);
    members.emplace_back();
    farthest_of.emplace_back(0.0f, seed);
    is_dirty.push_back(0);
    pruned_dijkstra(graph, std::span(&seed, 1), kFar, out.distance, heap, [&](int i, float d) {
      if (owner[i] >= 0 && !is_dirty[owner[i]]) {
        is_dirty[owner[i]] = 1;
        dirty.push_back(owner[i]);
      }
      owner[i] = cell;
      members[cell].push_back(i);
      if (d > farthest_of[cell].first) farthest_of[cell] = {d, i};
    });
    cells.emplace(farthest_of[cell].first, cell);
    for (const int c : dirty) {
      std::vector<int>& list = members[c];
      std::erase_if(list, [&](int i) { return owner[i] != c; });
      farthest_of[c] = {0.0f, seeds[c]};
      for (const int i : list)
        if (out.distance[i] > farthest_of[c].first) farthest_of[c] = {out.distance[i], i};
      cells.emplace(farthest_of[c].first, c);
      is_dirty[c] = 0;
    }
    dirty.clear();
  }
  return out;
}

}  // namespace specdeform::detail
