#include "specdeform/deform/arap_solver.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "deform/reduced_forms.h"
#include "linalg/basis_product.h"
#include "linalg/nearest_rotation.h"
#include "linalg/parallel.h"
#include "linalg/sparse_basis_product.h"
#include "membrane_stiffness.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/vertex_clusters.h"
#include "specdeform/operators/laplacian.h"
#include "specdeform/operators/mass_matrix.h"

namespace specdeform {

namespace {

using Sparse = Eigen::SparseMatrix<double>;

// The rotation R maximising tr(R X) over all rotations (reflections excluded): the one nearest
// to X^T.
void fit_rotation(const Eigen::Matrix3d& X, Eigen::Ref<Eigen::Matrix3d> R) {
  R = detail::nearest_rotation(X.transpose());
}

// The local step: each R_k maximises tr(R_k S_k) given the covariances S (3k x 3, blocks S_k),
// from R's previous value where the fit iterates. Returns the energy's rotation-dependent part,
// -sum_k tr((R_k - I) S_k).
double fit_rotations(const Eigen::MatrixX3d& S, Eigen::MatrixX3d& R) {
  double energy = 0.0;
  for (Eigen::Index k = 0; k < S.rows(); k += 3) {
    const Eigen::Matrix3d Sk = S.middleRows<3>(k);
    fit_rotation(Sk, R.middleRows<3>(k));
    energy -= ((R.middleRows<3>(k) - Eigen::Matrix3d::Identity()) * Sk).trace();
  }
  return energy;
}

// An iterate: x (m x 3 or n x 3), the clusters' rotations R_k (the blocks of 3k x 3), the
// energy E(x, R) and half its gradient in x.
struct Iterate {
  Eigen::MatrixX3d x, rotations, gradient;  // gradient: half of E's, for these rotations
  double energy = 0.0;
};

// The blocks R_k^T - I of the global step's right-hand side (3k x 3).
Eigen::MatrixX3d transposed_minus_identity(const Eigen::MatrixX3d& rotations) {
  Eigen::MatrixX3d out(rotations.rows(), 3);
  for (Eigen::Index k = 0; k < rotations.rows(); k += 3)
    out.middleRows<3>(k) = rotations.middleRows<3>(k).transpose() - Eigen::Matrix3d::Identity();
  return out;
}

// The minimisation of E(x) = min_R E(x, R) over a space that provides covariance(x) (S, 3k x 3),
// energy(x, R^T - I blocks, &gradient) (E's quadratic and constraint part, and half of E's
// gradient in x with the rotations optimal for x: the envelope theorem) and precondition(v) (the
// inverse of the quadratic part's Hessian: the global step is x - precondition(gradient)).
// L-BFGS (Liu, Bouaziz & Kavan, "Quasi-Newton methods for real-time simulation of hyperelastic
// materials", 2017) with the global step's matrix as the initial inverse Hessian: without
// history its step is the local/global step. A step that fails the Armijo condition is replaced
// by the local/global step, which never raises the energy, and the history is cleared.
template <typename Space>
ArapState iterate(const Space& space, ArapState start, double scale, const ArapOptions& options,
                  ArapReport* report) {
  const auto local = [&](Eigen::MatrixX3d x, Eigen::MatrixX3d R) {
    Iterate it{std::move(x), std::move(R), {}, 0.0};
    const double rotational = fit_rotations(space.covariance(it.x), it.rotations);
    it.energy =
        space.energy(it.x, transposed_minus_identity(it.rotations), &it.gradient) + rotational;
    return it;
  };
  const auto dot = [](const Eigen::MatrixX3d& a, const Eigen::MatrixX3d& b) {
    return (a.array() * b.array()).sum();
  };
  struct Pair {
    Eigen::MatrixX3d step, change;  // x_{i+1} - x_i, gradient_{i+1} - gradient_i
    double rho;                     // 1 / (change . step)
  };
  std::deque<Pair> history;
  ArapReport r;
  Iterate current = local(std::move(start.x), std::move(start.rotations));
  const double floor = std::max(options.energy_floor * scale, 1e-14 * current.energy);
  std::vector<double> alpha;
  // A start whose energy is rounding noise (the rest, a rigid motion) is the solution: a step
  // would only move it by that noise.
  r.converged = current.energy <= floor;
  while (!r.converged && r.iterations < options.max_iterations) {
    ++r.iterations;
    Eigen::MatrixX3d direction = current.gradient;  // the two-loop recursion
    alpha.resize(history.size());
    for (size_t i = history.size(); i-- > 0;) {
      alpha[i] = history[i].rho * dot(history[i].step, direction);
      direction -= alpha[i] * history[i].change;
    }
    direction = space.precondition(direction);
    for (size_t i = 0; i < history.size(); ++i) {
      direction +=
          (alpha[i] - history[i].rho * dot(history[i].change, direction)) * history[i].step;
    }
    Iterate next;
    const double slope = -2.0 * dot(current.gradient, direction);  // of E along -direction
    bool accepted = false;
    if (!history.empty() && slope < 0.0) {
      next = local(current.x - direction, current.rotations);
      accepted = next.energy <= current.energy + 1e-4 * slope;
    }
    if (accepted) {
      ++r.accelerated;
    } else {
      next = local(current.x - space.precondition(current.gradient), current.rotations);
      history.clear();
    }
    Pair pair{next.x - current.x, next.gradient - current.gradient, 0.0};
    const double curvature = dot(pair.change, pair.step);
    if (options.history > 0 && curvature > 0.0) {
      pair.rho = 1.0 / curvature;
      history.push_back(std::move(pair));
      if (static_cast<int>(history.size()) > options.history) history.pop_front();
    }
    r.relative_change = (current.energy - next.energy) / std::max(current.energy, floor);
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

// The bending part of the covariance operator, 3k x n: with l_i = (M^-1 K s)_i, the rest
// shape's mean-curvature normal at vertex i (M the lumped mass), cluster k's rows of B s' are
// sum_{i in k} l_i (K s')_i^T.
Sparse bending_operator(const Sparse& K, const Eigen::VectorXd& mass, const Vertices& s,
                        const Eigen::VectorXi& label, int clusters) {
  const Eigen::MatrixX3d curvature = mass.cwiseInverse().asDiagonal() * (K * s);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(3 * static_cast<size_t>(K.nonZeros()));
  for (int j = 0; j < K.outerSize(); ++j) {
    for (Sparse::InnerIterator it(K, j); it; ++it) {  // K_ij, i = it.row()
      const int i = static_cast<int>(it.row());
      for (int d = 0; d < 3; ++d)
        entries.emplace_back(3 * label[i] + d, j, curvature(i, d) * it.value());
    }
  }
  Sparse B(3 * clusters, K.cols());
  B.setFromTriplets(entries.begin(), entries.end());
  return B;
}

// The mixed form's bending covariance weights, 3k x n: cluster k's rows hold, in vertex i's
// column, a_i l_i for the projected curvature l_i (the row i of `curvature`) and the lumped area
// a_i, so that applied to curvatures (n x 3) they give sum_{i in k} a_i l_i l'_i^T.
Sparse curvature_weights(const Eigen::MatrixX3d& curvature, const Eigen::VectorXd& mass,
                         const Eigen::VectorXi& label, int clusters) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(3 * static_cast<size_t>(curvature.rows()));
  for (int i = 0; i < curvature.rows(); ++i)
    for (int d = 0; d < 3; ++d)
      entries.emplace_back(3 * label[i] + d, i, mass[i] * curvature(i, d));
  Sparse W(3 * clusters, curvature.rows());
  W.setFromTriplets(entries.begin(), entries.end());
  return W;
}

}  // namespace

ArapSolver::ArapSolver(const TriangleMesh& mesh, const Vertices& base,
                       std::shared_ptr<const ManifoldHarmonics> basis, const ArapOptions& options,
                       const std::vector<char>& moving)
    : options_(options) {
  if (base.rows() != mesh.num_vertices()) {
    throw InputError("ARAP: the base has " + std::to_string(base.rows()) + " vertices, the mesh " +
                     std::to_string(mesh.num_vertices()));
  }
  // The clusters beside the basis's own Laplacian and lumped mass, on two threads.
  VertexClusters clusters;
  Sparse K;
  Eigen::VectorXd mass;
  detail::run_pair(
      [&] {
        const TriangleMesh surface{base, mesh.F};
        clusters = moving.empty() ? vertex_clusters(surface, options.clusters)
                                  : vertex_clusters(surface, options.clusters, moving);
      },
      [&] {
        LaplacianOperators L = laplacian_operators(mesh, MassType::Lumped,
                                                   basis ? basis->laplacian : LaplacianType::Cotan);
        K = std::move(L.stiffness);
        mass = L.mass.diagonal();
      });
  label_ = clusters.label;
  // Membrane and bending, as the linear energy's ks = 1 and kb = bending (unit-area scale).
  const Sparse stretch =
      cluster_operator(detail::membrane_stiffness(K), base, label_, clusters.count);
  const double bend = 2.0 * options.bending * mass.sum();
  // The mean over each cluster's vertices (k x n), applied to the basis when there is one.
  Eigen::VectorXd size = Eigen::VectorXd::Zero(clusters.count);
  for (int i = 0; i < label_.size(); ++i) size[label_[i]] += 1.0;
  std::vector<Eigen::Triplet<double>> mean;
  for (int i = 0; i < label_.size(); ++i) mean.emplace_back(label_[i], i, 1.0 / size[label_[i]]);
  Sparse cluster_mean(clusters.count, mesh.num_vertices());
  cluster_mean.setFromTriplets(mean.begin(), mean.end());
  if (basis) {
    // H^T (K+ - K) H, summed over the dropped (negative-weight) pairs only.
    const Eigen::MatrixXd& H = basis->basis;
    std::vector<std::pair<int, int>> dropped;
    std::vector<double> weight;
    for (int j = 0; j < K.outerSize(); ++j) {
      for (Sparse::InnerIterator it(K, j); it; ++it) {
        if (it.row() < j && it.value() > 0.0) {
          dropped.emplace_back(static_cast<int>(it.row()), j);
          weight.push_back(std::sqrt(it.value()));
        }
      }
    }
    // Column by column (contiguous writes, reads within one column of H), on two threads.
    Eigen::MatrixXd differences(dropped.size(), H.cols());
    detail::split_in_two(H.cols(), [&](Eigen::Index begin, Eigen::Index end) {
      for (Eigen::Index c = begin; c < end; ++c) {
        const double* h = H.col(c).data();
        double* out = differences.col(c).data();
        for (size_t e = 0; e < dropped.size(); ++e)
          out[e] = weight[e] * (h[dropped[e].first] - h[dropped[e].second]);
      }
    });
    membrane_correction_ = differences.transpose() * differences;
    // Bending in the mixed form (deform/reduced_forms.h): a curvature M^-1 K s' taken as its
    // projection H S c' onto the span, s' = H c', S = H^T K H; the base's coefficients a from
    // the basis's own mass.
    const Eigen::MatrixXd S = detail::reduced_stiffness(K, *basis);
    const bool lumped = basis->mass == MassType::Lumped;
    const Sparse own_mass =
        lumped ? Sparse(mass.asDiagonal()) : mass_matrix(mesh, basis->mass, basis->laplacian);
    const Eigen::MatrixX3d curvature = H * (S * (H.transpose() * (own_mass * base)));
    const Sparse weights = curvature_weights(curvature, mass, label_, clusters.count);
    const std::vector<Eigen::MatrixXd> reduced =
        detail::sparse_basis_products({&stretch, &weights, &cluster_mean}, H);
    reduced_ = reduced[0] + bend * (reduced[1] * S);
    rest_ = stretch * base + bend * (weights * curvature);
    reduced_hessian_ =
        S + 0.5 * bend * detail::reduced_bending(S, mass, H, lumped) + membrane_correction_;
    reduced_transposed_ = reduced_.transpose();
    reduced_mean_ = reduced[2];
  } else {
    operator_ = stretch + bend * bending_operator(K, mass, base, label_, clusters.count);
    rest_ = operator_ * base;
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
  const Eigen::AngleAxisd rotation(detail::nearest_rotation(linear));
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
  // Q c and 1/2 Q^T r with the frame's vectorised kernel (no BLAS call: its threads would spin
  // beside the frame's own).
  Eigen::MatrixX3d covariance(const Eigen::MatrixX3d& c) const {
    Eigen::MatrixX3d S;
    detail::add_basis_product(self.rest_, self.reduced_, c, S);
    return S;
  }
  Eigen::MatrixX3d linear_term(const Eigen::MatrixX3d& rotations) const {
    Eigen::MatrixX3d g;
    detail::add_basis_product(Eigen::MatrixX3d::Zero(self.reduced_.cols(), 3),
                              self.reduced_transposed_, 0.5 * rotations, g);
    return g;
  }
  Eigen::MatrixX3d global(const Eigen::MatrixX3d& rotations) const {
    return solver.solve(targets, linear_term(rotations));
  }
  double energy(const Eigen::MatrixX3d& c, const Eigen::MatrixX3d& rotations,
                Eigen::MatrixX3d* gradient) const {
    return solver.energy(targets, c, linear_term(rotations), gradient);
  }
  Eigen::MatrixX3d precondition(const Eigen::MatrixX3d& v) const { return solver.precondition(v); }
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
  double energy(const Eigen::MatrixX3d& d, const Eigen::MatrixX3d& rotations,
                Eigen::MatrixX3d* gradient) const {
    return solver.energy(targets, d, 0.5 * (self.operator_.transpose() * rotations), gradient);
  }
  Eigen::MatrixX3d precondition(const Eigen::MatrixX3d& v) const { return solver.precondition(v); }
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
  return iterate(ReducedSpace{*this, solver, targets}, checked(std::move(start), reduced_.cols()),
                 energy_scale(rest_), options_, report);
}

ArapState ArapSolver::solve(const SpatialSolver& solver, const SpatialSolver::Targets& targets,
                            ArapState start, ArapReport* report) const {
  if (operator_.cols() == 0) throw InputError("ARAP: built with a basis");
  return iterate(SpatialSpace{*this, solver, targets}, checked(std::move(start), operator_.cols()),
                 energy_scale(rest_), options_, report);
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
