#include "specdeform/deform/reduced_solver.h"

#include <string>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "specdeform/exceptions.h"

namespace specdeform {

ReducedSolver::ReducedSolver(const Eigen::MatrixXd& basis, const Eigen::VectorXd& eigenvalues,
                             const Eigen::VectorXd& vertex_area, double area,
                             const DeformOptions& options)
    : basis_(basis), vertex_area_(vertex_area / area), options_(options) {
  const Eigen::ArrayXd lambda = eigenvalues.array().max(0.0);  // -1e-14 is 0
  hessian_ = (options.ks * lambda + options.kb * area * lambda.square()).matrix();
}

void ReducedSolver::set_constraints(const std::vector<int>& vertices) {
  const int m = static_cast<int>(basis_.cols());
  const int nc = static_cast<int>(vertices.size());
  rows_.resize(nc, m);
  for (int i = 0; i < nc; ++i) rows_.row(i) = basis_.row(vertices[i]);
  if (options_.constraints == ConstraintMode::Soft) {
    Eigen::VectorXd w(nc);
    for (int i = 0; i < nc; ++i) w[i] = options_.constraint_weight * vertex_area_[vertices[i]];
    weighted_columns_ = (w.asDiagonal() * rows_).transpose();
    // Update the normal matrix by the vertices that changed, or rebuild it when many did.
    std::vector<char> next(basis_.rows(), 0);
    for (const int v : vertices) next[v] = 1;
    std::vector<int> added, removed;
    if (!constrained_.empty()) {
      for (int v = 0; v < static_cast<int>(basis_.rows()); ++v) {
        if (next[v] && !constrained_[v]) added.push_back(v);
        if (!next[v] && constrained_[v]) removed.push_back(v);
      }
    }
    if (constrained_.empty() || 2 * (added.size() + removed.size()) > vertices.size()) {
      normal_ = weighted_columns_ * rows_;
      normal_.diagonal() += hessian_;
    } else {
      const auto update = [&](const std::vector<int>& changed, double sign) {
        Eigen::MatrixXd H(changed.size(), m);
        Eigen::VectorXd weight(changed.size());
        for (size_t i = 0; i < changed.size(); ++i) {
          H.row(i) = basis_.row(changed[i]);
          weight[i] = sign * options_.constraint_weight * vertex_area_[changed[i]];
        }
        normal_.noalias() += H.transpose() * weight.asDiagonal() * H;
      };
      update(added, 1.0);
      update(removed, -1.0);
    }
    constrained_ = std::move(next);
    soft_.compute(normal_);
    if (soft_.info() != Eigen::Success) {
      throw SolverError(
          "the reduced system is singular: the constraints do not pin every "
          "zero-energy mode");
    }
    return;
  }
  if (nc > m) {
    throw InputError("hard constraints: " + std::to_string(nc) + " constrained vertices but only " +
                     std::to_string(m) +
                     " modes; use soft constraints, fewer constrained vertices or more modes");
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(rows_.transpose());  // H_C^T = Q R P^T
  qr.setThreshold(1e-10);
  if (qr.rank() < nc) {
    throw InputError("hard constraints: the basis can meet only " + std::to_string(qr.rank()) +
                     " of the " + std::to_string(nc) +
                     " constraints independently; use soft constraints or more modes");
  }
  const Eigen::MatrixXd Q = qr.householderQ();
  const Eigen::MatrixXd Q1 = Q.leftCols(nc), Q2 = Q.rightCols(m - nc);
  // Particular solution c0 = Q1 y with H_C Q1 y = t: (R P^T)^T y = t.
  const Eigen::MatrixXd R = qr.matrixR().topLeftCorner(nc, nc).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd RPt = R * qr.colsPermutation().transpose();
  const Eigen::MatrixXd particular = Q1 * RPt.transpose().inverse();  // m x n'
  if (m == nc) {
    hard_ = particular;
    return;
  }
  const Eigen::MatrixXd DQ2 = hessian_.asDiagonal() * Q2;
  const Eigen::LDLT<Eigen::MatrixXd> reduced(Q2.transpose() * DQ2);
  if (reduced.info() != Eigen::Success || !reduced.isPositive()) {
    throw SolverError("hard constraints: the energy does not determine the free modes");
  }
  hard_ = particular - Q2 * reduced.solve(DQ2.transpose() * particular);
}

Eigen::MatrixX3d ReducedSolver::solve(const Eigen::MatrixX3d& targets) const {
  if (targets.rows() != rows_.rows()) {
    throw InputError("deformation: targets for " + std::to_string(targets.rows()) +
                     " vertices, the selection has " + std::to_string(rows_.rows()));
  }
  // Outer products and vector solves: no BLAS call, whose worker threads would spin on the
  // second core while the rest of the frame needs it. Vertices that keep their place (the
  // fixed ones, typically most) add nothing to the right-hand side.
  if (options_.constraints == ConstraintMode::Soft) {
    Eigen::MatrixX3d c = Eigen::MatrixX3d::Zero(weighted_columns_.rows(), 3);
    for (Eigen::Index i = 0; i < targets.rows(); ++i) {
      if (!targets.row(i).isZero(0.0)) c.noalias() += weighted_columns_.col(i) * targets.row(i);
    }
    for (int d = 0; d < 3; ++d) c.col(d) = soft_.solve(c.col(d));
    return c;
  }
  return hard_.lazyProduct(targets);
}

}  // namespace specdeform
