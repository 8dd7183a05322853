// The spatial reference solver: the energy of deform_options.h minimised over all n vertices
// (Rong, Cao & Guo 2008, eq. 14, with a sparse Cholesky factorisation instead of the paper's
// iterative BiCG), the baseline of the benchmarks and the ground truth of the tests.
//
// Over the displacement d (n x 3) it minimises
//     E(d) = tr(d^T A d) - 2 tr(d^T g) + constraints,
//   A = ks K + kb A_s K D^-1 K   (linear energy; D the lumped mass, A_s the surface area)
//   A = K+ + b A_s K D^-1 K      (ARAP's global step, K+ without negative weights;
//                                 arap_solver.h)
// for a linear term g (n x 3; zero for the linear energy):
//   hard: Dirichlet conditions d_C = t, A_FF d_F = g_F - A_FC t
//   soft: (A + w W) d = w W t + g, W = a_i on the constrained vertices
// factored with CHOLMOD once per selection; each frame is one back-substitution (3 columns).
// The bi-Laplacian always uses the lumped mass (the consistent one would make it dense).
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Sparse>

#include "specdeform/deform/deform_options.h"
#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform {

class SpatialSolver {
 public:
  SpatialSolver(const TriangleMesh& mesh, const DeformOptions& options);
  ~SpatialSolver();
  SpatialSolver(SpatialSolver&&) noexcept;
  SpatialSolver& operator=(SpatialSolver&&) noexcept;

  // Factors the system for these constrained vertices. Throws SolverError if it is singular.
  void set_constraints(const std::vector<int>& vertices);

  // One frame's targets (displacements, n' x 3) as the solve and the energy use them.
  struct Targets {
    Eigen::MatrixX3d values;
    double constant = 0.0;  // soft: w sum a_i |t_i|^2
  };
  Targets prepare(const Eigen::MatrixX3d& targets) const;

  // The minimiser d (n x 3) of E for the targets and a linear term g (n x 3, or 0 rows).
  Eigen::MatrixX3d solve(const Targets& targets, const Eigen::MatrixX3d& g) const;
  Eigen::MatrixX3d solve(const Eigen::MatrixX3d& targets) const {
    return solve(prepare(targets), Eigen::MatrixX3d());
  }

  // E(d) without the linear term: tr(d^T A d) plus, soft, the constraint term; with `gradient`,
  // also half of E's gradient at d for the linear term g (n x 3), as in ReducedSolver.
  double energy(const Targets& targets, const Eigen::MatrixX3d& d,
                const Eigen::MatrixX3d& g = Eigen::MatrixX3d(),
                Eigen::MatrixX3d* gradient = nullptr) const;

  // The inverse of E's Hessian applied to v (hard: zero on the constrained vertices).
  Eigen::MatrixX3d precondition(const Eigen::MatrixX3d& v) const;

  // The energy's matrix A (n x n), on the unit-area scale.
  const Eigen::SparseMatrix<double>& energy_matrix() const { return A_; }

 private:
  struct Factor;
  DeformOptions options_;
  Eigen::SparseMatrix<double> A_;
  Eigen::VectorXd vertex_area_;  // the soft constraints' a_i (piece_area_fractions)
  std::vector<int> constrained_;
  std::vector<int> free_;                 // hard: the free vertices
  Eigen::SparseMatrix<double> coupling_;  // hard: A_FC
  std::unique_ptr<Factor> factor_;
};

}  // namespace specdeform
