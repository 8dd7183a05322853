// Internal: the shift-invert operator x = (K - sigma M)^-1 b of the eigensolvers (K, M n x n
// symmetric, M positive definite), factored by CHOLMOD and solved by linalg/triangular_solver.h
// (two threads, a block of right-hand sides interleaved).
//  - sigma < 0 (below the spectrum of K >= 0): K - sigma M is positive definite, supernodal LL^T.
//  - sigma > 0 (an interior shift): simplicial LDL^T without pivoting, then one step of
//    iterative refinement per solve, which brings its ~1e-10 solves back to round-off (the
//    Krylov relation needs that). A shift (nearly) on an eigenvalue makes the matrix (nearly)
//    singular: usable() tells, and the caller moves the shift.
// The pattern of K - sigma M is the same for every sigma, so one ShiftInvertAnalysis holds the
// fill-reducing ordering and symbolic factor of each kind (definite, interior), computed on first
// use and shared by all the shifts of a solve.
#pragma once

#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Sparse>

#include "linalg/basis_sweep.h"
#include "linalg/triangular_solver.h"

struct cholmod_common_struct;

namespace specdeform::detail {

class ShiftInvertAnalysis {
 public:
  // K and M are referenced: they must outlive this object and the operators made from it.
  ShiftInvertAnalysis(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M);
  ~ShiftInvertAnalysis();
  ShiftInvertAnalysis(const ShiftInvertAnalysis&) = delete;
  ShiftInvertAnalysis& operator=(const ShiftInvertAnalysis&) = delete;

  // Symbolic analyses done so far (at most one per kind).
  int analyses() const { return analyses_; }

 private:
  friend class ShiftInvert;
  // The numeric factor of K - sigma M (lower triangle in `lower`), or null where CHOLMOD fails;
  // the caller frees it with free_factor().
  cholmod_factor_struct* factorize(const Eigen::SparseMatrix<double>& lower, bool definite);
  void free_factor(cholmod_factor_struct* factor);

  const Eigen::SparseMatrix<double>& K_;
  const Eigen::SparseMatrix<double>& M_;
  cholmod_common_struct* common_;
  cholmod_factor_struct* symbolic_[2] = {nullptr, nullptr};  // [definite]
  int analyses_ = 0;
};

class ShiftInvert {
 public:
  ShiftInvert(ShiftInvertAnalysis& analysis, double sigma, std::mt19937_64& rng);

  bool usable() const { return ok_; }
  double sigma() const { return sigma_; }
  // X = (K - sigma M)^-1 B, in X's memory.
  void solve(const RowMatrix& B, RowMatrix& X);

 private:
  bool definite() const { return sigma_ < 0.0; }
  double sigma_;
  Eigen::SparseMatrix<double> S_;
  bool ok_ = false;
  TriangularSolver solver_;
  std::vector<double> workspace_;
  RowMatrix residual_, correction_;
};

// A shift for a band around `target` that stays clear of the eigenvalues already seen: the middle
// of the gap between consecutive values of `known` (ascending) that holds `target`, or `target`
// itself outside their range.
double clear_shift(double target, const std::vector<double>& known);

}  // namespace specdeform::detail
