// Internal: distances along a mesh's edges (Dijkstra's shortest paths on its edge graph) and the
// farthest-point sampling built on them: the multilevel basis's coarse space
// (spectral/coarse_space.h), ARAP's rotation clusters (mesh/vertex_clusters.h) and the handles'
// region of influence (deform/influence.h).
//
// Lengths and distances are single precision (relative 6e-8): the searches are bound by fetching
// each settled vertex's arcs, and an arc here is 8 bytes (neighbour and length side by side)
// where a sparse matrix keeps a 4-byte index and an 8-byte value in two arrays and a diagonal
// entry besides. A vertex's arcs are prefetched when it enters the heap, long before it is
// settled (692k vertices, the coarse space's sampling and bumps: 2.5 s on the matrix, 1.1 s
// here). Number the vertices breadth first for long searches (linalg/locality_order.h): a
// search then finds nearby the arcs it fetches next.
#pragma once

#include <bit>
#include <cstdint>
#include <functional>
#include <limits>
#include <queue>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Sparse>

#include "mesh/vertex_rings.h"
#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform::detail {

constexpr float kFar = std::numeric_limits<float>::infinity();

// Vertex i's neighbours are arcs[start[i] .. start[i + 1]).
struct EdgeGraph {
  struct Arc {
    int to;
    float length;
  };
  std::vector<int> start;  // n + 1
  std::vector<Arc> arcs;
  int size() const { return static_cast<int>(start.size()) - 1; }
};

// The off-diagonal entries of a symmetric n x n matrix as arcs, their values as lengths (>= 0).
EdgeGraph edge_graph(const Eigen::SparseMatrix<double>& lengths);
// The mesh's edges with their Euclidean lengths.
EdgeGraph edge_graph(const TriangleMesh& mesh);
// The same from the mesh's rings and positions V, vertex i numbered new_number[i] in the graph
// (a permutation of 0 .. n-1).
EdgeGraph edge_graph(const VertexRings& rings, const Vertices& V, std::span<const int> new_number);

// A min-heap of (distance, vertex), each entry one integer: a non-negative float's bits order as
// its value does, so the distance's bits above the vertex's order the entries by distance.
class DistanceHeap {
 public:
  bool empty() const { return heap_.empty(); }
  void push(float distance, int vertex) {
    heap_.push(static_cast<uint64_t>(std::bit_cast<uint32_t>(distance)) << 32 |
               static_cast<uint32_t>(vertex));
  }
  std::pair<float, int> pop() {
    const uint64_t top = heap_.top();
    heap_.pop();
    return {std::bit_cast<float>(static_cast<uint32_t>(top >> 32)), static_cast<int>(top)};
  }

 private:
  std::priority_queue<uint64_t, std::vector<uint64_t>, std::greater<>> heap_;
};

// Dijkstra from the sources (put at distance 0) that only goes where it brings a vertex closer
// than `distance` (n) already has it, and no farther than `limit`; calls visit(vertex, distance)
// for each vertex it settles, in the order of their distances.
template <typename Visit>
void pruned_dijkstra(const EdgeGraph& graph, std::span<const int> sources, float limit,
                     std::vector<float>& distance, DistanceHeap& heap, Visit&& visit) {
  const int* start = graph.start.data();
  const EdgeGraph::Arc* arcs = graph.arcs.data();
  for (const int source : sources) {
    distance[source] = 0.0f;
    heap.push(0.0f, source);
  }
  while (!heap.empty()) {
    const auto [d, i] = heap.pop();
    if (d > distance[i]) continue;  // a stale entry
    visit(i, d);
    for (int e = start[i]; e < start[i + 1]; ++e) {
      const int j = arcs[e].to;
      const float to_j = d + arcs[e].length;
      if (to_j < distance[j] && to_j <= limit) {
        distance[j] = to_j;
        __builtin_prefetch(arcs + start[j]);
        heap.push(to_j, j);
      }
    }
  }
}

// Farthest-point sampling: each next seed is the vertex farthest from all seeds so far, the
// lowest-numbered vertex of a connected component no seed reaches yet first (the first seed is
// vertex 0). Stops at `samples` seeds once every component has one (so at
// max(samples, components), never more than n), or earlier when every vertex is a seed.
struct Sampling {
  std::vector<int> seeds;
  std::vector<int> owner;         // n: the seed (its index in `seeds`) nearest to each vertex
  std::vector<float> distance;    // n: the distance to it
  float covering_radius() const;  // the largest distance: every vertex is this near a seed
};
Sampling farthest_points(const EdgeGraph& graph, int samples);

}  // namespace specdeform::detail
