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

// The rotation R maximising tr(R X) over all rotations (reflections excluded).
void fit_rotation(const Eigen::Matrix3d& X, Eigen::Ref<Eigen::Matrix3d> R) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(X, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d V = svd.matrixV();
  if ((V * svd.matrixU().transpose()).determinant() < 0) V.col(2) = -V.col(2);
  R = V * svd.matrixU().transpose();
}

// The rotations' part of the energy and its local step. With the covariances S_k (3k x 3) and
// the cluster graph's weights g_kl (symmetric, zero diagonal),
//     E_R = -sum_k tr((R_k - I) S_k) + sum_{k < l} g_kl |R_k - R_l|_F^2;
// fit() replaces each R_k in turn by its minimiser given the others, R_k = argmax
// tr(R_k (S_k + 2 sum_l g_kl R_l^T)) (one sweep of block coordinate descent, exact without the
// graph), and returns E_R.
struct RotationSmoothness {
  const Sparse& graph;  // k x k
  double fit(const Eigen::MatrixX3d& S, Eigen::MatrixX3d& R) const {
    for (Eigen::Index k = 0; k < S.rows() / 3; ++k) {
      Eigen::Matrix3d X = S.middleRows<3>(3 * k);
      for (Sparse::InnerIterator it(graph, k); it; ++it)
        X += 2.0 * it.value() * R.middleRows<3>(3 * it.row()).transpose();
      fit_rotation(X, R.middleRows<3>(3 * k));
    }
    double energy = 0.0;
    for (Eigen::Index k = 0; k < S.rows() / 3; ++k) {
      const Eigen::Matrix3d Rk = R.middleRows<3>(3 * k);
      energy -= ((Rk - Eigen::Matrix3d::Identity()) * S.middleRows<3>(3 * k)).trace();
      for (Sparse::InnerIterator it(graph, k); it; ++it) {
        if (it.row() > k) energy += it.value() * (Rk - R.middleRows<3>(3 * it.row())).squaredNorm();
      }
    }
    return energy;
  }
};

// An iterate of the local/global loop: x (m x 3 or n x 3), the clusters' rotations R_k (the
// blocks of 3k x 3) and the energy E(x, R).
struct Iterate {
  Eigen::MatrixX3d x, rotations;
  double energy = 0.0;
};

// The blocks R_k^T - I of the global step's right-hand side (3k x 3).
Eigen::MatrixX3d transposed_minus_identity(const Eigen::MatrixX3d& rotations) {
  Eigen::MatrixX3d out(rotations.rows(), 3);
  for (Eigen::Index k = 0; k < rotations.rows(); k += 3)
    out.middleRows<3>(k) = rotations.middleRows<3>(k).transpose() - Eigen::Matrix3d::Identity();
  return out;
}

