#include "linalg/nearest_rotation.h"

#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

namespace specdeform::detail {

namespace {

// The closed form's result is kept where R^T A, symmetric for the exact polar factor, is so to
// this fraction of |A|; beyond it the Jacobi SVD decides.
constexpr double kSymmetryTolerance = 1e-10;

Eigen::Matrix3d by_svd(const Eigen::Matrix3d& A) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU();
  if ((U * svd.matrixV().transpose()).determinant() < 0) U.col(2) = -U.col(2);
  return U * svd.matrixV().transpose();
}

}  // namespace

Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& A) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(A.transpose() * A);  // ascending eigenvalues
  const Eigen::Vector3d v1 = eigen.eigenvectors().col(2);
  const Eigen::Vector3d v2 =
      (eigen.eigenvectors().col(1) - v1.dot(eigen.eigenvectors().col(1)) * v1).normalized();
  const Eigen::Vector3d u1 = (A * v1).normalized();
  Eigen::Vector3d u2 = A * v2;
  u2 -= u1.dot(u2) * u1;
  if (!(u2.norm() > 1e-9 * A.norm()) || !std::isfinite(u2.norm())) return by_svd(A);
  u2.normalize();
  Eigen::Matrix3d U, V;
  U << u1, u2, u1.cross(u2);
  V << v1, v2, v1.cross(v2);
  const Eigen::Matrix3d R = U * V.transpose();
  const Eigen::Matrix3d P = R.transpose() * A;
  return (P - P.transpose()).norm() <= kSymmetryTolerance * A.norm() ? R : by_svd(A);
}

}  // namespace specdeform::detail
