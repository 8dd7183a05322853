#include "linalg/galerkin_product.h"

#include <gtest/gtest.h>

#include <random>

#include "support/random_sparse.h"

namespace specdeform {
namespace {

using Sparse = Eigen::SparseMatrix<double>;

// Against the plain sparse product, for a symmetric A with and without off-diagonal entries,
// with columns of P that share rows and an empty column.
TEST(GalerkinProducts, MatchTheSparseProducts) {
  std::mt19937_64 rng(7);
  const Sparse B = test::random_sparse(400, 400, 5, rng);
  const Sparse symmetric = Sparse(B + Sparse(B.transpose()));
  Sparse diagonal(400, 400);
  for (int i = 0; i < 400; ++i) diagonal.insert(i, i) = 1.0 + i;
  Sparse P = test::random_sparse(400, 41, 12, rng);
  P.col(40) *= 0.0;
  P.prune(0.0);
  const Eigen::SparseMatrix<double, Eigen::RowMajor> rows = P;
  const std::array<Sparse, 2> products = detail::galerkin_products(symmetric, diagonal, P, rows);
  for (int k = 0; k < 2; ++k) {
    const Sparse& A = k == 0 ? symmetric : diagonal;
    const Eigen::MatrixXd expected = Eigen::MatrixXd(P.transpose() * A * P);
    const Sparse& C = products[k];
    ASSERT_EQ(C.rows(), 41);
    ASSERT_EQ(C.cols(), 41);
    EXPECT_LT((Eigen::MatrixXd(C) - expected).cwiseAbs().maxCoeff(),
              1e-12 * expected.cwiseAbs().maxCoeff());
    EXPECT_EQ((Eigen::MatrixXd(C) - Eigen::MatrixXd(C).transpose()).cwiseAbs().maxCoeff(), 0.0);
  }
}

}  // namespace
}  // namespace specdeform
