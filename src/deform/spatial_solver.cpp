#include "specdeform/deform/spatial_solver.h"

#include <Eigen/CholmodSupport>

#include "membrane_stiffness.h"
#include "specdeform/deform/selection.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/mesh_info.h"
#include "specdeform/operators/laplacian.h"

namespace specdeform {

struct SpatialSolver::Factor {
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
};

SpatialSolver::SpatialSolver(const TriangleMesh& mesh, const DeformOptions& options)
    : options_(options), factor_(std::make_unique<Factor>()) {
  const LaplacianOperators L = laplacian_operators(mesh, MassType::Lumped, LaplacianType::Cotan);
  const Eigen::SparseMatrix<double>& K = L.stiffness;
  const Eigen::VectorXd mass = L.mass.diagonal();
  check_operators(K, L.mass, "spatial solver");
  const double area = mass.sum();
  int pieces = 0;
  const Eigen::VectorXi components = vertex_components(mesh, &pieces);
  vertex_area_ = piece_area_fractions(mass, components, pieces);
  const bool arap = options.energy == DeformEnergy::Arap;
  const double ks = arap ? 1.0 : options.ks, kb = arap ? options.arap.bending : options.kb;
  const Eigen::SparseMatrix<double> Dinv_K = mass.cwiseInverse().asDiagonal() * K;
  A_ = ks * (arap ? detail::membrane_stiffness(K) : K) +
       (kb * area) * Eigen::SparseMatrix<double>(K * Dinv_K);
  A_.makeCompressed();
}

SpatialSolver::~SpatialSolver() = default;
SpatialSolver::SpatialSolver(SpatialSolver&&) noexcept = default;
SpatialSolver& SpatialSolver::operator=(SpatialSolver&&) noexcept = default;

void SpatialSolver::set_constraints(const std::vector<int>& vertices) {
  const int n = static_cast<int>(A_.rows());
  constrained_ = vertices;
  Eigen::SparseMatrix<double> S;
  if (options_.constraints == ConstraintMode::Soft) {
    Eigen::VectorXd w = Eigen::VectorXd::Zero(n);
    for (const int v : vertices) w[v] = options_.constraint_weight * vertex_area_[v];
    S = A_;
    S.diagonal() += w;
  } else {
    std::vector<int> position(n, -1);
    for (size_t i = 0; i < vertices.size(); ++i) position[vertices[i]] = -2 - static_cast<int>(i);
    free_.clear();
    for (int v = 0; v < n; ++v) {
      if (position[v] == -1) {
        position[v] = static_cast<int>(free_.size());
        free_.push_back(v);
      }
    }
    std::vector<Eigen::Triplet<double>> ff, fc;
    for (int col = 0; col < n; ++col) {
      for (Eigen::SparseMatrix<double>::InnerIterator it(A_, col); it; ++it) {
        const int r = position[it.row()], c = position[col];
        if (r < 0) continue;
        if (c >= 0) {
          ff.emplace_back(r, c, it.value());
        } else {
          fc.emplace_back(r, -2 - c, it.value());
        }
      }
    }
    S.resize(static_cast<int>(free_.size()), static_cast<int>(free_.size()));
    S.setFromTriplets(ff.begin(), ff.end());
    coupling_.resize(static_cast<int>(free_.size()), static_cast<int>(vertices.size()));
    coupling_.setFromTriplets(fc.begin(), fc.end());
  }
  factor_->llt.compute(S);
  if (factor_->llt.info() != Eigen::Success) {
    throw SolverError("spatial solver: the constrained system is singular");
  }
}

SpatialSolver::Targets SpatialSolver::prepare(const Eigen::MatrixX3d& targets) const {
  if (targets.rows() != static_cast<Eigen::Index>(constrained_.size())) {
    throw InputError("deformation: targets for " + std::to_string(targets.rows()) +
                     " vertices, the selection has " + std::to_string(constrained_.size()));
  }
  Targets out{targets, 0.0};
  if (options_.constraints == ConstraintMode::Soft) {
    for (size_t i = 0; i < constrained_.size(); ++i) {
      out.constant +=
          options_.constraint_weight * vertex_area_[constrained_[i]] * targets.row(i).squaredNorm();
    }
  }
  return out;
}

Eigen::MatrixX3d SpatialSolver::solve(const Targets& targets, const Eigen::MatrixX3d& g) const {
  const int n = static_cast<int>(A_.rows());
  const Eigen::MatrixX3d& t = targets.values;
  if (options_.constraints == ConstraintMode::Soft) {
    Eigen::MatrixX3d rhs = g.rows() == 0 ? Eigen::MatrixX3d(Eigen::MatrixX3d::Zero(n, 3)) : g;
    for (size_t i = 0; i < constrained_.size(); ++i) {
      const int v = constrained_[i];
      rhs.row(v) += options_.constraint_weight * vertex_area_[v] * t.row(i);
    }
    return factor_->llt.solve(rhs);
  }
  Eigen::MatrixX3d rhs = -(coupling_ * t);
  if (g.rows() != 0) {
    for (size_t i = 0; i < free_.size(); ++i) rhs.row(i) += g.row(free_[i]);
  }
  const Eigen::MatrixX3d free = factor_->llt.solve(rhs);
  Eigen::MatrixX3d d(n, 3);
  for (size_t i = 0; i < free_.size(); ++i) d.row(free_[i]) = free.row(i);
  for (size_t i = 0; i < constrained_.size(); ++i) d.row(constrained_[i]) = t.row(i);
  return d;
}

double SpatialSolver::energy(const Targets& targets, const Eigen::MatrixX3d& d,
                             const Eigen::MatrixX3d& g, Eigen::MatrixX3d* gradient) const {
  const Eigen::MatrixX3d Ad = A_ * d;
  double e = (d.array() * Ad.array()).sum();
  if (gradient != nullptr) {
    *gradient = Ad;
    if (g.rows() != 0) *gradient -= g;
  }
  if (options_.constraints == ConstraintMode::Soft) {
    for (size_t i = 0; i < constrained_.size(); ++i) {
      const int v = constrained_[i];
      const double w = options_.constraint_weight * vertex_area_[v];
      const Eigen::RowVector3d miss = d.row(v) - targets.values.row(i);
      e += w * miss.squaredNorm();
      if (gradient != nullptr) gradient->row(v) += w * miss;
    }
  }
  return e;
}

Eigen::MatrixX3d SpatialSolver::precondition(const Eigen::MatrixX3d& v) const {
  if (options_.constraints == ConstraintMode::Soft) return factor_->llt.solve(v);
  Eigen::MatrixX3d free(free_.size(), 3);
  for (size_t i = 0; i < free_.size(); ++i) free.row(i) = v.row(free_[i]);
  free = factor_->llt.solve(free);
  Eigen::MatrixX3d out = Eigen::MatrixX3d::Zero(v.rows(), 3);
  for (size_t i = 0; i < free_.size(); ++i) out.row(free_[i]) = free.row(i);
  return out;
}

}  // namespace specdeform
