#include "spectral/coarse_space.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "linalg/parallel.h"
#include "mesh/graph_distance.h"

namespace specdeform::detail {

namespace {

using Sparse = Eigen::SparseMatrix<double>;

// A truncated Gaussian: on the armadillo (N = 1000, m = 100) it gave the first 20 eigenvalues
// within 1.9% at support 2.5 where the Wendland bump (1 - t)^4 (4t + 1) needed support 3 (and
// 1.3 times the entries), 1 - t got 5.2%.
double bump(double t) {
  return t >= 1.0 ? 0.0 : std::exp(-4.0 * t * t) - std::exp(-4.0);
}

}  // namespace

CoarseSpace partition_of_unity(const Sparse& lengths, int samples, double support) {
  const int n = static_cast<int>(lengths.rows());
  const EdgeGraph graph = edge_graph(lengths);
  const Sampling farthest = farthest_points(graph, std::clamp(samples, 1, n));
  const std::vector<int>& seeds = farthest.seeds;
  CoarseSpace out;
  out.radius = farthest.covering_radius();
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
      pruned_dijkstra(graph, std::span(&seeds[j], 1), rho, distance, heap, [&](int i, float d) {
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
