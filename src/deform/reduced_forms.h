// Internal: the reduced quadratic forms of the deformation energies (deform_options.h), computed
// from the basis itself so that they hold for any M-orthonormal basis, eigenvectors or not (a
// multilevel basis has U^T M U = I but K U != M U Lambda): with U (n x m), K the stiffness
// matrix (n x n, symmetric) and a the lumped vertex areas (n), in the mesh's units,
//     stiffness = U^T K U                                           (m x m, symmetric),
//     bending   = U^T K diag(a)^-1 K U        (Bending::Fine: the fine bi-Laplacian),
//               = stiffness^2                 (Bending::Mixed: the bi-Laplacian of the
//                 mixed formulation in the span, Delta u = v weakly with v in the span too).
// For exact manifold harmonics of K and the lumped mass both are Lambda^2. On a coarse basis
// they differ: Fine charges the kinks of the coarse functions (measured on a bumpy bar, the
// linear energy's result lay 2.1% of the diagonal (RMS) from the exact basis's with Fine, 0.04%
// with Mixed); ARAP needs Fine, since its rotated curvature term (arap_solver.h) is formed from K
// U. K U is formed a block of rows at a time on two threads: O(nnz(K) m + n m^2) work and no n x m
// temporary.
#pragma once

#include <Eigen/Core>
#include <Eigen/Sparse>

namespace specdeform::detail {

enum class Bending { Fine, Mixed };

struct ReducedForms {
  Eigen::MatrixXd stiffness, bending;
};

ReducedForms reduced_forms(const Eigen::SparseMatrix<double>& K, const Eigen::VectorXd& area,
                           const Eigen::MatrixXd& U, Bending bending);

}  // namespace specdeform::detail
