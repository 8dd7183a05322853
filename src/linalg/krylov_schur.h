// Internal: shift-invert block Krylov-Schur (Stewart 2001, in block form) for the `wanted`
// eigenpairs of K h = lambda M h nearest the shift sigma, in the M-orthogonal complement of pairs
// already found. With A = (K - sigma M)^-1 M it maintains the Krylov relation
//     A V = V T + Q F^T,    V^T M V = I,  Q^T M Q = I,  V^T M Q = 0,
// so Ritz pairs (theta, y = V z) of T have the residual A y - theta y = Q F^T z for free, and
// A y / theta = y + Q F^T z / theta, one step of inverse iteration, is free too. Thick restarts
// keep the `keep` Ritz vectors of largest |theta|. Each block step solves for a block of
// right-hand sides and orthogonalises it against V by block Gram-Schmidt, twice, in two passes
// over V (the first pass's subtraction fused with the second's projection,
// linalg/basis_sweep.h), then Cholesky QR within the block. The second pass's subtraction is
// lagged (DCGS2, Swirydowicz et al. 2020): the block joins V as it is, V is kept as V_true L
// with L unit upper triangular, and the next block's coefficients are corrected through the
// Krylov relation, so no third pass is needed (one per restart cycle finishes the last block).
#pragma once

#include <functional>
#include <random>

#include <Eigen/Core>
#include <Eigen/Sparse>

#include "linalg/block_orthogonalization.h"
#include "linalg/mass_operator.h"
#include "linalg/shift_invert.h"

namespace specdeform::detail {

struct KrylovSchurSettings {
  int wanted = 0;    // pairs nearest sigma to converge
  int block = 8;     // columns per block
  int subspace = 0;  // largest basis, a multiple of `block`
  // A pair has converged when the residual of its refined vector, ||r||_M / theta^2, is at most
  // tolerance * max(|lambda|, 1) (unit-area scale).
  double tolerance = 1e-8;
  int max_restarts = 60;
};

struct KrylovSchurResult {
  Eigen::VectorXd lambda;  // eigenvalues nearest sigma first
  Eigen::MatrixXd H;       // M-orthonormal to round-off, M-orthogonal to `found`
  bool converged = true;   // all `wanted` pairs converged
  int restarts = 0;
  long long solves = 0;  // right-hand sides solved
};

// `found`: pairs already known (M-orthonormal); `near`: those of them close enough to sigma to
// be amplified by the shift-invert, deflated from every block (the rest only at the end).
// `progress(fraction)` is called before every block step with an estimate of the work done.
KrylovSchurResult krylov_schur(ShiftInvert& op, const MassOperator& M, const Basis& found,
                               const Basis& near, const KrylovSchurSettings& settings,
                               std::mt19937_64& rng, const std::function<void(double)>& progress);

// Rayleigh-Ritz of (K, M) on the span of H (independent columns): H becomes an M-orthonormal
// basis of eigenvector approximations and lambda their values, ascending.
void rayleigh_ritz(const Eigen::SparseMatrix<double>& K, const MassOperator& M, Eigen::MatrixXd& H,
                   Eigen::VectorXd& lambda);

}  // namespace specdeform::detail
