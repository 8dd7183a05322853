// As-rigid-as-possible deformation of the smooth base (Sorkine & Alexa, "As-rigid-as-possible
// surface modeling", 2007): the energy of deform_options.h made rotation-invariant, with one
// rotation per vertex cluster, minimised in the spectral subspace of the manifold harmonics or
// over all vertices.
//
// The energy of the deformed base s' = s + d (n x 3), the clusters those of
// mesh/vertex_clusters.h computed on s, R_k(i) the rotation of vertex i's cluster:
//     E(d, R) = 1/2 sum_i sum_{j ~ i} w+_ij |(s'_i - s'_j) - R_k(i) (s_i - s_j)|^2      membrane
//             + b A sum_i a_i |(M^-1 K s')_i - R_k(i) (M^-1 K s)_i|^2                    bending
//             + constraints,
// K the detailed mesh's stiffness matrix (the basis's Laplacian, cotan or intrinsic Delaunay;
// cotan without a basis), M that Laplacian's lumped mass (a_i), A the area,
// w+_ij = max(w_ij, 0) (negative weights would make a cluster's rest covariance indefinite and
// the rest pose no minimum), b = ArapOptions::bending. The membrane term keeps edge vectors, the
// bending term mean-curvature normals, each turned by its cluster's rotation; with every
// R_k = I the energy is the paper's linear one (ks = 1, kb = b, K+ for the membrane). The
// bending term gives the surface the stiffness against bending and necking that the membrane
// alone lacks (a bent bar keeps its cross-sections).
//
// In the spectral subspace, s' = s + H c, the curvatures M^-1 K s' are taken in the mixed form,
// as their M-projection onto the span (deform/reduced_forms.h): exact for eigenvectors, and free
// of the kinks of a basis that is not made of them (multilevel). With the cluster operator Q
// (3k x m; over all vertices the sparse 3k x n operator with the identity for H), the
// covariance of cluster k is S_k = S_k(s) + Q_k c (3 x 3) and
//     E(c, R) = tr(c^T D c) - sum_k tr((R_k - I) S_k) + constraints + const,
// D = S + b A S G S + H^T (K+ - K) H (S = H^T K H, G = H^T M H: Lambda + b A Lambda^2 + ... for
// eigenvectors) the reduced Hessian that ReducedSolver factors once per selection
// (reduced_solver.h):
//  - local step: R_k maximises tr(R_k S_k) (a closed-form polar decomposition, reflections
//    excluded): O(k m) per iteration;
//  - the energy's gradient in c, with the rotations optimal for c, is 2 (D c - 1/2 Q^T (R - I))
//    plus the constraints' (the blocks R_k^T - I stacked), and the global step c - D'^-1 (...),
//    D' = D with the soft constraints, minimises E for fixed rotations: O(m^2) per iteration.
// The iterations are L-BFGS with the global step's matrix as the initial inverse Hessian (Liu,
// Bouaziz & Kavan, "Quasi-Newton methods for real-time simulation of hyperelastic materials",
// 2017): without history a step is the local/global step; a step that fails the Armijo condition
// is replaced by the local/global step, so the energy never increases. Each iteration is
// O(k m + m^2), independent of n. They stop when an iteration lowers the energy by less than
// `tolerance` times the energy, or times `energy_floor` of the base's Dirichlet energy where the
// energy is smaller (a piece that only moves rigidly has an energy of rounding noise: measured
// against itself, its change would read as any number), when the energy falls below that floor
// (a start already below it, such as the rest under identity transforms, takes no step and is
// returned bit for bit), or at `max_iterations`. Energies are in the units of the mesh's lengths squared, on the unit-area
// scale of deform_options.h.
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
  double relative_change = 0.0;  // the fraction of the energy the last step removed (of the
                                 // floor, where the energy was below it): at most 1
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
  // mesh: the detailed mesh (its Laplacian's weights); base: its smooth base s (n x 3); basis:
  // the manifold harmonics (the spectral subspace) or null (all vertices); moving: the vertices
  // the basis can move (n flags, whole pieces; empty: all): the clusters cover them, the others
  // are one more cluster, which stays unturned.
  ArapSolver(const TriangleMesh& mesh, const Vertices& base,
             std::shared_ptr<const ManifoldHarmonics> basis, const ArapOptions& options,
             const std::vector<char>& moving = {});

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

  // Spectral: the reduced Hessian D (m x m) for ReducedSolver.
  const Eigen::MatrixXd& reduced_hessian() const { return reduced_hessian_; }
  // Spectral: H^T (K+ - K) H (m x m), D's part from the membrane's dropped negative cotangent
  // weights (zero where the mesh has none).
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
  Eigen::MatrixXd reduced_hessian_, membrane_correction_;
};

}  // namespace specdeform
