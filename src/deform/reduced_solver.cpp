#include "specdeform/deform/reduced_solver.h"

#include <string>

#include <Eigen/LU>
#include <Eigen/QR>

#include "linalg/basis_product.h"
#include "specdeform/exceptions.h"

namespace specdeform {

ReducedSolver::ReducedSolver(std::shared_ptr<const ManifoldHarmonics> basis,
                             Eigen::MatrixXd hessian, Eigen::VectorXd vertex_area,
                             const DeformOptions& options)
    : basis_(std::move(basis)),
      hessian_(std::move(hessian)),
      vertex_area_(std::move(vertex_area)),
      options_(options) {}

void ReducedSolver::set_constraints(const std::vector<int>& vertices) {
  const Eigen::MatrixXd& H = basis_->basis;
  const int m = static_cast<int>(H.cols());
  const int nc = static_cast<int>(vertices.size());
  // H_C^T: columns of the previous selection are copied (contiguous), only new vertices'
  // rows are gathered from the basis.
  Eigen::MatrixXd columns(m, nc);
  for (int i = 0; i < nc; ++i) {
    const int v = vertices[i];
    if (column_of_.empty() || column_of_[v] < 0) {
      columns.col(i) = H.row(v).transpose();
    } else {
      columns.col(i) = columns_.col(column_of_[v]);
    }
  }
  std::vector<int> added, removed;
  std::vector<int> column_of(H.rows(), -1);
  for (int i = 0; i < nc; ++i) column_of[vertices[i]] = i;
  if (!column_of_.empty()) {
    for (int v = 0; v < static_cast<int>(H.rows()); ++v) {
      if (column_of[v] >= 0 && column_of_[v] < 0) added.push_back(v);
      if (column_of[v] < 0 && column_of_[v] >= 0) removed.push_back(v);
    }
  }
  const bool rebuild = column_of_.empty() || 2 * (added.size() + removed.size()) > vertices.size();
  column_of_ = std::move(column_of);
  columns_ = std::move(columns);
  vertex_ = vertices;
  moments_.clear();
  group_.clear();
  weights_.resize(nc);
  for (int i = 0; i < nc; ++i) weights_[i] = weight(vertices[i]);
  if (options_.constraints == ConstraintMode::Soft) {
    // Update the normal matrix by the vertices that changed, or rebuild it when many did.
    if (rebuild) {
      normal_ = columns_ * weights_.asDiagonal() * columns_.transpose();
      normal_ += hessian_;
    } else {
      const auto update = [&](const std::vector<int>& changed, double sign) {
        Eigen::MatrixXd rows(changed.size(), m);
        Eigen::VectorXd w(changed.size());
        for (size_t i = 0; i < changed.size(); ++i) {
          rows.row(i) = H.row(changed[i]);
          w[i] = sign * weight(changed[i]);
        }
        normal_.noalias() += rows.transpose() * w.asDiagonal() * rows;
      };
      update(added, 1.0);
      update(removed, -1.0);
    }
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
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(columns_);  // H_C^T = Q R P^T
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
    hard_free_ = Eigen::MatrixXd::Zero(m, m);
    return;
  }
  const Eigen::MatrixXd DQ2 = hessian_ * Q2;
  const Eigen::LDLT<Eigen::MatrixXd> reduced(Q2.transpose() * DQ2);
  if (reduced.info() != Eigen::Success || !reduced.isPositive()) {
    throw SolverError("hard constraints: the energy does not determine the free modes");
  }
  hard_ = particular - Q2 * reduced.solve(DQ2.transpose() * particular);
  hard_free_ = Q2 * reduced.solve(Q2.transpose());
}

ReducedSolver::Targets ReducedSolver::prepare(const Eigen::MatrixX3d& targets) const {
  if (targets.rows() != columns_.cols()) {
    throw InputError("deformation: targets for " + std::to_string(targets.rows()) +
                     " vertices, the selection has " + std::to_string(columns_.cols()));
  }
  Targets out;
  if (options_.constraints == ConstraintMode::Hard) {
    out.rhs = hard_.lazyProduct(targets);
    return out;
  }
  // Outer products: no BLAS call, whose worker threads would spin on the second core while the
  // rest of the frame needs it. Vertices that keep their place (the fixed ones, typically most)
  // add nothing.
  out.rhs = Eigen::MatrixX3d::Zero(columns_.rows(), 3);
  for (Eigen::Index i = 0; i < targets.rows(); ++i) {
    if (!targets.row(i).isZero(0.0)) {
      out.rhs.noalias() += columns_.col(i) * (weights_[i] * targets.row(i));
      out.constant += weights_[i] * targets.row(i).squaredNorm();
    }
  }
  return out;
}

void ReducedSolver::set_groups(const std::vector<int>& group, int num_groups,
                               const Eigen::MatrixX3d& positions) {
  const Eigen::Index nc = columns_.cols(), m = columns_.rows();
  if (static_cast<Eigen::Index>(group.size()) != nc) {
    throw InputError("deformation: groups for " + std::to_string(group.size()) +
                     " vertices, the selection has " + std::to_string(nc));
  }
  group_ = group;
  rest_.resize(nc, 3);
  for (Eigen::Index i = 0; i < nc; ++i) rest_.row(i) = positions.row(vertex_[i]);
  moments_.assign(num_groups, Moments{});
  for (Moments& g : moments_) {
    g.h0 = Eigen::VectorXd::Zero(m);
    g.h1 = Eigen::MatrixX3d::Zero(m, 3);
  }
  for (Eigen::Index i = 0; i < nc; ++i) {
    if (group[i] < 0) continue;
    Moments& g = moments_.at(group[i]);
    g.weight += weights_[i];
    g.centroid += weights_[i] * rest_.row(i).transpose();
  }
  for (Moments& g : moments_)
    if (g.weight > 0.0) g.centroid /= g.weight;
  for (Eigen::Index i = 0; i < nc; ++i) {
    if (group[i] < 0) continue;
    Moments& g = moments_[group[i]];
    const Eigen::Vector3d r = rest_.row(i).transpose() - g.centroid;
    g.spread += weights_[i] * r * r.transpose();
    g.h0 += weights_[i] * columns_.col(i);
    g.h1.noalias() += columns_.col(i) * (weights_[i] * r.transpose());
  }
}

ReducedSolver::Targets ReducedSolver::prepare(
    const std::vector<Eigen::Affine3d>& transforms) const {
  if (group_.size() != static_cast<size_t>(columns_.cols())) {
    throw InputError("deformation: the handle groups of the selection are not set");
  }
  if (transforms.size() != moments_.size()) {
    throw InputError("deformation: " + std::to_string(transforms.size()) + " transforms for " +
                     std::to_string(moments_.size()) + " handle groups");
  }
  if (options_.constraints == ConstraintMode::Hard) {  // n' <= m: per vertex
    Eigen::MatrixX3d targets = Eigen::MatrixX3d::Zero(rest_.rows(), 3);
    for (Eigen::Index i = 0; i < rest_.rows(); ++i) {
      if (group_[i] >= 0) {
        const Eigen::Vector3d s = rest_.row(i).transpose();
        targets.row(i) = (transforms[group_[i]] * s - s).transpose();
      }
    }
    return prepare(targets);
  }
  Targets out;
  out.rhs = Eigen::MatrixX3d::Zero(columns_.rows(), 3);
  for (size_t k = 0; k < moments_.size(); ++k) {
    const Moments& g = moments_[k];
    const Eigen::Matrix3d B = transforms[k].linear() - Eigen::Matrix3d::Identity();
    const Eigen::Vector3d u = transforms[k] * g.centroid - g.centroid;
    out.rhs.noalias() += g.h1 * B.transpose();
    out.rhs.noalias() += g.h0 * u.transpose();
    out.constant += (B * g.spread * B.transpose()).trace() + g.weight * u.squaredNorm();
  }
  return out;
}

Eigen::MatrixX3d ReducedSolver::solve(const Targets& targets, const Eigen::MatrixX3d& g) const {
  if (options_.constraints == ConstraintMode::Hard) {
    if (g.rows() == 0) return targets.rhs;
    return targets.rhs + hard_free_.lazyProduct(g);
  }
  Eigen::MatrixX3d c = g.rows() == 0 ? targets.rhs : Eigen::MatrixX3d(targets.rhs + g);
  for (int d = 0; d < 3; ++d) c.col(d) = soft_.solve(c.col(d));
  return c;
}

double ReducedSolver::energy(const Targets& targets, const Eigen::MatrixX3d& c,
                             const Eigen::MatrixX3d& g, Eigen::MatrixX3d* gradient) const {
  const bool hard = options_.constraints == ConstraintMode::Hard;
  // The Hessian's product Nc (soft: the normal matrix D + w H_C^T W H_C; hard: D).
  Eigen::MatrixX3d Nc;
  if (hard) {
    Nc = hessian_.lazyProduct(c);
  } else {
    detail::add_basis_product(Eigen::MatrixX3d::Zero(c.rows(), 3), normal_, c, Nc);
  }
  if (gradient != nullptr) {
    *gradient = hard ? Nc : Eigen::MatrixX3d(Nc - targets.rhs);
    if (g.rows() != 0) *gradient -= g;
  }
  if (hard) return (c.array() * Nc.array()).sum();
  return (c.array() * (Nc - 2.0 * targets.rhs).array()).sum() + targets.constant;
}

Eigen::MatrixX3d ReducedSolver::precondition(const Eigen::MatrixX3d& v) const {
  if (options_.constraints == ConstraintMode::Hard) return hard_free_.lazyProduct(v);
  Eigen::MatrixX3d out = v;
  for (int d = 0; d < 3; ++d) out.col(d) = soft_.solve(out.col(d));
  return out;
}

}  // namespace specdeform
