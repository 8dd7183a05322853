// Internal: the accuracy of computed eigenpairs of K h = lambda M h, per pair, on the unit-area
// scale (A = sum of M's entries, D = M's row sums):
//     residual = A ||K h - lambda M h||_{D^-1} / max(A lambda, 1),
//     floor    = eps A || |K||h| + |lambda| |M||h| ||_{D^-1} / max(A lambda, 1),
// the floor being the rounding error of forming K h - lambda M h itself: no solver gets below
// it, and on meshes with nearly degenerate triangles (huge cotangent weights, tiny areas) it
// exceeds any sensible tolerance. A pair meets a tolerance when its residual is at most
// max(tolerance, floor_factor * floor): its threshold.
#pragma once

#include <Eigen/Core>
#include <Eigen/Sparse>

#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform::detail {

struct PairErrors {
  Eigen::VectorXd residual, floor;

  // Each pair's threshold, as above.
  Eigen::VectorXd thresholds(double tolerance, double floor_factor) const;
  // Whether every residual is within `factor` times its threshold.
  bool within(double tolerance, double floor_factor, double factor = 1.0) const;
};

// K and M symmetric. floors = false: the floors are left 0 (an approximate basis, whose
// residuals are orders of magnitude above them: half the work).
PairErrors pair_errors(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M,
                       const Eigen::MatrixXd& H, const Eigen::VectorXd& lambda, bool floors = true);

// The same for a factored basis H = P Z without forming H (each block of H's columns gathered
// from P's rows as it is needed), without floors; `largest` receives each column's entry of
// largest magnitude, signed (for the sign convention, at no further pass).
PairErrors pair_errors(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M,
                       const FactoredBasis& H, const Eigen::VectorXd& lambda,
                       Eigen::VectorXd& largest);

}  // namespace specdeform::detail
