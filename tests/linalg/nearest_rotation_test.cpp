#include "linalg/nearest_rotation.h"

#include <gtest/gtest.h>

#include <cstdlib>

#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace specdeform {
namespace {

// The reference: Jacobi SVD with the reflection removed.
Eigen::Matrix3d reference(const Eigen::Matrix3d& A) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU();
  if ((U * svd.matrixV().transpose()).determinant() < 0) U.col(2) = -U.col(2);
  return U * svd.matrixV().transpose();
}

TEST(NearestRotation, MatchesTheSvdAndIsProper) {
  std::srand(3);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Matrix3d A = Eigen::Matrix3d::Random();
    const Eigen::Matrix3d R = detail::nearest_rotation(A);
    EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
    EXPECT_LT((R - reference(A)).norm(), 1e-9) << A;
  }
}

// A rotation times a symmetric positive stretch gives the rotation back; a mirror gives a proper
// rotation; rank 1 (all edges parallel) falls back to the SVD.
TEST(NearestRotation, PolarFactorMirrorAndRankOne) {
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  const Eigen::Matrix3d S = Eigen::Vector3d(2.0, 0.7, 1.3).asDiagonal();
  EXPECT_LT((detail::nearest_rotation(Q * S) - Q).norm(), 1e-12);
  const Eigen::Matrix3d mirror = Eigen::Vector3d(1.0, 1.0, -1.0).asDiagonal();
  EXPECT_NEAR(detail::nearest_rotation(mirror).determinant(), 1.0, 1e-12);
  const Eigen::Matrix3d rank_one = Eigen::Vector3d(1, 2, 0) * Eigen::RowVector3d(0, 1, 1);
  const Eigen::Matrix3d R = detail::nearest_rotation(rank_one);
  EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
}

// An ill-conditioned symmetric positive definite matrix (an ARAP cluster's rest covariance on a
// mesh of slivers, eigenvalues 2.7e3, 4.4e4, 3.1e9) is its own symmetric factor: its nearest
// rotation is the identity, and Q times it gives Q (the closed form on A^T A alone was off by up
// to 70 degrees).
TEST(NearestRotation, IllConditionedStretch) {
  std::srand(7);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Matrix3d frame =
        Eigen::Quaterniond(Eigen::Vector4d::Random().normalized()).toRotationMatrix();
    const Eigen::Vector3d spread(2.7e3, 4.4e4, 3.1e9);
    const Eigen::Matrix3d S = frame * spread.asDiagonal() * frame.transpose();
    EXPECT_LT((detail::nearest_rotation(S) - Eigen::Matrix3d::Identity()).norm(), 1e-10) << S;
    const Eigen::Matrix3d Q =
        Eigen::AngleAxisd(0.3 * trial, Eigen::Vector3d::Random().normalized()).matrix();
    EXPECT_LT((detail::nearest_rotation(Q * S) - Q).norm(), 1e-10);
  }
}

}  // namespace
}  // namespace specdeform
