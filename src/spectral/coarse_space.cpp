#include "spectral/coarse_space.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numeric>
#include <queue>
#include <utility>
#include <vector>

#include "linalg/parallel.h"

namespace specdeform::detail {

namespace {

using Sparse = Eigen::SparseMatrix<double>;
constexpr float kFar = std::numeric_limits<float>::infinity();

// The edges as the searches walk them: vertex i's neighbours arcs[start[i] .. start[i + 1]),
// each with its length in single precision (relative 6e-8). One 8-byte arc where the matrix has
// a 4-byte index and an 8-byte value in two arrays, and no diagonal entry: the searches are
// bound by fetching each settled vertex's arcs (692k vertices: the sampling and the bumps 2.5 s
// on the matrix, 1.1 s here with the prefetch below and the bumps in vertex order).
struct EdgeGraph {
  struct Arc {
    int to;
    float length;
  };
  explicit EdgeGraph(const Sparse& lengths) : start(lengths.cols() + 1) {
    arcs.reserve(lengths.nonZeros());
    for (int i = 0; i < lengths.outerSize(); ++i) {
      start[i] = static_cast<int>(arcs.size());
      for (Sparse::InnerIterator it(lengths, i); it; ++it)
        if (it.index() != i) arcs.push_back({it.index(), static_cast<float>(it.value())});
    }
    start.back() = static_cast<int>(arcs.size());
  }
  int size() const { return static_cast<int>(start.size()) - 1; }
  std::vector<int> start;
  std::vector<Arc> arcs;
};

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

// Dijkstra from `source` that only goes where it brings a vertex closer than `distance` already
// has it, and no farther than `limit`; calls visit(vertex, distance) for each vertex it settles.
// A vertex's arcs are prefetched when it enters the heap, long before it is settled.
template <typename Visit>
void pruned_dijkstra(const EdgeGraph& graph, int source, float limit, std::vector<float>& distance,
                     DistanceHeap& heap, Visit&& visit) {
  const int* start = graph.start.data();
  const EdgeGraph::Arc* arcs = graph.arcs.data();
  distance[source] = 0.0f;
  heap.push(0.0f, source);
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

// A truncated Gaussian: on the armadillo (N = 1000, m = 100) it gave the first 20 eigenvalues
// within 1.9% at support 2.5 where the Wendland bump (1 - t)^4 (4t + 1) needed support 3 (and
// 1.3 times the entries), 1 - t got 5.2%.
double bump(double t) {
  return t >= 1.0 ? 0.0 : std::exp(-4.0 * t * t) - std::exp(-4.0);
}

// Farthest-point sampling: each next seed is the vertex farthest from all seeds so far, a vertex
// of a component no seed reaches yet first. Each vertex belongs to the cell of its nearest seed;
// each cell keeps its farthest vertex, recomputed (over the cell's member list, pruned of those a
// newer seed took) only when a new seed took some of its vertices, and a lazy max-heap over the
// cells yields the next seed: O(n) besides the pruned Dijkstras, no heap entry per vertex.
// Returns the seeds; `nearest` gets every vertex's distance to its nearest seed.
std::vector<int> farthest_points(const EdgeGraph& graph, int samples, std::vector<float>& nearest) {
  const int n = graph.size();
  nearest.assign(n, kFar);
  std::vector<int> owner(n, -1), seeds;
  std::vector<std::vector<int>> members;
  std::vector<std::pair<float, int>> farthest_of;    // per cell: its farthest member and distance
  std::priority_queue<std::pair<float, int>> cells;  // (distance, cell), lazy
  std::vector<int> dirty;
  std::vector<char> is_dirty;
  DistanceHeap heap;
  int unreached = 0;  // all vertices before it have an owner
  while (static_cast<int>(seeds.size()) < samples) {
    while (unreached < n && owner[unreached] >= 0) ++unreached;
    int seed = unreached;
    if (seed == n) {  // every vertex reached: the farthest one of the farthest cell
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
    pruned_dijkstra(graph, seed, kFar, nearest, heap, [&](int i, float d) {
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
        if (nearest[i] > farthest_of[c].first) farthest_of[c] = {nearest[i], i};
      cells.emplace(farthest_of[c].first, c);
      is_dirty[c] = 0;
    }
    dirty.clear();
  }
  return seeds;
}

}  // namespace

CoarseSpace partition_of_unity(const Sparse& lengths, int samples, double support) {
  const int n = static_cast<int>(lengths.rows());
  const EdgeGraph graph(lengths);
  std::vector<float> nearest;
  const std::vector<int> seeds = farthest_points(graph, std::clamp(samples, 1, n), nearest);
  CoarseSpace out;
  out.radius = *std::max_element(nearest.begin(), nearest.end());
  const float rho = static_cast<float>(support * out.radius);

  // Column j of P: seed j's bump, by a Dijkstra limited to rho (its entries in the order
  // settled). The seeds are taken in the order of their vertices, which a breadth-first
  // numbering (linalg/locality_order.h) keeps near each other, so that one search finds much of
  // the graph the last one fetched (692k vertices: 0.69 against 0.94 s in the sampling's order);
  // split between two threads.
  const int N = static_cast<int>(seeds.size());
  std::vector<int> in_vertex_order(N);
  std::iota(in_vertex_order.begin(), in_vertex_order.end(), 0);
  std::ranges::sort(in_vertex_order, {}, [&](int j) { return seeds[j]; });
  std::vector<std::vector<std::pair<int, double>>> columns(N);
  const auto bumps = [&](int begin, int end) {
    std::vector<float> distance(n, kFar);
    DistanceHeap heap;
    for (int k = begin; k < end; ++k) {
      const int j = in_vertex_order[k];
      std::vector<std::pair<int, double>>& column = columns[j];
      pruned_dijkstra(graph, seeds[j], rho, distance, heap, [&](int i, float d) {
        column.emplace_back(i, rho > 0.0f ? bump(double{d} / rho) : 1.0);
      });
      for (const auto& [i, value] : column) distance[i] = kFar;
      std::erase_if(column, [](const auto& entry) { return entry.second <= 0.0; });
    }
  };
  run_pair([&] { bumps(0, N / 2); }, [&] { bumps(N / 2, N); });
  // Row-major by counting (each row's entries in column order), each entry divided by its
  // row's sum (the partition of unity).
  Eigen::SparseMatrix<double, Eigen::RowMajor>& R = out.rows;
  R.resize(n, N);
  std::vector<int> fill(n + 1, 0);
  for (const auto& column : columns)
    for (const auto& entry : column) ++fill[entry.first + 1];
  for (int i = 0; i < n; ++i) fill[i + 1] += fill[i];
  R.resizeNonZeros(fill[n]);
  std::copy(fill.begin(), fill.end(), R.outerIndexPtr());
  for (int j = 0; j < N; ++j) {
    for (const auto& [i, value] : columns[j]) {
      const int at = fill[i]++;
      R.innerIndexPtr()[at] = j;
      R.valuePtr()[at] = value;
    }
    columns[j] = {};
  }
  for (int i = 0; i < n; ++i) {
    const double sum = R.row(i).sum();
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(R, i); it; ++it) {
      it.valueRef() /= sum;
    }
  }
  out.prolongation = R;  // Eigen's transposition is the same counting
  return out;
}

Sparse edge_lengths(const Sparse& K, const Eigen::MatrixX3d& V) {
  Sparse L = K;
  for (int j = 0; j < L.outerSize(); ++j)
    for (Sparse::InnerIterator it(L, j); it; ++it)
      it.valueRef() = (V.row(it.row()) - V.row(j)).norm();
  return L;
}

Sparse estimated_edge_lengths(const Sparse& K, const Sparse& M) {
  const Eigen::VectorXd area = M * Eigen::VectorXd::Ones(M.cols());
  Sparse L = K;
  for (int j = 0; j < L.outerSize(); ++j)
    for (Sparse::InnerIterator it(L, j); it; ++it)
      it.valueRef() = std::sqrt(0.5 * (area[it.row()] + area[j]));
  return L;
}

}  // namespace specdeform::detail