// The local/global iterations with Anderson acceleration over a space that provides
// covariance(x) (S, 3k x 3), global(R^T - I blocks) (the global step's minimiser) and energy(x)
// (the quadratic and constraint part of E). The local step is a sweep of block coordinate
// descent over the clusters (exact for the plain ARAP term; with the smoothness term each
// cluster sees its neighbours' latest rotations), so no step raises the energy.
template <typename Space>
ArapState iterate(const Space& space, const RotationSmoothness& smoothness, ArapState start,
                  double scale, const ArapOptions& options, ArapReport* report) {
  const auto local = [&](Eigen::MatrixX3d x, Eigen::MatrixX3d R) {
    Iterate it{std::move(x), std::move(R), 0.0};
    const Eigen::MatrixX3d S = space.covariance(it.x);
    it.energy = space.energy(it.x) + smoothness.fit(S, it.rotations);
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
    return Eigen::MatrixX3d(Eigen::Map<const Eigen::MatrixX3d>(u.data(), size / 3, 3));
  };

  ArapReport r;
  Iterate current = local(std::move(start.x), std::move(start.rotations));
  const double floor = 1e-14 * std::max(current.energy, scale);
  while (r.iterations < options.max_iterations) {
    ++r.iterations;
    const Eigen::MatrixX3d g = space.global(transposed_minus_identity(current.rotations));
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
      next = local(mix(), current.rotations);
      accelerated = next.energy < current.energy;
    }
    if (accelerated) {
      ++r.accelerated;
    } else {
      next = local(g, current.rotations);
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
  return {std::move(current.x), std::move(current.rotations)};
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

// The weights g_kl of the rotations' smoothness term: beta times the finite-volume weight of
// the Dirichlet energy on the cluster graph, the length of the boundary between clusters k and
// l (the lengths of the edges that cross it) over the distance between their centroids.
Sparse cluster_graph(const Sparse& K, const Vertices& s, const Eigen::VectorXi& label, int clusters,
                     double beta) {
  Eigen::MatrixX3d centroid = Eigen::MatrixX3d::Zero(clusters, 3);
  Eigen::VectorXd size = Eigen::VectorXd::Zero(clusters);
  for (Eigen::Index i = 0; i < s.rows(); ++i) {
    centroid.row(label[i]) += s.row(i);
    size[label[i]] += 1.0;
  }
  centroid.array().colwise() /= size.array();
  std::vector<Eigen::Triplet<double>> boundary;
  for (int j = 0; j < K.outerSize(); ++j) {
    for (Sparse::InnerIterator it(K, j); it; ++it) {
      const int i = static_cast<int>(it.row());
      if (label[i] != label[j]) {
        boundary.emplace_back(label[i], label[j], (s.row(i) - s.row(j)).norm());
      }
    }
  }
  Sparse length(clusters, clusters);  // each crossing edge twice, once per direction
  length.setFromTriplets(boundary.begin(), boundary.end());
  std::vector<Eigen::Triplet<double>> weights;
  for (int l = 0; l < clusters; ++l) {
    for (Sparse::InnerIterator it(length, l); it; ++it) {
      const double distance = (centroid.row(it.row()) - centroid.row(l)).norm();
      if (beta > 0.0 && distance > 0.0) {
        weights.emplace_back(it.row(), l, 0.5 * beta * it.value() / distance);
      }
    }
  }
  Sparse graph(clusters, clusters);
  graph.setFromTriplets(weights.begin(), weights.end());
  return graph;
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
  const Sparse K = cotan_stiffness(mesh);
  const Sparse A = cluster_operator(K, base, label_, clusters.count);
  rest_ = A * base;
  graph_ = cluster_graph(K, base, label_, clusters.count,
                         options.rotation_smoothness * surface_area(TriangleMesh{base, mesh.F}));
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
ArapState propagated_start(const Space& space, const ConstrainedSet& set,
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
  ArapState start;
  start.rotations.resize(3 * clusters, 3);
  for (int k = 0; k < clusters; ++k) {
    const Eigen::Vector3d w = blended.row(k).transpose();
    const double angle = w.norm();
    start.rotations.middleRows<3>(3 * k) =
        angle > 0.0 ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix()
                    : Eigen::Matrix3d::Identity();
  }
  start.x = space.global(transposed_minus_identity(start.rotations));
  return start;
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

ArapState ArapSolver::start(const ReducedSolver& solver, const ReducedSolver::Targets& targets,
                            const ConstrainedSet& set,
                            const std::vector<Eigen::Affine3d>& transforms) const {
  if (reduced_.cols() == 0) throw InputError("ARAP: built without a basis");
  return propagated_start(ReducedSpace{*this, solver, targets}, set, transforms, clusters());
}

ArapState ArapSolver::start(const SpatialSolver& solver, const SpatialSolver::Targets& targets,
                            const ConstrainedSet& set,
                            const std::vector<Eigen::Affine3d>& transforms) const {
  if (operator_.cols() == 0) throw InputError("ARAP: built with a basis");
  return propagated_start(SpatialSpace{*this, solver, targets}, set, transforms, clusters());
}

ArapState ArapSolver::solve(const ReducedSolver& solver, const ReducedSolver::Targets& targets,
                            ArapState start, ArapReport* report) const {
  if (reduced_.cols() == 0) throw InputError("ARAP: built without a basis");
  return iterate(ReducedSpace{*this, solver, targets}, RotationSmoothness{graph_},
                 checked(std::move(start), reduced_.cols()), energy_scale(rest_), options_, report);
}

ArapState ArapSolver::solve(const SpatialSolver& solver, const SpatialSolver::Targets& targets,
                            ArapState start, ArapReport* report) const {
  if (operator_.cols() == 0) throw InputError("ARAP: built with a basis");
  return iterate(SpatialSpace{*this, solver, targets}, RotationSmoothness{graph_},
                 checked(std::move(start), operator_.cols()), energy_scale(rest_), options_,
                 report);
}

ArapState ArapSolver::checked(ArapState start, Eigen::Index size) const {
  if (start.x.rows() != size) {
    throw InputError("ARAP: a start of " + std::to_string(start.x.rows()) + " rows, " +
                     std::to_string(size) + " expected");
  }
  if (start.rotations.rows() != rest_.rows()) {  // none given: the identity
    start.rotations = Eigen::MatrixX3d(rest_.rows(), 3);
    for (int k = 0; k < clusters(); ++k)
      start.rotations.middleRows<3>(3 * k) = Eigen::Matrix3d::Identity();
  }
  return start;
}

}  // namespace specdeform
