#include "linalg/mass_operator.h"

#include <gtest/gtest.h>

#include <random>

#include "linalg/block_orthogonalization.h"

namespace specdeform {
namespace {

using detail::MassOperator;
using detail::RowMatrix;
using Mat = Eigen::MatrixXd;
using Sparse = Eigen::SparseMatrix<double>;

// A lumped (diagonal) and a consistent-like (tridiagonal, diagonally dominant) mass matrix.
Sparse diagonal_mass(int n) {
  Sparse M(n, n);
  for (int i = 0; i < n; ++i) M.insert(i, i) = 1.0 + 0.5 * std::sin(i);
  return M;
}

Sparse banded_mass(int n) {
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(i, i, 2.0 + std::cos(i));
    if (i + 1 < n) t.emplace_back(i, i + 1, 0.25), t.emplace_back(i + 1, i, 0.25);
  }
  Sparse M(n, n);
  M.setFromTriplets(t.begin(), t.end());
  return M;
}

// Every product against the plain sparse one, on both paths.
TEST(MassOperator, MatchesTheSparseProducts) {
  std::mt19937_64 rng(3);
  for (const Sparse& Ms : {diagonal_mass(301), banded_mass(301)}) {
    const MassOperator M(Ms);
    EXPECT_EQ(M.diagonal(), Ms.nonZeros() == Ms.rows());
    const Mat X = detail::random_block(301, 8, rng);
    const Mat MX = Ms * X;
    EXPECT_LE((M.apply(X) - MX).cwiseAbs().maxCoeff(), 1e-13);
    EXPECT_LE((M.gram(X) - X.transpose() * MX).cwiseAbs().maxCoeff(), 1e-11);
    EXPECT_LE((M.norms(X) - (X.transpose() * MX).diagonal().cwiseSqrt()).cwiseAbs().maxCoeff(),
              1e-12);
    RowMatrix out;
    M.apply(RowMatrix(X), out);
    EXPECT_LE((Mat(out) - MX).cwiseAbs().maxCoeff(), 1e-13);
  }
}

// project(): X -= V D, then V^T M X and X^T M X, as the Krylov step uses it.
TEST(MassOperator, ProjectsAgainstABasis) {
  std::mt19937_64 rng(5);
  for (const Sparse& Ms : {diagonal_mass(257), banded_mass(257)}) {
    const MassOperator M(Ms);
    Mat B = detail::random_block(257, 20, rng);
    detail::orthonormalize(B, {}, M, rng);
    const RowMatrix V = B;
    const RowMatrix X0 = detail::random_block(257, 8, rng);
    const RowMatrix D = detail::random_block(12, 8, rng);
    RowMatrix X = X0, P, G;
    M.project(V, 12, X, &D, &P, &G);
    const Mat X1 = Mat(X0) - B.leftCols(12) * Mat(D);
    EXPECT_LE((Mat(X) - X1).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LE((Mat(P) - B.leftCols(12).transpose() * (Ms * X1)).cwiseAbs().maxCoeff(), 1e-10);
    EXPECT_LE((Mat(G) - X1.transpose() * (Ms * X1)).cwiseAbs().maxCoeff(), 1e-9);
  }
}

}  // namespace
}  // namespace specdeform
