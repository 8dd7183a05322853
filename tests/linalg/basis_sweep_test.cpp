#include "linalg/basis_sweep.h"

#include <gtest/gtest.h>

#include <random>

#include "specdeform/exceptions.h"

namespace specdeform {
namespace {

using detail::RowMatrix;
using Mat = Eigen::MatrixXd;

RowMatrix random_matrix(Eigen::Index rows, Eigen::Index cols, std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  RowMatrix A(rows, cols);
  for (Eigen::Index i = 0; i < A.size(); ++i) A.data()[i] = normal(rng);
  return A;
}

// Every product against its plain Eigen form: row counts that do not divide into the row groups
// or the two threads, 8 and 16 columns, a basis with unused columns, each kind of weighting.
TEST(BasisSweep, MatchesDenseProducts) {
  std::mt19937_64 rng(7);
  for (const Eigen::Index n : {1, 3, 5, 37, 1000}) {
    for (const Eigen::Index w : {8, 16}) {
      const Eigen::Index k = 13;
      const RowMatrix V = random_matrix(n, k + 4, rng);
      const RowMatrix D = random_matrix(k, w, rng);
      const RowMatrix X0 = random_matrix(n, w, rng);
      const Eigen::VectorXd weights = random_matrix(n, 1, rng).array().abs();
      const RowMatrix Y = random_matrix(n, w, rng);
      const Mat Vk = V.leftCols(k);
      const Mat X1 = X0 - Vk * Mat(D);
      const double tol = 1e-12 * static_cast<double>(n);

      RowMatrix X = X0, P, G;
      detail::sweep_basis(V, k, X,
                          {.subtract = &D, .weights = &weights, .projection = &P, .gram = &G});
      EXPECT_LE((Mat(X) - X1).cwiseAbs().maxCoeff(), 1e-12);
      EXPECT_LE((Mat(P) - Vk.transpose() * weights.asDiagonal() * X1).cwiseAbs().maxCoeff(), tol);
      EXPECT_LE((Mat(G) - X1.transpose() * weights.asDiagonal() * X1).cwiseAbs().maxCoeff(), tol);

      X = X0;
      detail::sweep_basis(V, k, X, {.weighted = &Y, .projection = &P, .gram = &G});
      EXPECT_EQ(Mat(X), Mat(X0));
      EXPECT_LE((Mat(P) - Vk.transpose() * Mat(Y)).cwiseAbs().maxCoeff(), tol);
      EXPECT_LE((Mat(G) - Mat(X0).transpose() * Mat(Y)).cwiseAbs().maxCoeff(), tol);

      detail::sweep_basis(V, k, X, {.projection = &P});
      EXPECT_LE((Mat(P) - Vk.transpose() * Mat(X0)).cwiseAbs().maxCoeff(), tol);
    }
  }
}

TEST(BasisSweep, RejectsMismatchedSizes) {
  std::mt19937_64 rng(1);
  const RowMatrix V = random_matrix(10, 5, rng);
  RowMatrix X = random_matrix(10, 8, rng), P;
  EXPECT_THROW(detail::sweep_basis(V, 6, X, {.projection = &P}), InputError);
  RowMatrix narrow = random_matrix(10, 6, rng);
  EXPECT_THROW(detail::sweep_basis(V, 5, narrow, {.projection = &P}), InputError);
  const RowMatrix D = random_matrix(4, 8, rng);
  EXPECT_THROW(detail::sweep_basis(V, 5, X, {.subtract = &D}), InputError);
}

}  // namespace
}  // namespace specdeform
