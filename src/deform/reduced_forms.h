// Internal: the reduced quadratic forms of the deformation energies (deform_options.h), computed
// from the basis itself so that they hold for any M-orthonormal basis U (n x m), eigenvectors or
// not (a multilevel basis has U^T M U = I but K U != M U Lambda), in the mesh's units:
//     stiffness  S = U^T K U                  (m x m, symmetric; K the stiffness matrix),
//     bending    S G S,  G = U^T M_l U         (the bi-Laplacian of the mixed formulation in the
//                span: the curvature M^-1 K u of u = U c taken as its M-projection U S c onto
//                the span, whose squared norm in the lumped mass M_l is this; G = I for a basis
//                orthonormal in M_l).
// For exact manifold harmonics of K and M_l: Lambda and Lambda^2; for a Rayleigh-Ritz basis of K
// (the multilevel one) S = Lambda exactly, but not the bending. The fine bi-Laplacian
// U^T K M_l^-1 K U would charge the kinks of a coarse basis's functions: measured on the
// armadillo's hand scene (43k vertices, ARAP), the result with a multilevel basis lay 0.34% of
// the diagonal (RMS) from the exact basis's with the bending in the fine form, 0.12% in the mixed
// form (0.11% without bending); the linear energy 0.015% in the mixed form.
// K U is formed 16 columns at a time on two threads: O(nnz(K) m + n m^2) work and no n x m
// temporary.
#pragma once

#include <Eigen/Core>
#include <Eigen/Sparse>

#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform::detail {

// S = U^T K U (K symmetric).
Eigen::MatrixXd reduced_stiffness(const Eigen::SparseMatrix<double>& K, const Eigen::MatrixXd& U);
// The same for a basis of K's Laplacian: diag(eigenvalues) when basis.rayleigh_ritz says so
// (a 692k-vertex mesh: 1 s of forming U^T K U saved), else the product.
Eigen::MatrixXd reduced_stiffness(const Eigen::SparseMatrix<double>& K,
                                  const ManifoldHarmonics& basis);

// S G S with G = U^T diag(area) U, or S^2 when `orthonormal` (U^T diag(area) U = I) says G = I.
Eigen::MatrixXd reduced_bending(const Eigen::MatrixXd& S, const Eigen::VectorXd& area,
                                const Eigen::MatrixXd& U, bool orthonormal);

}  // namespace specdeform::detail
