#include "linalg/krylov_schur.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

namespace specdeform {
namespace {

using detail::MassOperator;
using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;
using Sparse = Eigen::SparseMatrix<double>;

Sparse diagonal(const Vec& d) {
  Sparse D(d.size(), d.size());
  for (Eigen::Index i = 0; i < d.size(); ++i) D.insert(i, i) = d[i];
  return D;
}

// K = diag(spectrum), M = diag(mass): the eigenpairs are (spectrum_i / mass_i, e_i / sqrt(mass_i)).
// The spectrum 1, 2, 3, ... with a planted triple eigenvalue 9 (then 9.5, 13, 14, ...).
struct DiagonalProblem {
  Vec lambda, mass;
  Sparse K, M;
  explicit DiagonalProblem(int n) : lambda(n), mass(n) {
    for (int i = 0; i < n; ++i) {
      mass[i] = 1.0 + 0.5 * (i % 3);
      lambda[i] = 1.0 + i;
    }
    lambda.segment(8, 3).setConstant(9.0);
    lambda[11] = 9.5;
    std::sort(lambda.data(), lambda.data() + n);
    K = diagonal(lambda.cwiseProduct(mass));
    M = diagonal(mass);
  }
};

// The `wanted` pairs nearest the shift -0.5, blocks of 4, deflated against `found` (given as
// near too); Rayleigh-Ritz applied, so that the pairs come out ascending.
detail::KrylovSchurResult nearest_pairs(const DiagonalProblem& p, const Mat& found, int wanted,
                                        int subspace, uint64_t seed) {
  const MassOperator M(p.M);
  detail::ShiftInvertAnalysis analysis(p.K, p.M);
  std::mt19937_64 rng(seed);
  detail::ShiftInvert op(analysis, -0.5, rng);
  EXPECT_TRUE(op.usable());
  detail::KrylovSchurSettings set;
  set.wanted = wanted;
  set.block = 4;
  set.subspace = subspace;
  set.tolerance = 1e-10;
  detail::KrylovSchurResult r = detail::krylov_schur(op, M, found, found, set, rng, [](double) {});
  detail::rayleigh_ritz(p.K, M, r.H, r.lambda);
  return r;
}

// The wanted pairs nearest the shift, the cluster complete, the vectors in the right coordinates.
TEST(KrylovSchur, DiagonalOperatorWithAPlantedCluster) {
  const DiagonalProblem p(1500);
  const detail::KrylovSchurResult r = nearest_pairs(p, Mat(1500, 0), 20, 48, 1);
  ASSERT_TRUE(r.converged);
  EXPECT_GE(r.restarts, 1);  // 20 wanted in a subspace of 48: it had to restart
  ASSERT_GE(r.lambda.size(), 20);
  for (int i = 0; i < 20; ++i) EXPECT_NEAR(r.lambda[i], p.lambda[i], 1e-9 * p.lambda[i]) << i;
  // H^T M H = I, and the cluster's vectors lie in the span of e_8 ... e_10 (9.5's in e_11).
  EXPECT_LE(
      (r.H.transpose() * p.M * r.H - Mat::Identity(r.H.cols(), r.H.cols())).cwiseAbs().maxCoeff(),
      1e-12);
  for (int j = 8; j <= 10; ++j) {
    Vec outside = r.H.col(j);
    outside.segment(8, 3).setZero();
    EXPECT_LE(outside.norm(), 1e-7) << j;
  }
  EXPECT_NEAR(std::abs(r.H(11, 11)) * std::sqrt(p.mass[11]), 1.0, 1e-7);
}

// Deflation: with the first pairs given as found, the next ones come out, orthogonal to them.
TEST(KrylovSchur, DeflatesThePairsFound) {
  const DiagonalProblem p(800);
  Mat found = Mat::Zero(800, 5);
  for (int i = 0; i < 5; ++i) found(i, i) = 1.0 / std::sqrt(p.mass[i]);
  const detail::KrylovSchurResult r = nearest_pairs(p, found, 10, 32, 2);
  ASSERT_TRUE(r.converged);
  for (int i = 0; i < 10; ++i) EXPECT_NEAR(r.lambda[i], p.lambda[5 + i], 1e-9 * p.lambda[5 + i]);
  EXPECT_LE((found.transpose() * p.M * r.H).cwiseAbs().maxCoeff(), 1e-12);
}

// One symbolic analysis per kind for any number of shifts; every solve exact.
TEST(ShiftInvert, SharesTheAnalysisBetweenShifts) {
  const DiagonalProblem p(300);
  detail::ShiftInvertAnalysis analysis(p.K, p.M);
  std::mt19937_64 rng(3);
  const detail::RowMatrix b = detail::random_block(300, 3, rng);
  for (const double sigma : {-0.1, -2.0, 5.5, 40.5, -0.3}) {
    detail::ShiftInvert op(analysis, sigma, rng);
    ASSERT_TRUE(op.usable()) << sigma;
    detail::RowMatrix x;
    op.solve(b, x);
    const Mat S = Mat(p.K) - sigma * Mat(p.M);
    EXPECT_LE((S * Mat(x) - Mat(b)).cwiseAbs().maxCoeff(), 1e-12) << sigma;
  }
  EXPECT_EQ(analysis.analyses(), 2);  // one definite, one interior
  // A shift on an eigenvalue (a singular matrix) is refused, not solved.
  EXPECT_FALSE(detail::ShiftInvert(analysis, 20.0, rng).usable());
}

// A shift placed in the gap of the eigenvalues seen that holds the target.
TEST(ShiftInvert, ClearShiftUsesTheGapAroundTheTarget) {
  const std::vector<double> known = {1.0, 2.0, 5.0, 6.0};
  EXPECT_DOUBLE_EQ(detail::clear_shift(3.0, known), 3.5);
  EXPECT_DOUBLE_EQ(detail::clear_shift(5.0, known), 3.5);  // on an eigenvalue: the gap below
  EXPECT_DOUBLE_EQ(detail::clear_shift(5.2, known), 5.5);
  EXPECT_DOUBLE_EQ(detail::clear_shift(0.5, known), 0.5);  // outside: unchanged
  EXPECT_DOUBLE_EQ(detail::clear_shift(7.0, known), 7.0);
}

}  // namespace
}  // namespace specdeform
