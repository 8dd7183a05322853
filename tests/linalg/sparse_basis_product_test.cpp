#include "linalg/sparse_basis_product.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "specdeform/exceptions.h"
#include "support/random_sparse.h"

namespace specdeform {
namespace {

using Sparse = Eigen::SparseMatrix<double>;

// Against Eigen's product: several matrices at once, row counts that are not a multiple of the
// blocks (and one smaller than a block), empty columns, and an odd number of basis columns.
TEST(SparseBasisProducts, MatchEigensProduct) {
  std::mt19937_64 rng(3);
  for (const int n : {1, 37, 64, 1000, 4097}) {
    const Eigen::MatrixXd H = Eigen::MatrixXd::Random(n, 13);
    const Sparse A = test::random_sparse(30, n, 3, rng);
    Sparse B = test::random_sparse(7, n, 1, rng);
    B.col(0) *= 0.0;
    B.prune(0.0);
    const std::vector<Eigen::MatrixXd> out = detail::sparse_basis_products({&A, &B}, H);
    ASSERT_EQ(out.size(), 2u);
    EXPECT_LT((out[0] - Eigen::MatrixXd(A * H)).norm(), 1e-12 * (1.0 + out[0].norm())) << n;
    EXPECT_LT((out[1] - Eigen::MatrixXd(B * H)).norm(), 1e-12 * (1.0 + out[1].norm())) << n;
  }
}

TEST(SparseBasisProducts, RefusesMismatchedSizes) {
  const Sparse A(3, 10);
  EXPECT_THROW(detail::sparse_basis_products({&A}, Eigen::MatrixXd::Zero(9, 2)), InputError);
}

}  // namespace
}  // namespace specdeform
