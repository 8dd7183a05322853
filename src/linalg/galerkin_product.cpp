#include "linalg/galerkin_product.h"

#include <vector>

#include "linalg/parallel.h"

namespace specdeform::detail {

namespace {

using Sparse = Eigen::SparseMatrix<double>;
using RowSparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;
using Triplets = std::vector<Eigen::Triplet<double>>;

// Two dense vectors of which only the touched entries are non-zero, cleared entry by entry.
struct Accumulator {
  explicit Accumulator(Eigen::Index size) : value(2 * size, 0.0), marked(size, 0) {}
  void mark(int i) {
    if (!marked[i]) {
      marked[i] = 1;
      touched.push_back(i);
    }
  }
  void add(int i, double a, double b) {
    mark(i);
    value[2 * i] += a;
    value[2 * i + 1] += b;
  }
  // Calls f(i, first, second) for each touched entry and clears it.
  template <typename F>
  void drain(F&& f) {
    for (const int i : touched) {
      f(i, value[2 * i], value[2 * i + 1]);
      value[2 * i] = value[2 * i + 1] = 0.0;
      marked[i] = 0;
    }
    touched.clear();
  }
  std::vector<double> value;  // interleaved: first, second
  std::vector<char> marked;
  std::vector<int> touched;
};

// The symmetric matrix of which the triplets give the upper triangle.
Sparse symmetric(const Triplets& halves0, const Triplets& halves1, int N) {
  Triplets all;
  all.reserve(2 * (halves0.size() + halves1.size()));
  for (const Triplets* half : {&halves0, &halves1}) {
    for (const Eigen::Triplet<double>& t : *half) {
      all.push_back(t);
      if (t.row() != t.col()) all.emplace_back(t.col(), t.row(), t.value());
    }
  }
  Sparse C(N, N);
  C.setFromTriplets(all.begin(), all.end());
  return C;
}

}  // namespace

std::array<Sparse, 2> galerkin_products(const Sparse& K, const Sparse& M, const Sparse& P,
                                        const RowSparse& P_rows) {
  const int N = static_cast<int>(P.cols());
  struct Half {
    Triplets k, m;
  };
  const auto columns = [&](int begin, int end, Half& out) {
    Accumulator applied(K.rows()), projected(N);
    for (int j = begin; j < end; ++j) {
      for (Sparse::InnerIterator p(P, j); p; ++p) {  // K P_j, M P_j (columns i: rows i)
        for (Sparse::InnerIterator a(K, p.index()); a; ++a)
          applied.add(static_cast<int>(a.index()), a.value() * p.value(), 0.0);
        for (Sparse::InnerIterator a(M, p.index()); a; ++a)
          applied.add(static_cast<int>(a.index()), 0.0, a.value() * p.value());
      }
      applied.drain([&](int l, double k, double m) {  // rows c <= j of P^T (K P_j), P^T (M P_j)
        for (RowSparse::InnerIterator q(P_rows, l); q && q.index() <= j; ++q)
          projected.add(static_cast<int>(q.index()), q.value() * k, q.value() * m);
      });
      projected.drain([&](int c, double k, double m) {
        if (k != 0.0) out.k.emplace_back(c, j, k);
        if (m != 0.0) out.m.emplace_back(c, j, m);
      });
    }
  };
  Half halves[2];
  run_pair([&] { columns(N / 2, N, halves[1]); }, [&] { columns(0, N / 2, halves[0]); });
  return {symmetric(halves[0].k, halves[1].k, N), symmetric(halves[0].m, halves[1].m, N)};
}

}  // namespace specdeform::detail
