#include "spectral/coarse_space.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <utility>
#include <vector>

#include "linalg/huge_pages.h"
#include "linalg/parallel.h"

namespace specdeform::detail {

namespace {

using Sparse = Eigen::SparseMatrix<double>;

// A truncated Gaussian: on the armadillo (N = 1000, m = 100) it gave the first 20 eigenvalues
// within 1.9% at support 2.5 where the Wendland bump (1 - t)^4 (4t + 1) needed support 3 (and
// 1.3 times the entries), 1 - t got 5.2%.
double bump(double t) {
  return t >= 1.0 ? 0.0 : std::exp(-4.0 * t * t) - std::exp(-4.0);
}

// One thread's columns of P, their entries (row, value) one after the other in one array on
// huge pages: a vector per column took a fifth of the basis's page faults at 692k, growing.
struct Columns {
  std::vector<std::pair<int, double>> entries;
  std::vector<size_t> end;  // column k of the thread's ends at end[k]

  void reserve(size_t count) {
    entries.reserve(count);
    advise_huge_pages(entries.data(), sizeof(entries[0]) * count);
  }
};

// A thread's columns, the first numbered `first`, into R's rows at fill[row]++.
void place(const Columns& columns, int first, std::vector<int>& fill,
           Eigen::SparseMatrix<double, Eigen::RowMajor>& R) {
  size_t e = 0;
  for (size_t k = 0; k < columns.end.size(); ++k) {
    for (; e < columns.end[k]; ++e) {
      const auto& [i, value] = columns.entries[e];
      const int at = fill[i]++;
      R.innerIndexPtr()[at] = first + static_cast<int>(k);
      R.valuePtr()[at] = value;
    }
  }
}

// P = R in column-major storage by counting, on huge pages, each thread placing half of the
// columns (Eigen's conversion is the same counting, on one thread and 4 KB pages).
void column_major(const Eigen::SparseMatrix<double, Eigen::RowMajor>& R, Sparse& P) {
  const int n = static_cast<int>(R.rows()), N = static_cast<int>(R.cols());
  const int nnz = static_cast<int>(R.nonZeros());
  const int* row_start = R.outerIndexPtr();
  const int* column = R.innerIndexPtr();
  const double* value = R.valuePtr();
  P.resize(n, N);
  P.resizeNonZeros(nnz);
  advise_huge_pages(P);
  int* start = P.outerIndexPtr();
  std::fill_n(start, N + 1, 0);
  for (int e = 0; e < nnz; ++e) ++start[column[e] + 1];
  for (int j = 0; j < N; ++j) start[j + 1] += start[j];
  std::vector<int> fill(start, start + N);
  const auto place_columns = [&](int first, int last) {
    for (int i = 0; i < n; ++i) {
      for (int e = row_start[i]; e < row_start[i + 1]; ++e) {
        if (column[e] < first || column[e] >= last) continue;
        const int at = fill[column[e]]++;
        P.innerIndexPtr()[at] = i;
        P.valuePtr()[at] = value[e];
      }
    }
  };
  run_pair([&] { place_columns(0, N / 2); }, [&] { place_columns(N / 2, N); });
}

}  // namespace

CoarseSpace partition_of_unity(const Sparse& lengths, int samples, double support) {
  const EdgeGraph graph = edge_graph(lengths);
  const int n = static_cast<int>(lengths.rows());
  return partition_of_unity(graph, farthest_points(graph, std::clamp(samples, 1, n)), support);
}

CoarseSpace partition_of_unity(const EdgeGraph& graph, const Sampling& farthest, double support) {
  const int n = graph.size();
  CoarseSpace out;
  out.radius = farthest.covering_radius();
  const float rho = static_cast<float>(support * out.radius);

  // Column j of P: the bump of the j-th seed in the order of their vertices, by a Dijkstra
  // limited to rho (its entries in the order settled). A breadth-first numbering
  // (linalg/locality_order.h) keeps seeds of nearby numbers near each other, so that one search
  // finds much of the graph the last one fetched (692k vertices: 0.69 against 0.94 s in the
  // sampling's order). The columns split between two threads, each counting its entries per row.
  std::vector<int> seed = farthest.seeds;
  std::ranges::sort(seed);
  const int N = static_cast<int>(seed.size());
  Columns columns[2];
  std::vector<int> count[2] = {std::vector<int>(n, 0), std::vector<int>(n, 0)};
  const auto bumps = [&](int begin, int end, Columns& out, std::vector<int>& rows) {
    // About 2 support^2 functions cover a vertex (coarse_space.h): half of them this thread's.
    out.reserve(static_cast<size_t>(n * (support * support + 1.0)));
    std::vector<float> distance(n, kFar);
    DistanceHeap heap;
    for (int j = begin; j < end; ++j) {
      const size_t first = out.entries.size();
      pruned_dijkstra(graph, std::span(&seed[j], 1), rho, distance, heap, [&](int i, float d) {
        out.entries.emplace_back(i, rho > 0.0f ? bump(double{d} / rho) : 1.0);
      });
      const auto column = std::span(out.entries).subspan(first);
      for (const auto& [i, value] : column) distance[i] = kFar;
      const auto dropped =
          std::ranges::remove_if(column, [](const auto& e) { return e.second <= 0.0; });
      out.entries.resize(out.entries.size() - dropped.size());
      for (size_t e = first; e < out.entries.size(); ++e) ++rows[out.entries[e].first];
      out.end.push_back(out.entries.size());
    }
  };
  run_pair([&] { bumps(0, N / 2, columns[0], count[0]); },
           [&] { bumps(N / 2, N, columns[1], count[1]); });
  // Row-major by counting: each row's entries of the first half of the columns, then of the
  // second (so in column order), each thread placing its own; then each entry divided by its
  // row's sum (the partition of unity).
  Eigen::SparseMatrix<double, Eigen::RowMajor>& R = out.rows;
  R.resize(n, N);
  int* start = R.outerIndexPtr();
  start[0] = 0;
  for (int i = 0; i < n; ++i) start[i + 1] = start[i] + count[0][i] + count[1][i];
  R.resizeNonZeros(start[n]);
  advise_huge_pages(R);
  run_pair(
      [&] {
        for (int i = 0; i < n; ++i) count[0][i] = start[i];
        place(columns[0], 0, count[0], R);
        columns[0] = {};
      },
      [&] {
        for (int i = 0; i < n; ++i)
          count[1][i] = start[i + 1] - count[1][i];  // after the first half
        place(columns[1], N / 2, count[1], R);
        columns[1] = {};
      });
  split_in_two(n, [&](Eigen::Index begin, Eigen::Index end) {
    double* value = R.valuePtr();
    for (Eigen::Index i = begin; i < end; ++i) {
      double sum = 0.0;
      for (int e = start[i]; e < start[i + 1]; ++e) sum += value[e];
      for (int e = start[i]; e < start[i + 1]; ++e) value[e] /= sum;
    }
  });
  column_major(R, out.prolongation);
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
