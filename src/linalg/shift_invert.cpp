#include "linalg/shift_invert.h"

#include <cholmod.h>

#include <Eigen/CholmodSupport>

#include "specdeform/exceptions.h"

namespace specdeform::detail {

ShiftInvertAnalysis::ShiftInvertAnalysis(const Eigen::SparseMatrix<double>& K,
                                         const Eigen::SparseMatrix<double>& M)
    : K_(K), M_(M), common_(new cholmod_common) {
  cholmod_start(common_);
  common_->print = 0;  // a singular shift is reported by usable(), not printed
}

ShiftInvertAnalysis::~ShiftInvertAnalysis() {
  for (cholmod_factor*& f : symbolic_) cholmod_free_factor(&f, common_);
  cholmod_finish(common_);
  delete common_;
}

cholmod_factor* ShiftInvertAnalysis::factorize(const Eigen::SparseMatrix<double>& lower,
                                               bool definite) {
  Eigen::SparseMatrix<double> copy = lower;  // viewAsCholmod takes a non-const matrix
  cholmod_sparse A = Eigen::viewAsCholmod(copy);
  A.stype = -1;
  common_->supernodal = definite ? CHOLMOD_SUPERNODAL : CHOLMOD_SIMPLICIAL;
  common_->final_ll = definite;
  cholmod_factor*& symbolic = symbolic_[definite ? 1 : 0];
  if (symbolic == nullptr) {
    symbolic = cholmod_analyze(&A, common_);
    if (symbolic == nullptr) return nullptr;
    ++analyses_;
  }
  cholmod_factor* factor = cholmod_copy_factor(symbolic, common_);
  if (factor == nullptr) return nullptr;
  if (!cholmod_factorize(&A, factor, common_) || common_->status != CHOLMOD_OK ||
      factor->minor != factor->n) {
    cholmod_free_factor(&factor, common_);
    return nullptr;
  }
  return factor;
}

void ShiftInvertAnalysis::free_factor(cholmod_factor* factor) {
  cholmod_free_factor(&factor, common_);
}

ShiftInvert::ShiftInvert(ShiftInvertAnalysis& analysis, double sigma, std::mt19937_64& rng)
    : sigma_(sigma), S_(analysis.K_ - sigma * analysis.M_) {
  const Eigen::SparseMatrix<double> lower = S_.triangularView<Eigen::Lower>();
  cholmod_factor* factor = analysis.factorize(lower, definite());
  ok_ = factor != nullptr;
  if (ok_) {
    try {
      solver_.assign(factor);
    } catch (const SolverError&) {
      ok_ = false;
    }
    analysis.free_factor(factor);
  }
  if (ok_ && !definite()) {  // an LDL^T without pivoting: check it on a random right-hand side
    std::normal_distribution<double> normal;
    RowMatrix b(S_.rows(), 1), x;
    for (Eigen::Index i = 0; i < b.rows(); ++i) b(i, 0) = normal(rng);
    solve(b, x);
    ok_ = x.allFinite() && (b - S_ * x).norm() <= 1e-10 * b.norm();
  }
}

void ShiftInvert::solve(const RowMatrix& B, RowMatrix& X) {
  solver_.solve(B, X, workspace_);
  if (definite()) return;
  residual_ = B;
  residual_.noalias() -= S_ * X;
  solver_.solve(residual_, correction_, workspace_);
  X += correction_;
}

double clear_shift(double target, const std::vector<double>& known) {
  for (size_t i = 0; i + 1 < known.size(); ++i) {
    if (known[i] <= target && target <= known[i + 1]) return 0.5 * (known[i] + known[i + 1]);
  }
  return target;
}

}  // namespace specdeform::detail
