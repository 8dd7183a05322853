// The deformation of the smooth base in the spectral domain (Rong, Cao & Guo 2008, section 4.3,
// done as in the technical notes rather than literally).
//
// With d = H c, H the n x m manifold harmonics (H^T M H = I, mesh units), every energy of
// deform_options.h has a reduced Hessian D (m x m), the same for x, y and z, formed from H
// itself (S = H^T K H, the bending in the mixed form of deform/reduced_forms.h, A the surface
// area: unit-area scaling), so that any M-orthonormal basis serves, eigenvectors or not:
//     linear:  D = ks S + kb A S^2           (ks Lambda + kb A Lambda^2 for eigenvectors)
//     ARAP:    D = S + b A S^2 + H^T (K+ - K) H   (its global step; arap_solver.h)
// This solver minimises, over the coefficients c (m x 3),
//     E(c) = tr(c^T D c) - 2 tr(c^T g) + constraints
// for a linear term g (m x 3; zero for the linear energy). No n x n product is ever formed.
//  - Soft constraints: w sum_C a_i |h_i^T c - t_i|^2, so (D + w H_C^T W_C H_C) c = w H_C^T W_C t
//    + g, factored (Cholesky, m x m) once per selection in O(n' m^2 + m^3) — or, when the
//    selection changes by a few vertices, in O(changed m^2 + m^3) by updating the normal matrix
//    — and solved per frame in O(n'' m + m^2), n'' the constrained vertices that move.
//  - Hard constraints: H_C c = t exactly (null-space method on a QR of H_C^T); needs H_C
//    (n' x m) of full row rank, so n' <= m: otherwise InputError.
// Targets t are displacements (n' x 3) of the constrained vertices. Where each handle group moves
// its vertices by one affine map T_g (t_i = T_g s_i - s_i; fixed vertices: 0), the soft
// right-hand side needs only each group's moments about its weighted centroid c_g (r_i = s_i -
// c_g, B_g = T_g's linear part - I, u_g = T_g c_g - c_g):
//     w H_C^T W_C t = sum_g (sum_i w a_i h_i r_i^T) B_g^T + (sum_i w a_i h_i) u_g^T,
// O(groups m) per frame instead of O(n'' m) (n'' = 69k handle vertices at 692k: 9-16 ms).
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "specdeform/deform/deform_options.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform {

class ReducedSolver {
 public:
  // hessian: D (m x m, symmetric positive semidefinite); vertex_area: lumped mass (n) on the
  // unit-area scale.
  ReducedSolver(std::shared_ptr<const ManifoldHarmonics> basis, Eigen::MatrixXd hessian,
                Eigen::VectorXd vertex_area, const DeformOptions& options);

  // Factors the reduced system for these constrained vertices.
  void set_constraints(const std::vector<int>& vertices);

  // What one frame's targets contribute, computed once per frame: soft, the right-hand side
  // w H_C^T W_C t and the constant w sum a_i |t_i|^2; hard, the minimiser for g = 0.
  struct Targets {
    Eigen::MatrixX3d rhs;
    double constant = 0.0;
  };
  Targets prepare(const Eigen::MatrixX3d& targets) const;

  // For prepare(transforms), after set_constraints: group[i], the handle group of constrained
  // vertex i (-1: it keeps its place; groups 0 .. num_groups - 1), and positions, the rest s of
  // all n vertices that the transforms move. O(n' m).
  void set_groups(const std::vector<int>& group, int num_groups, const Eigen::MatrixX3d& positions);
  // prepare() for the targets t_i = T_g(i) s_i - s_i (0 for group -1): soft, in O(groups m).
  Targets prepare(const std::vector<Eigen::Affine3d>& transforms) const;

  // The minimiser c (m x 3) of E for the targets and a linear term g (m x 3, or 0 rows for none).
  Eigen::MatrixX3d solve(const Targets& targets, const Eigen::MatrixX3d& g) const;
  Eigen::MatrixX3d solve(const Eigen::MatrixX3d& targets) const {
    return solve(prepare(targets), Eigen::MatrixX3d());
  }

  // E(c) without the linear term: tr(c^T D c) plus, soft, the constraint term (hard: c is taken
  // to meet the constraints). With `gradient`, also half of E's gradient at c for the linear term
  // g (m x 3): soft, (D + w H_C^T W_C H_C) c - rhs - g; hard, D c - g.
  double energy(const Targets& targets, const Eigen::MatrixX3d& c,
                const Eigen::MatrixX3d& g = Eigen::MatrixX3d(),
                Eigen::MatrixX3d* gradient = nullptr) const;

  // The inverse of E's Hessian applied to v (soft: the normal matrix's inverse; hard: restricted
  // to the directions that keep the constraints): solve() is c - precondition(gradient) from any
  // c (that meets the hard constraints).
  Eigen::MatrixX3d precondition(const Eigen::MatrixX3d& v) const;

  const Eigen::MatrixXd& hessian() const { return hessian_; }

 private:
  // The soft constraint's weight of a vertex: constraint_weight times its (unit-scale) area.
  double weight(int vertex) const { return options_.constraint_weight * vertex_area_[vertex]; }

  std::shared_ptr<const ManifoldHarmonics> basis_;
  Eigen::MatrixXd hessian_;
  Eigen::VectorXd vertex_area_;  // on the unit-area scale
  DeformOptions options_;
  Eigen::MatrixXd columns_;     // H_C^T, m x n'
  Eigen::VectorXd weights_;     // w W_C (n')
  std::vector<int> column_of_;  // vertex -> its column of columns_, or -1
  std::vector<int> vertex_;     // column -> its vertex
  // Each group's moments (set_groups): the weight W_g = sum w a_i, the centroid c_g, the spread
  // sum w a_i r_i r_i^T, h0 = sum w a_i h_i (m) and h1 = sum w a_i h_i r_i^T (m x 3).
  struct Moments {
    double weight = 0.0;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
    Eigen::VectorXd h0;
    Eigen::MatrixX3d h1;
  };
  std::vector<Moments> moments_;
  std::vector<int> group_;  // set_groups' (n')
  Eigen::MatrixX3d rest_;   // s of the constrained vertices (n' x 3)
  Eigen::MatrixXd normal_;  // soft: D + w H_C^T W_C H_C
  Eigen::LLT<Eigen::MatrixXd> soft_;
  // Hard: c = Q1 R^-T t + Q2 z, z = (Q2^T D Q2)^-1 Q2^T (g - D Q1 R^-T t), i.e. c = P t + Z g.
  Eigen::MatrixXd hard_;       // P, m x n'
  Eigen::MatrixXd hard_free_;  // Z = Q2 (Q2^T D Q2)^-1 Q2^T, m x m
};

}  // namespace specdeform
