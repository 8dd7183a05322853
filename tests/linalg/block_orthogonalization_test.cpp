#include "linalg/block_orthogonalization.h"

#include <gtest/gtest.h>

#include <random>

#include "specdeform/exceptions.h"

namespace specdeform {
namespace {

using detail::MassOperator;
using Mat = Eigen::MatrixXd;
using Sparse = Eigen::SparseMatrix<double>;

Sparse mass(int n) {
  Sparse M(n, n);
  for (int i = 0; i < n; ++i) M.insert(i, i) = 0.5 + (i % 7) * 0.25;
  return M;
}

// rows x cols, M-orthonormal.
Mat orthonormal_block(int rows, int cols, const MassOperator& M, std::mt19937_64& rng) {
  Mat B = detail::random_block(rows, cols, rng);
  detail::orthonormalize(B, {}, M, rng);
  return B;
}

double orthonormality(const Mat& W, const Sparse& M) {
  return (W.transpose() * M * W - Mat::Identity(W.cols(), W.cols())).cwiseAbs().maxCoeff();
}

// Cholesky QR keeps W R and makes W M-orthonormal for a well-conditioned block.
TEST(BlockOrthogonalization, CholeskyQrKeepsTheProduct) {
  std::mt19937_64 rng(1);
  const Sparse Ms = mass(500);
  const MassOperator M(Ms);
  const Mat W0 = detail::random_block(500, 8, rng);
  Mat W = W0, R = Mat::Identity(8, 8);
  ASSERT_TRUE(detail::cholesky_qr2(W, M, R));
  EXPECT_LE(orthonormality(W, Ms), 1e-13);
  EXPECT_LE((W * R - W0).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LE(R.triangularView<Eigen::StrictlyLower>().toDenseMatrix().cwiseAbs().maxCoeff(), 0.0);
}

// With a lag: W = W_true + V E, W_true M-orthogonal to V. Cholesky QR on W alone (no product
// with V) makes W - V E M-orthonormal, keeps (W - V E) R = W_true and turns E along with W.
TEST(BlockOrthogonalization, CholeskyQrWithALag) {
  std::mt19937_64 rng(5);
  const Sparse Ms = mass(600);
  const MassOperator M(Ms);
  const Mat V = orthonormal_block(600, 40, M, rng);
  Mat W_true = detail::random_block(600, 8, rng);
  detail::project_out(W_true, {V}, M);
  const Mat E0 = 1e-4 * detail::random_block(40, 8, rng);
  Mat W = W_true + V * E0, E = E0, R = Mat::Identity(8, 8);
  ASSERT_TRUE(detail::cholesky_qr2(W, M, R, Mat(), &E));
  const Mat Q = W - V * E;
  EXPECT_LE(orthonormality(Q, Ms), 1e-13);
  EXPECT_LE((V.transpose() * Ms * Q).cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_LE((Q * R - W_true).cwiseAbs().maxCoeff(), 1e-12);
  // Without the lag the same block is orthonormalised with V's part in it.
  Mat W2 = W_true + V * E0, R2 = Mat::Identity(8, 8);
  ASSERT_TRUE(detail::cholesky_qr2(W2, M, R2));
  EXPECT_GE((V.transpose() * Ms * W2).cwiseAbs().maxCoeff(), 1e-7);
}

// A block with planted dependent columns: Cholesky QR refuses it (W R unchanged), column
// Gram-Schmidt hands exactly the dependent columns to the callback.
TEST(BlockOrthogonalization, PlantedDependentColumns) {
  std::mt19937_64 rng(2);
  const Sparse Ms = mass(400);
  const MassOperator M(Ms);
  Mat W0 = detail::random_block(400, 6, rng);
  W0.col(3) = 2.0 * W0.col(0) - W0.col(1);   // dependent
  W0.col(5) = W0.col(2) * 1e-3 + W0.col(4);  // dependent
  Mat W = W0, R = Mat::Identity(6, 6);
  EXPECT_FALSE(detail::cholesky_qr2(W, M, R));
  EXPECT_LE((W * R - W0).cwiseAbs().maxCoeff(), 1e-10);

  W = W0;
  std::vector<int> replaced;
  detail::column_gram_schmidt(W, M, 1e-8, R, [&](int j) {
    replaced.push_back(j);
    Mat fresh = detail::random_block(400, 1, rng);
    detail::orthonormalize(fresh, {W.leftCols(j)}, M, rng);
    W.col(j) = fresh.col(0);
  });
  EXPECT_EQ(replaced, (std::vector<int>{3, 5}));
  EXPECT_LE(orthonormality(W, Ms), 1e-12);
  // The independent columns are reproduced by W R; the dependent ones by the earlier columns.
  const Mat WR = W * R;
  for (int j : {0, 1, 2, 4}) EXPECT_LE((WR.col(j) - W0.col(j)).cwiseAbs().maxCoeff(), 1e-10);

  W = W0;
  detail::orthonormalize(W, {}, M, rng);
  EXPECT_LE(orthonormality(W, Ms), 1e-12);
}

// Projection against a basis, and a full orthonormalisation against one: no component left.
TEST(BlockOrthogonalization, ProjectsOutBases) {
  std::mt19937_64 rng(3);
  const Sparse Ms = mass(300);
  const MassOperator M(Ms);
  const Mat B = orthonormal_block(300, 30, M, rng);
  Mat W = detail::random_block(300, 8, rng);
  W.col(0) = B.col(4) + 1e-9 * W.col(0);  // almost in the basis: cancellation, a second pass
  detail::project_out(W, {B.leftCols(10), B.rightCols(20)}, M);
  EXPECT_LE((B.transpose() * Ms * W).cwiseAbs().maxCoeff(), 1e-14 * 1e3);
  detail::orthonormalize(W, {B}, M, rng);
  EXPECT_LE(orthonormality(W, Ms), 1e-12);
  EXPECT_LE((B.transpose() * Ms * W).cwiseAbs().maxCoeff(), 1e-12);
}

// More columns wanted than the space has room for.
TEST(BlockOrthogonalization, RefusesABlockLargerThanTheSpace) {
  std::mt19937_64 rng(4);
  const Sparse Ms = mass(10);
  const MassOperator M(Ms);
  const Mat B = orthonormal_block(10, 8, M, rng);
  Mat W = detail::random_block(10, 4, rng);
  EXPECT_THROW(detail::orthonormalize(W, {B}, M, rng), SolverError);
}

}  // namespace
}  // namespace specdeform
