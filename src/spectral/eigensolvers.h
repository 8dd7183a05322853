// Internal: the three ways compute_manifold_harmonics() solves K h = lambda M h for the first m
// pairs, all on the unit-area scale (M of total mass 1), ascending, H^T M H = I:
//  - solve_dense: Eigen's dense generalized solver (small meshes, or m close to n);
//  - solve_lanczos: Spectra's shift-invert Lanczos on CHOLMOD, the plain baseline;
//  - solve_block_krylov: K's null space (the constants of each connected component) exactly,
//    then bands of pairs by shift-invert block Krylov-Schur (linalg/krylov_schur.h), the first
//    below the spectrum, later ones at interior shifts, each deflated against the pairs found;
//  - solve_multilevel: an approximation (spectral/multilevel.cpp): the Galerkin projection onto
//    a coarse partition-of-unity space (spectral/coarse_space.h), solved exactly there.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Sparse>

#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform::detail {

struct Spectrum {
  Eigen::VectorXd lambda;
  // The basis (n x m); where `factored` holds it, empty or memory for its product (n x m, its
  // pages touched, contents undefined: linalg/basis_product.h factored_product).
  Eigen::MatrixXd H;
  SolveStatus status = SolveStatus::Converged;
  int bands = 0, restarts = 0;
  long long solves = 0;
  bool cluster_truncated = false;  // lambda_m (nearly) equals lambda_{m+1}
  int coarse_functions = 0;        // solve_multilevel: N
  FactoredBasis factored;          // solve_multilevel: H = P Z, H left to form
  // solve_multilevel: max |H^T M H - I| = max |Z^T (P^T M P) Z - I|, measured on the coarse
  // problem (H = P Z exactly).
  double orthonormality_error = 0.0;
};

Spectrum solve_dense(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M,
                     int m);
Spectrum solve_lanczos(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M,
                       const ManifoldHarmonicsOptions& options);
Spectrum solve_block_krylov(const Eigen::SparseMatrix<double>& K,
                            const Eigen::SparseMatrix<double>& M,
                            const ManifoldHarmonicsOptions& options);

// lengths: K's edges with their lengths (coarse_space.h), for the coarse space's distances.
Spectrum solve_multilevel(const Eigen::SparseMatrix<double>& K,
                          const Eigen::SparseMatrix<double>& M,
                          const Eigen::SparseMatrix<double>& lengths,
                          const ManifoldHarmonicsOptions& options);

// The connected components of K's graph (its stored entries): a label in [0, count) per
// vertex, numbered by first vertex; returns count.
int stiffness_components(const Eigen::SparseMatrix<double>& K, std::vector<int>& label);

// K's null space, known exactly: the constants on each connected component of K's graph,
// M-normalised; n x (number of components).
Eigen::MatrixXd stiffness_null_space(const Eigen::SparseMatrix<double>& K,
                                     const Eigen::SparseMatrix<double>& M);

// Reports progress through options.progress, if set.
void report(const ManifoldHarmonicsOptions& options, double fraction, std::string_view stage);

}  // namespace specdeform::detail
