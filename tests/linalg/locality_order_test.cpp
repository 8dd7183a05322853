#include "linalg/locality_order.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

namespace specdeform {
namespace {

using Sparse = Eigen::SparseMatrix<double>;

// The Laplacian pattern of a side x side grid (plus a lone vertex: a second component), its
// vertices numbered at random.
Sparse shuffled_grid(int side, std::vector<int>& number) {
  const int n = side * side + 1;
  number.resize(n);
  std::iota(number.begin(), number.end(), 0);
  std::shuffle(number.begin(), number.end(), std::mt19937(5));
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) t.emplace_back(number[i], number[i], 4.0 + i);
  for (int r = 0; r < side; ++r) {
    for (int c = 0; c < side; ++c) {
      const int v = r * side + c;
      for (const int w : {c + 1 < side ? v + 1 : -1, r + 1 < side ? v + side : -1}) {
        if (w < 0) continue;
        t.emplace_back(number[v], number[w], -1.0 - v);
        t.emplace_back(number[w], number[v], -1.0 - v);
      }
    }
  }
  Sparse A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

int bandwidth(const Sparse& A) {
  int b = 0;
  for (int j = 0; j < A.outerSize(); ++j)
    for (Sparse::InnerIterator it(A, j); it; ++it) b = std::max(b, std::abs(int(it.index()) - j));
  return b;
}

TEST(LocalityOrder, ABreadthFirstNumberingIsAPermutationThatNarrowsTheBand) {
  std::vector<int> number;
  const Sparse A = shuffled_grid(30, number);
  const detail::Permutation P = detail::breadth_first_order(A);
  std::vector<int> seen(P.indices().data(), P.indices().data() + P.size());
  std::sort(seen.begin(), seen.end());
  std::vector<int> all(A.rows());
  std::iota(all.begin(), all.end(), 0);
  EXPECT_EQ(seen, all);
  const Sparse B = detail::renumbered(A, P);
  EXPECT_GT(bandwidth(A), 500);
  EXPECT_LE(bandwidth(B), 2 * 30 + 1);  // a breadth-first front of a grid spans two diagonals
  // P A P^T exactly, with each column's rows sorted.
  const Sparse expected = P * A * P.transpose();
  EXPECT_EQ(Eigen::MatrixXd(B), Eigen::MatrixXd(expected));
  for (int j = 0; j < B.outerSize(); ++j)
    for (int e = B.outerIndexPtr()[j] + 1; e < B.outerIndexPtr()[j + 1]; ++e)
      EXPECT_LT(B.innerIndexPtr()[e - 1], B.innerIndexPtr()[e]);
  // Rows of X computed in the new numbering come back to the old one.
  const Eigen::MatrixXd X = Eigen::MatrixXd::Random(A.rows(), 3);
  Eigen::MatrixXd Y = P * X;
  detail::permute_rows_back(P, Y);
  EXPECT_EQ(Y, X);
}

}  // namespace
}  // namespace specdeform
