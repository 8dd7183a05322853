// As-rigid-as-possible deformation of the smooth base (Sorkine & Alexa, "As-rigid-as-possible
// surface modeling", 2007) with one rotation per vertex cluster, in the spectral subspace of
// the manifold harmonics or over all vertices, accelerated by Anderson mixing with an energy
// safeguard (Peng, Deng, Zhang & Liu, "Anderson acceleration for geometry optimization and
// physics simulation", 2018).
//
// The energy of the deformed base s' = s + d (n x 3), with K's cotangent weights w_ij (K the
// detailed mesh's stiffness matrix, so that the quadratic part is d's K-energy) and the
// clusters of mesh/vertex_clusters.h (computed on s), is
//     E(d, R) = 1/2 sum_i sum_{j ~ i} w_ij |(s'_i - s'_j) - R_k(i) (s_i - s_j)|^2
//               + sum_{k < l} g_kl |R_k - R_l|_F^2 + constraints,
// the second term smoothing the rotations between neighbouring clusters (as SR-ARAP, Levi &
// Gotsman 2014, does between vertices): g_kl = beta A b_kl / (2 d_kl), A the surface area, b_kl
// the length of the boundary between clusters k and l and d_kl the distance of their centroids
// (a finite-volume Dirichlet energy of the rotation field, times beta A), beta =
// ArapOptions::rotation_smoothness. It gives the surface a bending stiffness that ARAP alone
// lacks: a strongly twisted bar keeps its cross-sections instead of necking.
// With the cluster operator Q (3k x m: Q_k = sum_{i in k, j ~ i} w_ij (s_i - s_j)(h_i - h_j)^T,
// H the basis; over all vertices the sparse 3k x n operator with unit vectors for h) and d = H c:
//  - local step: the covariance of cluster k is S_k = S_k(s) + Q_k c (3 x 3), and R_k maximises
//    tr(R_k (S_k + 2 sum_l g_kl R_l^T)) (SVD, reflections excluded), the clusters in turn with
//    their neighbours' latest rotations (block coordinate descent): O(k m) per iteration;
//  - global step: the minimiser of tr(c^T Lambda c) - 2 tr(c^T g) + constraints with
//    g = 1/2 Q^T (R - I) (the blocks R_k^T - I stacked), one solve of the m x m system that
//    ReducedSolver factors once per selection (D = Lambda): O(m^2) per iteration.
// Each iteration is O(k m + m^2), independent of n. The energy tracked is E up to a term of
// the order of the basis's eigen-residual (Lambda stands for H^T K H), minimised exactly by
// each step: it never increases (Anderson steps that would raise it are rejected). Stops when
// an iteration lowers the energy by less than `tolerance` times the energy, when the energy
// falls below 1e-14 of its starting value, or at `max_iterations`. Energies are in the units
// of the mesh's lengths squared, on the unit-area scale of deform_options.h.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Sparse>

#include "specdeform/deform/deform_options.h"
#include "specdeform/deform/reduced_solver.h"
#include "specdeform/deform/selection.h"
#include "specdeform/deform/spatial_solver.h"
#include "specdeform/mesh/triangle_mesh.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform {

struct ArapReport {
  int iterations = 0;            // local/global steps taken
  int accelerated = 0;           // of which quasi-Newton (L-BFGS) steps kept
  double energy = 0.0;           // at the result
  double relative_change = 0.0;  // the last step's decrease of the energy over the energy
  bool converged = false;        // stopped by the tolerance, not by the cap
};

// Where the iterations are: x (spectral: the coefficients c, m x 3; all vertices: the
// displacement d, n x 3) and the clusters' rotations (the blocks R_k of 3k x 3; none: the
// identity).
struct ArapState {
  Eigen::MatrixX3d x;
  Eigen::MatrixX3d rotations;
};

class ArapSolver {
 public:
  // mesh: the detailed mesh (its cotangent weights); base: its smooth base s (n x 3); basis:
  // the manifold harmonics (the spectral subspace) or null (all vertices).
  ArapSolver(const TriangleMesh& mesh, const Vertices& base,
             std::shared_ptr<const ManifoldHarmonics> basis, const ArapOptions& options);

  // The cold start of a frame: the rotation of each handle group (the polar part of its
  // transform) spread over the surface, R_k = exp(sum_g phi_g,k log R_g) with phi_g the harmonic
  // weight of group g (the global step's system solved for 1 on the group and 0 on the other
  // constrained vertices, averaged over cluster k), then the global step with these rotations.
  // A twisted or bent bar starts twisted or bent; from the rest pose the iterations would stall
  // in the linear energy's collapsed shape.
  ArapState start(const ReducedSolver& solver, const ReducedSolver::Targets& targets,
                  const ConstrainedSet& set, const std::vector<Eigen::Affine3d>& transforms) const;
  ArapState start(const SpatialSolver& solver, const SpatialSolver::Targets& targets,
                  const ConstrainedSet& set, const std::vector<Eigen::Affine3d>& transforms) const;

  // The iterations from `start` (the spectral or the all-vertices kind, as built).
  ArapState solve(const ReducedSolver& solver, const ReducedSolver::Targets& targets,
                  ArapState start, ArapReport* report = nullptr) const;
  ArapState solve(const SpatialSolver& solver, const SpatialSolver::Targets& targets,
                  ArapState start, ArapReport* report = nullptr) const;

  // Spectral: H^T (K+ - K) H (m x m), what the membrane's dropped negative cotangent weights
  // add to the reduced Hessian Lambda (zero where the mesh has none).
  const Eigen::MatrixXd& membrane_correction() const { return membrane_correction_; }

  int clusters() const { return static_cast<int>(rest_.rows() / 3); }
  const Eigen::VectorXi& cluster_of_vertex() const { return label_; }

 private:
  struct ReducedSpace;
  struct SpatialSpace;
  // `start` with identity rotations where it has none; InputError for x of the wrong size.
  ArapState checked(ArapState start, Eigen::Index size) const;

  ArapOptions options_;
  Eigen::VectorXi label_;
  // Over all vertices: the cluster operator (3k x n) and the mean over each cluster (k x n).
  Eigen::SparseMatrix<double> operator_, mean_;
  // Spectral: the same applied to the basis, Q = operator_ H (3k x m), Q^T and mean_ H (k x m).
  Eigen::MatrixXd reduced_, reduced_transposed_, reduced_mean_;
  Eigen::MatrixX3d rest_;  // S(s), 3k x 3
  Eigen::MatrixXd membrane_correction_;
};

}  // namespace specdeform
