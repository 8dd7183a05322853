#include "pose.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include "specdeform/exceptions.h"
#include "specdeform/operators/laplacian.h"

namespace specdeform::server {

FittedTransform fit_transform(const Vertices& rest, const Vertices& current,
                              const std::vector<int>& vertices) {
  if (vertices.empty()) throw InputError("pin: no vertices");
  Eigen::MatrixX3d X(vertices.size(), 3), Y(vertices.size(), 3);
  for (size_t i = 0; i < vertices.size(); ++i) {
    X.row(static_cast<Eigen::Index>(i)) = rest.row(vertices[i]);
    Y.row(static_cast<Eigen::Index>(i)) = current.row(vertices[i]);
  }
  const Eigen::RowVector3d cx = X.colwise().mean(), cy = Y.colwise().mean();
  X.rowwise() -= cx;
  Y.rowwise() -= cy;
  const Eigen::Matrix3d XX = X.transpose() * X, XY = X.transpose() * Y;
  // The rotation of Kabsch's fit (reflections excluded), then the affine fit regularised
  // towards it: (XX + e I) A^T = XY + e R^T.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(XY, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1 : 1;
  const Eigen::Matrix3d R = svd.matrixV() * D * svd.matrixU().transpose();
  const double e = 1e-6 * XX.trace() + 1e-300;
  const Eigen::Matrix3d At =
      (XX + e * Eigen::Matrix3d::Identity()).ldlt().solve(XY + e * R.transpose());
  FittedTransform out;
  out.transform.linear() = At.transpose();
  out.transform.translation() = cy.transpose() - At.transpose() * cx.transpose();
  out.transform.makeAffine();
  if (!(std::abs(out.transform.linear().determinant()) > 1e-12)) {  // degenerate: the rotation
    out.transform.linear() = R;
    out.transform.translation() = cy.transpose() - R * cx.transpose();
  }
  for (int v : vertices) {
    const Eigen::Vector3d p = out.transform * Eigen::Vector3d(rest.row(v).transpose());
    out.max_error = std::max(out.max_error, (p - current.row(v).transpose()).norm());
  }
  return out;
}

ManifoldHarmonics reuse_basis(const TriangleMesh& mesh, const ManifoldHarmonics& basis) {
  const LaplacianOperators L = laplacian_operators(mesh, basis.mass, basis.laplacian);
  const Eigen::SparseMatrix<double>&K = L.stiffness, &M = L.mass;
  const Eigen::MatrixXd& H = basis.basis;
  const Eigen::MatrixXd A = H.transpose() * (K * H), B = H.transpose() * (M * H);
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (A + A.transpose()),
                                                                      0.5 * (B + B.transpose()));
  if (eig.info() != Eigen::Success) throw SolverError("apply pose: Rayleigh-Ritz failed");
  ManifoldHarmonics out;
  out.mass = basis.mass;
  out.laplacian = basis.laplacian;
  out.eigenvalues = eig.eigenvalues().cwiseMax(0.0);
  out.basis = H * eig.eigenvectors();
  out.max_residual = eigen_residual(K, M, out.basis, out.eigenvalues);
  out.status = SolveStatus::NotConverged;
  return out;
}

}  // namespace specdeform::server
