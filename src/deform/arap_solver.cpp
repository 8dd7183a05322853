#include "specdeform/deform/arap_solver.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/SVD>

#include "specdeform/exceptions.h"
#include "specdeform/mesh/vertex_clusters.h"
#include "specdeform/operators/cotan_laplacian.h"

namespace specdeform {

namespace {

using Sparse = Eigen::SparseMatrix<double>;

// The rotation R maximising tr(R S), reflections excluded; returns tr(R S).
double fit_rotation(const Eigen::Matrix3d& S, Eigen::Matrix3d& R) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(S, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d V = svd.matrixV();
  Eigen::Vector3d sigma = svd.singularValues();
  if ((V * svd.matrixU().transpose()).determinant() < 0) {
    V.col(2) = -V.col(2);
    sigma[2] = -sigma[2];
  }
  R = V * svd.matrixU().transpose();
  return sigma.sum();
}

// An iterate of the local/global loop: x (m x 3 or n x 3), the local step's rotations as the
// blocks R_k^T - I (3k x 3), and the energy E(x, R).
struct Iterate {
  Eigen::MatrixX3d x, rotations;
  double energy = 0.0;
};

// The local/global iterations with Anderson acceleration over a space that provides
// covariance(x) (S, 3k x 3), global(rotations) (the global step's minimiser) and energy(x) (the
// quadratic and constraint part of E).
template <typename Space>
Eigen::MatrixX3d iterate(const Space& space, const Eigen::MatrixX3d& start, double scale,
                         const ArapOptions& options, ArapReport* report) {
  const auto local = [&](Eigen::MatrixX3d x) {
    Iterate it;
    it.x = std::move(x);
    const Eigen::MatrixX3d S = space.covariance(it.x);
    it.rotations.resize(S.rows(), 3);
    double arap = 0.0;  // -sum_k (tr(R_k S_k) - tr(S_k)): E's rotation-dependent part
    Eigen::Matrix3d R;
    for (Eigen::Index k = 0; k < S.rows(); k += 3) {
      const Eigen::Matrix3d Sk = S.middleRows<3>(k);
      arap -= fit_rotation(Sk, R) - Sk.trace();
      it.rotations.middleRows<3>(k) = R.transpose() - Eigen::Matrix3d::Identity();
    }
    it.energy = space.energy(it.x) + arap;
    return it;
  };
  // Anderson mixing of the last pairs (G(u_j), G(u_j) - u_j), flattened.
  std::deque<std::pair<Eigen::VectorXd, Eigen::VectorXd>> history;
  const auto mix = [&]() {
    const Eigen::Index p = static_cast<Eigen::Index>(history.size()) - 1;
    const Eigen::Index size = history.back().first.size();
    Eigen::MatrixXd dF(size, p), dG(size, p);
    for (Eigen::Index j = 0; j < p; ++j) {
      dF.col(j) = history[j + 1].second - history[j].second;
      dG.col(j) = history[j + 1].first - history[j].first;
    }
    Eigen::MatrixXd normal = dF.transpose() * dF;
    normal.diagonal().array() += 1e-12 * normal.trace() + 1e-300;
    const Eigen::VectorXd theta = normal.ldlt().solve(dF.transpose() * history.back().second);
    const Eigen::VectorXd u = history.back().first - dG * theta;
    return Eigen::MatrixX3d(Eigen::Map<const Eigen::MatrixX3d>(u.data(), start.rows(), 3));
  };

  ArapReport r;
  Iterate current = local(start);
  const double floor = 1e-14 * std::max(current.energy, scale);
  while (r.iterations < options.max_iterations) {
    ++r.iterations;
    const Eigen::MatrixX3d g = space.global(current.rotations);
    if (options.anderson_window > 0) {
      Eigen::VectorXd flat = Eigen::Map<const Eigen::VectorXd>(g.data(), g.size());
      Eigen::VectorXd residual =
          flat - Eigen::Map<const Eigen::VectorXd>(current.x.data(), current.x.size());
      history.emplace_back(std::move(flat), std::move(residual));
      if (static_cast<int>(history.size()) > options.anderson_window + 1) history.pop_front();
    }
    Iterate next;
    bool accelerated = false;
    if (history.size() >= 2) {
      next = local(mix());
      accelerated = next.energy < current.energy;
    }
    if (accelerated) {
      ++r.accelerated;
    } else {
      next = local(g);
      while (history.size() > 1) history.pop_front();
    }
    r.relative_change = (current.energy - next.energy) / std::max(next.energy, floor);
    current = std::move(next);
    if (current.energy <= floor || r.relative_change <= options.tolerance) {
      r.converged = true;
      break;
    }
  }
  r.energy = current.energy;
  if (report != nullptr) *report = r;
  return current.x;
}

// The cluster operator over all vertices, 3k x n: column j holds, for the cluster of j,
// sum_{i ~ j} w_ji (s_j - s_i), and for the cluster of each neighbour i, -w_ij (s_i - s_j).
Sparse cluster_operator(const Sparse& K, const Vertices& s, const Eigen::VectorXi& label,
                        int clusters) {
  const int n = static_cast<int>(K.cols());
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(6 * static_cast<size_t>(n));
  std::vector<std::pair<int, Eigen::Vector3d>> column;  // (cluster, entry) of one column
  const auto add = [&](int cluster, const Eigen::Vector3d& v) {
    for (auto& [k, value] : column) {
      if (k == cluster) {
        value += v;
        return;
      }
    }
    column.emplace_back(cluster, v);
  };
  for (int j = 0; j < n; ++j) {  // K is symmetric: column j lists j's neighbours i
    column.clear();
    for (Sparse::InnerIterator it(K, j); it; ++it) {
      const int i = static_cast<int>(it.row());
      if (i == j) continue;
      const Eigen::Vector3d e = -it.value() * (s.row(j) - s.row(i)).transpose();  // w_ji e_ji
      add(label[j], e);
      add(label[i], e);  // -w_ij e_ij of the half-edge (i, j)
    }
    for (const auto& [k, value] : column)
      for (int d = 0; d < 3; ++d) entries.emplace_back(3 * k + d, j, value[d]);
  }
  Sparse A(3 * clusters, n);
  A.setFromTriplets(entries.begin(), entries.end());
  return A;
}

}  // namespace

ArapSolver::ArapSolver(const TriangleMesh& mesh, const Vertices& base,
                       std::shared_ptr<const ManifoldHarmonics> basis, const ArapOptions& options)
    : options_(options) {
  if (base.rows() != mesh.num_vertices()) {
    throw InputError("ARAP: the base has " + std::to_string(base.rows()) + " vertices, the mesh " +
                     std::to_string(mesh.num_vertices()));
  }
  const VertexClusters clusters = vertex_clusters(TriangleMesh{base, mesh.F}, options.clusters);
  label_ = clusters.label;
  const Sparse A = cluster_operator(cotan_stiffness(mesh), base, label_, clusters.count);
  rest_ = A * base;
  // The mean over each cluster's vertices (k x n), applied to the basis when there is one.
  Eigen::VectorXd size = Eigen::VectorXd::Zero(clusters.count);
  for (int i = 0; i < label_.size(); ++i) size[label_[i]] += 1.0;
  std::vector<Eigen::Triplet<double>> mean;
  for (int i = 0; i < label_.size(); ++i) mean.emplace_back(label_[i], i, 1.0 / size[label_[i]]);
  Sparse cluster_mean(clusters.count, mesh.num_vertices());
  cluster_mean.setFromTriplets(mean.begin(), mean.end());
  if (basis) {
    reduced_ = A * basis->basis;
    reduced_mean_ = cluster_mean * basis->basis;
  } else {
    operator_ = A;
    mean_ = cluster_mean;
  }
}

namespace {

// The scale of the energies: the Dirichlet energy of the base, sum_k tr S_k(s).
double energy_scale(const Eigen::MatrixX3d& rest) {
  double sum = 0.0;
  for (Eigen::Index k = 0; k < rest.rows(); k += 3) sum += rest.middleRows<3>(k).trace();
  return std::abs(sum);
}

// The rotation vector (axis times angle) of the rotation nearest to `linear` (its polar part).
Eigen::Vector3d rotation_vector(const Eigen::Matrix3d& linear) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(linear, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU();
  if ((U * svd.matrixV().transpose()).determinant() < 0) U.col(2) = -U.col(2);
  const Eigen::AngleAxisd rotation(Eigen::Matrix3d(U * svd.matrixV().transpose()));
  return rotation.angle() * rotation.axis();
}

// The cold start: each group's rotation spread over the clusters by harmonic weights, then the
// global step with those rotations.
template <typename Space>
Eigen::MatrixX3d propagated_start(const Space& space, const ConstrainedSet& set,
                                  const std::vector<Eigen::Affine3d>& transforms, int clusters) {
  std::vector<Eigen::Vector3d> turn(set.num_groups);
  for (int g = 0; g < set.num_groups; ++g) turn[g] = rotation_vector(transforms[g].linear());
  Eigen::MatrixX3d blended = Eigen::MatrixX3d::Zero(clusters, 3);
  for (int first = 0; first < set.num_groups; first += 3) {  // three groups per solve
    bool turned = false;
    Eigen::MatrixX3d indicator = Eigen::MatrixX3d::Zero(set.vertices.size(), 3);
    for (size_t i = 0; i < set.vertices.size(); ++i) {
      const int column = set.group[i] - first;
      if (column < 0 || column >= 3 || turn[set.group[i]].isZero(0.0)) continue;
      indicator(i, column) = 1.0;
      turned = true;
    }
    if (!turned) continue;
    const Eigen::MatrixX3d weights = space.cluster_means(space.harmonic(indicator));
    for (int k = 0; k < clusters; ++k)
      for (int j = 0; j < 3 && first + j < set.num_groups; ++j)
        blended.row(k) += std::clamp(weights(k, j), 0.0, 1.0) * turn[first + j].transpose();
  }
  Eigen::MatrixX3d rotations(3 * clusters, 3);
  for (int k = 0; k < clusters; ++k) {
    const Eigen::Vector3d w = blended.row(k).transpose();
    const double angle = w.norm();
    const Eigen::Matrix3d R = angle > 0.0 ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix()
                                          : Eigen::Matrix3d::Identity();
    rotations.middleRows<3>(3 * k) = R.transpose() - Eigen::Matrix3d::Identity();
  }
  return space.global(rotations);
}

}  // namespace

// The spaces the local/global iterations run in: covariance(x), global(rotations), energy(x),
// and for the cold start harmonic(indicator) (the global step's system for constrained values)
// and cluster_means(x).
struct ArapSolver::ReducedSpace {
  const ArapSolver& self;
  const ReducedSolver& solver;
  const ReducedSolver::Targets& targets;
  Eigen::MatrixX3d covariance(const Eigen::MatrixX3d& c) const {
    return self.rest_ + self.reduced_.lazyProduct(c);
  }
  Eigen::MatrixX3d global(const Eigen::MatrixX3d& rotations) const {
    return solver.solve(targets, 0.5 * self.reduced_.transpose().lazyProduct(rotations));
  }
  double energy(const Eigen::MatrixX3d& c) const { return solver.energy(targets, c); }
  Eigen::MatrixX3d harmonic(const Eigen::MatrixX3d& values) const { return solver.solve(values); }
  Eigen::MatrixX3d cluster_means(const Eigen::MatrixX3d& c) const {
    return self.reduced_mean_.lazyProduct(c);
  }
};

struct ArapSolver::SpatialSpace {
  const ArapSolver& self;
  const SpatialSolver& solver;
  const SpatialSolver::Targets& targets;
  Eigen::MatrixX3d covariance(const Eigen::MatrixX3d& d) const {
    return self.rest_ + self.operator_ * d;
  }
  Eigen::MatrixX3d global(const Eigen::MatrixX3d& rotations) const {
    return solver.solve(targets, 0.5 * (self.operator_.transpose() * rotations));
  }
  double energy(const Eigen::MatrixX3d& d) const { return solver.energy(targets, d); }
  Eigen::MatrixX3d harmonic(const Eigen::MatrixX3d& values) const { return solver.solve(values); }
  Eigen::MatrixX3d cluster_means(const Eigen::MatrixX3d& d) const { return self.mean_ * d; }
};

Eigen::MatrixX3d ArapSolver::start(const ReducedSolver& solver,
                                   const ReducedSolver::Targets& targets, const ConstrainedSet& set,
                                   const std::vector<Eigen::Affine3d>& transforms) const {
  if (reduced_.cols() == 0) throw InputError("ARAP: built without a basis");
  return propagated_start(ReducedSpace{*this, solver, targets}, set, transforms, clusters());
}

Eigen::MatrixX3d ArapSolver::start(const SpatialSolver& solver,
                                   const SpatialSolver::Targets& targets, const ConstrainedSet& set,
                                   const std::vector<Eigen::Affine3d>& transforms) const {
  if (operator_.cols() == 0) throw InputError("ARAP: built with a basis");
  return propagated_start(SpatialSpace{*this, solver, targets}, set, transforms, clusters());
}

Eigen::MatrixX3d ArapSolver::solve(const ReducedSolver& solver,
                                   const ReducedSolver::Targets& targets,
                                   const Eigen::MatrixX3d& start, ArapReport* report) const {
  if (reduced_.cols() == 0) throw InputError("ARAP: built without a basis");
  return iterate(ReducedSpace{*this, solver, targets}, start, energy_scale(rest_), options_,
                 report);
}

Eigen::MatrixX3d ArapSolver::solve(const SpatialSolver& solver,
                                   const SpatialSolver::Targets& targets,
                                   const Eigen::MatrixX3d& start, ArapReport* report) const {
  if (operator_.cols() == 0) throw InputError("ARAP: built with a basis");
  return iterate(SpatialSpace{*this, solver, targets}, start, energy_scale(rest_), options_,
                 report);
}

}  // namespace specdeform
