#include "anchored_poisson.h"

#include <cholmod.h>

#include <algorithm>

#include <Eigen/CholmodSupport>

#include "specdeform/exceptions.h"

namespace specdeform::detail {

namespace {

using Sparse = Eigen::SparseMatrix<double>;

}  // namespace

AnchoredPoisson::AnchoredPoisson(const Sparse& K, Solves solves)
    : solves_(solves),
      K_(K),
      anchored_(K.rows(), 0),
      position_(K.rows()),
      common_(new cholmod_common) {
  cholmod_start(common_);
  // Factored supernodal (BLAS-3: half the time of a simplicial factorisation at 692k vertices);
  // turned into the simplicial LDL^T that rowadd and rowdel work on at the first update.
  common_->supernodal = CHOLMOD_SUPERNODAL;
  common_->final_ll = 0;
  common_->nmethods = 1;
  common_->method[0].ordering = solves == Solves::One ? CHOLMOD_AMD : CHOLMOD_METIS;
  Sparse lower = K_.triangularView<Eigen::Lower>();
  cholmod_sparse A = Eigen::viewAsCholmod(lower);
  A.stype = -1;
  symbolic_ = cholmod_analyze(&A, common_);
  if (symbolic_ == nullptr) {  // a CHOLMOD built without METIS: its default orderings
    common_->nmethods = 0;
    symbolic_ = cholmod_analyze(&A, common_);
  }
  if (symbolic_ == nullptr) throw SolverError("deformation transfer: Poisson analysis failed");
  const int* perm = static_cast<const int*>(symbolic_->Perm);
  order_.assign(perm, perm + K_.rows());
  for (int k = 0; k < static_cast<int>(K_.rows()); ++k) position_[perm[k]] = k;
}

AnchoredPoisson::~AnchoredPoisson() {
  cholmod_free_factor(&factor_, common_);
  cholmod_free_factor(&symbolic_, common_);
  cholmod_finish(common_);
  delete common_;
}

void AnchoredPoisson::factorize() {
  cholmod_free_factor(&factor_, common_);
  factor_ = cholmod_copy_factor(symbolic_, common_);
  {  // K's lower triangle, the anchors' rows and columns made identity
    Sparse lower = K_.triangularView<Eigen::Lower>();
    for (int col = 0; col < lower.outerSize(); ++col) {
      for (Sparse::InnerIterator it(lower, col); it; ++it) {
        if (anchored_[col] || anchored_[it.row()]) it.valueRef() = it.row() == col ? 1.0 : 0.0;
      }
    }
    cholmod_sparse view = Eigen::viewAsCholmod(lower);
    view.stype = -1;
    cholmod_factorize(&view, factor_, common_);
  }
  if (common_->status != CHOLMOD_OK || factor_->minor < factor_->n) {
    throw SolverError("deformation transfer: the Poisson system is singular");
  }
}

// Puts row and column `vertex` of K back (restricted to the vertices not anchored now).
void AnchoredPoisson::release(int vertex) {
  anchored_[vertex] = 0;
  std::vector<std::pair<int, double>> entries;
  for (Sparse::InnerIterator it(K_, vertex); it; ++it) {
    if (!anchored_[it.row()]) entries.emplace_back(position_[it.row()], it.value());
  }
  std::sort(entries.begin(), entries.end());
  cholmod_sparse* R =
      cholmod_allocate_sparse(K_.rows(), 1, entries.size(), 1, 1, 0, CHOLMOD_REAL, common_);
  int* p = static_cast<int*>(R->p);
  int* i = static_cast<int*>(R->i);
  double* x = static_cast<double*>(R->x);
  p[0] = 0;
  p[1] = static_cast<int>(entries.size());
  for (size_t e = 0; e < entries.size(); ++e) {
    i[e] = entries[e].first;
    x[e] = entries[e].second;
  }
  cholmod_rowadd(position_[vertex], R, factor_, common_);
  cholmod_free_sparse(&R, common_);
}

void AnchoredPoisson::set_anchors(const std::vector<int>& anchors) {
  std::vector<char> next(K_.rows(), 0);
  for (const int v : anchors) next[v] = 1;
  std::vector<int> add, remove;
  for (int v = 0; v < static_cast<int>(K_.rows()); ++v) {
    if (next[v] && !anchored_[v]) add.push_back(v);
    if (!next[v] && anchored_[v]) remove.push_back(v);
  }
  // A row update costs about 5 ms at 692k vertices, the whole factorisation 2 s: refactor from
  // scratch beyond max(16, n / 2000) changes (measured, the editor's paint stroke of 1,355
  // vertices: 6.6 s by updates).
  const Eigen::Index changes = static_cast<Eigen::Index>(add.size() + remove.size());
  if (!factored_ || solves_ == Solves::One ||
      changes > std::max<Eigen::Index>(16, K_.rows() / 2000)) {
    anchored_ = std::move(next);
    factorize();
    factored_ = true;
    if (solves_ == Solves::Many) solver_.assign(factor_);
    return;
  }
  if (factor_->is_super) {  // both forms held for a moment
    cholmod_change_factor(CHOLMOD_REAL, false, false, true, true, factor_, common_);
    if (common_->status != CHOLMOD_OK) {
      throw SolverError("deformation transfer: converting the Poisson factorisation failed");
    }
  }
  for (const int v : add) {
    cholmod_rowdel(position_[v], nullptr, factor_, common_);
    anchored_[v] = 1;
  }
  for (const int v : remove) release(v);
  if (common_->status != CHOLMOD_OK) {
    throw SolverError("deformation transfer: updating the Poisson factorisation failed");
  }
  solver_.assign(factor_);
}

int AnchoredPoisson::workspace_rows() const {
  return solves_ == Solves::One ? static_cast<int>(K_.rows()) : solver_.workspace_rows();
}

void AnchoredPoisson::solve_in_place(double* x) const {
  if (solves_ == Solves::Many) return solver_.solve_in_place(x, 3);
  // CHOLMOD's solve with L alone (the right-hand side is in the factor's order already).
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
  Eigen::Map<RowMajor> rows(x, K_.rows(), 3);
  Eigen::MatrixX3d columns = rows;
  cholmod_dense b = Eigen::viewAsCholmod(columns);
  cholmod_dense* solved = cholmod_solve(CHOLMOD_LDLt, factor_, &b, common_);
  if (solved == nullptr) throw SolverError("deformation transfer: the Poisson solve failed");
  rows = Eigen::Map<const Eigen::MatrixX3d>(static_cast<const double*>(solved->x), K_.rows(), 3);
  cholmod_free_dense(&solved, common_);
}

}  // namespace specdeform::detail
