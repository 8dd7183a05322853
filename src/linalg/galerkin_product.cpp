#include "linalg/galerkin_product.h"

#include <vector>

#include "linalg/parallel.h"

namespace specdeform::detail {

namespace {

using Sparse = Eigen::SparseMatrix<double>;
using Triplets = std::vector<Eigen::Triplet<double>>;

// A dense vector of which only the touched entries are non-zero, cleared entry by entry.
struct Accumulator {
  explicit Accumulator(Eigen::Index size) : value(size, 0.0), marked(size, 0) {}
  void add(int i, double v) {
    if (!marked[i]) {
      marked[i] = 1;
      touched.push_back(i);
    }
    value[i] += v;
  }
  // Calls f(i, value) for each touched entry and clears it.
  template <typename F>
  void drain(F&& f) {
    for (const int i : touched) {
      f(i, value[i]);
      value[i] = 0.0;
      marked[i] = 0;
    }
    touched.clear();
  }
  std::vector<double> value;
  std::vector<char> marked;
  std::vector<int> touched;
};

}  // namespace

Sparse galerkin_product(const Sparse& A, const Sparse& P) {
  const int N = static_cast<int>(P.cols());
  const Eigen::SparseMatrix<double, Eigen::RowMajor> rows = P;
  const auto columns = [&](int begin, int end, Triplets& out) {
    Accumulator applied(A.rows()), projected(N);
    for (int j = begin; j < end; ++j) {
      for (Sparse::InnerIterator p(P, j); p; ++p)  // A P_j (A's column i is its row i)
        for (Sparse::InnerIterator a(A, p.index()); a; ++a)
          applied.add(static_cast<int>(a.index()), a.value() * p.value());
      applied.drain([&](int l, double v) {  // P^T (A P_j)
        for (decltype(rows)::InnerIterator q(rows, l); q; ++q)
          projected.add(static_cast<int>(q.index()), q.value() * v);
      });
      projected.drain([&](int k, double v) { out.emplace_back(k, j, v); });
    }
  };
  Triplets halves[2];
  run_pair([&] { columns(N / 2, N, halves[1]); }, [&] { columns(0, N / 2, halves[0]); });
  halves[0].insert(halves[0].end(), halves[1].begin(), halves[1].end());
  Sparse C(N, N);
  C.setFromTriplets(halves[0].begin(), halves[0].end());
  const Sparse transposed = C.transpose();
  return 0.5 * (C + transposed);
}

}  // namespace specdeform::detail
