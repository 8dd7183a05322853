#include "spectral/coarse_space.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <utility>
#include <vector>

#include "linalg/parallel.h"

namespace specdeform::detail {

namespace {

using Sparse = Eigen::SparseMatrix<double>;
using Entry = std::pair<double, int>;  // (distance, vertex)
using MinHeap = std::priority_queue<Entry, std::vector<Entry>, std::greater<>>;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Dijkstra from `source` that only goes where it brings a vertex closer than `distance` already
// has it, and no farther than `limit`; calls visit(vertex, distance) for each vertex it settles.
template <typename Visit>
void pruned_dijkstra(const Sparse& lengths, int source, double limit, std::vector<double>& distance,
                     MinHeap& heap, Visit&& visit) {
  distance[source] = 0.0;
  heap.emplace(0.0, source);
  while (!heap.empty()) {
    const auto [d, i] = heap.top();
    heap.pop();
    if (d > distance[i]) continue;  // a stale entry
    visit(i, d);
    for (Sparse::InnerIterator it(lengths, i); it; ++it) {
      const int j = static_cast<int>(it.row());
      const double e = d + it.value();
      if (j != i && e < distance[j] && e <= limit) {
        distance[j] = e;
        heap.emplace(e, j);
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
std::vector<int> farthest_points(const Sparse& lengths, int samples, std::vector<double>& nearest) {
  const int n = static_cast<int>(lengths.rows());
  nearest.assign(n, kInfinity);
  std::vector<int> owner(n, -1), seeds;
  std::vector<std::vector<int>> members;
  std::vector<Entry> farthest_of;  // per cell: (distance, vertex) of its farthest member
  std::priority_queue<std::pair<double, int>> cells;  // (distance, cell), lazy
  std::vector<int> dirty;
  std::vector<char> is_dirty;
  MinHeap heap;
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
      if (cells.empty() || cells.top().first == 0.0) break;  // every vertex is a seed
      seed = farthest_of[cells.top().second].second;
    }
    const int cell = static_cast<int>(seeds.size());
    seeds.push_back(seed);
    members.emplace_back();
    farthest_of.emplace_back(0.0, seed);
    is_dirty.push_back(0);
    pruned_dijkstra(lengths, seed, kInfinity, nearest, heap, [&](int i, double d) {
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
      farthest_of[c] = {0.0, seeds[c]};
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
  std::vector<double> nearest;
  const std::vector<int> seeds = farthest_points(lengths, std::clamp(samples, 1, n), nearest);
  CoarseSpace out;
  out.radius = *std::max_element(nearest.begin(), nearest.end());
  const double rho = support * out.radius;

  // Column j of P: seed j's bump, by a Dijkstra limited to rho (its entries in the order
  // settled); the seeds split between two threads.
  const int N = static_cast<int>(seeds.size());
  std::vector<std::vector<std::pair<int, double>>> columns(N);
  const auto bumps = [&](int begin, int end) {
    std::vector<double> distance(n, kInfinity);
    MinHeap local;
    for (int j = begin; j < end; ++j) {
      std::vector<std::pair<int, double>>& column = columns[j];
      pruned_dijkstra(lengths, seeds[j], rho, distance, local, [&](int i, double d) {
        column.emplace_back(i, rho > 0.0 ? bump(d / rho) : 1.0);
      });
      for (const auto& [i, value] : column) distance[i] = kInfinity;
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
