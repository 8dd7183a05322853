// Random sparse matrices for the tests of linalg/'s sparse kernels.
#pragma once

#include <random>
#include <vector>

#include <Eigen/Sparse>

namespace specdeform::test {

// rows x cols with `per_column` normally distributed entries per column, in random rows (the
// entries that land on one position are summed).
inline Eigen::SparseMatrix<double> random_sparse(int rows, int cols, int per_column,
                                                 std::mt19937_64& rng) {
  std::uniform_int_distribution<int> row(0, rows - 1);
  std::normal_distribution<double> value;
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < cols; ++j)
    for (int k = 0; k < per_column; ++k) t.emplace_back(row(rng), j, value(rng));
  Eigen::SparseMatrix<double> A(rows, cols);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

}  // namespace specdeform::test
