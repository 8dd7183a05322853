// The deformation of the smooth base in the spectral domain (Rong, Cao & Guo 2008, section 4.3,
// done as in the technical notes rather than literally).
//
// With d = H c, H the n x m manifold harmonics (H^T M H = I, mesh units) and Lambda their
// eigenvalues, the energy of deform_options.h is exactly
//     E = c^T (ks Lambda + kb A Lambda^2) c            (A = surface area: unit-area scaling)
// a diagonal Hessian, the same for x, y and z; no n x n product is ever formed.
//  - Soft constraints: (D + w H_C^T W_C H_C) c = w H_C^T W_C t, factored (Cholesky, m x m) once
//    per selection in O(n' m^2 + m^3) — or, when the selection changes by a few vertices, in
//    O(changed m^2 + m^3) by updating the normal matrix — and solved per frame in O(n'' m + m^2),
//    n'' the constrained vertices that move (the fixed ones add nothing).
//  - Hard constraints: minimise c^T D c subject to H_C c = t (null-space method on a QR of
//    H_C^T); needs H_C (n' x m) of full row rank, so n' <= m: otherwise InputError.
// Targets t are displacements (n' x 3) of the constrained vertices.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/QR>

#include "specdeform/deform/deform_options.h"

namespace specdeform {

class ReducedSolver {
 public:
  // basis: n x m; eigenvalues: m; vertex_area: lumped mass (n); area: the surface area.
  ReducedSolver(const Eigen::MatrixXd& basis, const Eigen::VectorXd& eigenvalues,
                const Eigen::VectorXd& vertex_area, double area, const DeformOptions& options);

  // Factors the reduced system for these constrained vertices.
  void set_constraints(const std::vector<int>& vertices);

  // Spectral coefficients c (m x 3) of the displacement for target displacements t (n' x 3).
  Eigen::MatrixX3d solve(const Eigen::MatrixX3d& targets) const;

  // The diagonal Hessian D = ks Lambda + kb A Lambda^2 (m).
  const Eigen::VectorXd& hessian() const { return hessian_; }

 private:
  // The soft constraint's weight of a vertex: constraint_weight times its (unit-scale) area.
  double weight(int vertex) const { return options_.constraint_weight * vertex_area_[vertex]; }

  const Eigen::MatrixXd& basis_;
  Eigen::VectorXd vertex_area_;  // on the unit-area scale
  Eigen::VectorXd hessian_;
  DeformOptions options_;
  Eigen::MatrixXd columns_;     // H_C^T, m x n'
  Eigen::VectorXd weights_;     // w W_C (n')
  std::vector<int> column_of_;  // vertex -> its column of columns_, or -1
  Eigen::MatrixXd normal_;      // soft: D + w H_C^T W_C H_C
  Eigen::LLT<Eigen::MatrixXd> soft_;
  // Hard: c = Q1 R^-T t + Q2 z, z = -(Q2^T D Q2)^-1 Q2^T D Q1 R^-T t, i.e. c = P t.
  Eigen::MatrixXd hard_;  // P, m x n'
};

}  // namespace specdeform
