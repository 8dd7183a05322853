#include "triangular_solver.h"

#include <cholmod.h>

#include <algorithm>
#include <barrier>
#include <cmath>
#include <queue>
#include <utility>

#include "parallel.h"
#include "specdeform/exceptions.h"

namespace specdeform::detail {

namespace {

// Below this many entries of L one thread solves everything: a thread start costs more than
// the parallel work saves.
constexpr long kParallelEntries = 150'000;
// Subtrees are split while one holds more than this share of the work, as long as the
// separator stays below its cap.
constexpr double kLargestShare = 0.2;
constexpr double kSeparatorCap = 0.25;
constexpr int kMaxWidth = 8;

struct Columns {
  const int* start;
  const int* row;
  const double* value;
  const double* inv_diagonal;
};

// L y = b over `columns` (ascending): column j's update of the rows below it.
template <int W>
[[gnu::always_inline]] inline void forward(const Columns& L, const std::vector<int>& columns,
                                           double* x) {
  for (const int j : columns) {
    double xj[W];
    for (int k = 0; k < W; ++k) xj[k] = x[static_cast<size_t>(j) * W + k];
    for (int e = L.start[j]; e < L.start[j + 1]; ++e) {
      double* xi = x + static_cast<size_t>(L.row[e]) * W;
      const double l = L.value[e];
      for (int k = 0; k < W; ++k) xi[k] -= l * xj[k];
    }
  }
}

// D L^T x = y over `columns` (descending): x_j = y_j / D_j - sum_i L_ij x_i.
template <int W>
[[gnu::always_inline]] inline void backward(const Columns& L, const std::vector<int>& columns,
                                            double* x) {
  for (auto it = columns.rbegin(); it != columns.rend(); ++it) {
    const int j = *it;
    double s[W];
    for (int k = 0; k < W; ++k) s[k] = x[static_cast<size_t>(j) * W + k] * L.inv_diagonal[j];
    for (int e = L.start[j]; e < L.start[j + 1]; ++e) {
      const double* xi = x + static_cast<size_t>(L.row[e]) * W;
      const double l = L.value[e];
      for (int k = 0; k < W; ++k) s[k] -= l * xi[k];
    }
    for (int k = 0; k < W; ++k) x[static_cast<size_t>(j) * W + k] = s[k];
  }
}

// The kernel for the width, known at run time (1 to kMaxWidth).
template <bool Forward, int... W>
[[gnu::always_inline]] inline void dispatch(std::integer_sequence<int, W...>, const Columns& L,
                                            const std::vector<int>& columns, double* x, int width) {
  ((width == W + 1 ? (Forward ? forward<W + 1>(L, columns, x) : backward<W + 1>(L, columns, x))
                   : void()),
   ...);
}

// Compiled for AVX2 as well, chosen at run time: no -march flag is needed.
__attribute__((target_clones("avx2", "default"))) void forward_columns(
    const Columns& L, const std::vector<int>& columns, double* x, int width) {
  dispatch<true>(std::make_integer_sequence<int, kMaxWidth>(), L, columns, x, width);
}

__attribute__((target_clones("avx2", "default"))) void backward_columns(
    const Columns& L, const std::vector<int>& columns, double* x, int width) {
  dispatch<false>(std::make_integer_sequence<int, kMaxWidth>(), L, columns, x, width);
}

}  // namespace

TriangularSolver::TriangularSolver(cholmod_factor* factor, cholmod_common* common) {
  assign(factor, common);
}

void TriangularSolver::assign(cholmod_factor* factor, cholmod_common* common) {
  if (factor->is_super) {
    cholmod_change_factor(CHOLMOD_REAL, false, false, true, true, factor, common);
    if (common->status != CHOLMOD_OK || factor->is_super) {
      throw SolverError("converting the Cholesky factor failed (out of memory?)");
    }
  }
  if (factor->xtype != CHOLMOD_REAL || factor->itype != CHOLMOD_INT || factor->minor < factor->n) {
    throw SolverError("triangular solve: not a complete real factorisation");
  }
  copy(factor, true);
}

void TriangularSolver::copy(const cholmod_factor* factor, bool parallel) {
  n_ = static_cast<int>(factor->n);
  const int* Lp = static_cast<const int*>(factor->p);
  const int* Li = static_cast<const int*>(factor->i);
  const int* Lnz = static_cast<const int*>(factor->nz);
  const double* Lx = static_cast<const double*>(factor->x);
  const int* perm = static_cast<const int*>(factor->Perm);
  order_.assign(perm, perm + n_);

  // Copy L (unit diagonal, explicit zeros dropped) and 1 / D; parent[j] = the first row below
  // the diagonal in column j's stored pattern (the elimination tree).
  // The buffers keep their memory from one factor to the next (no page faults on reuse).
  std::vector<int> parent(n_, -1);
  inv_diagonal_.resize(n_);
  start_.resize(n_ + 1);
  row_.resize(factor->nzmax);
  value_.resize(factor->nzmax);
  int count = 0;
  for (int j = 0; j < n_; ++j) {
    const double diagonal = Lx[Lp[j]];
    const double d = factor->is_ll ? diagonal * diagonal : diagonal;
    if (!(d != 0.0 && std::isfinite(d))) throw SolverError("triangular solve: singular factor");
    inv_diagonal_[j] = 1.0 / d;
    const double scale = factor->is_ll ? 1.0 / diagonal : 1.0;
    start_[j] = count;
    for (int e = Lp[j] + 1; e < Lp[j] + Lnz[j]; ++e) {
      if (parent[j] < 0 || Li[e] < parent[j]) parent[j] = Li[e];
      if (Lx[e] == 0.0) continue;
      row_[count] = Li[e];
      value_[count++] = Lx[e] * scale;
    }
  }
  start_[n_] = count;
  row_.resize(count);
  value_.resize(count);
  for (auto& list : forest_) list.clear();
  separator_.clear();

  const auto serial_fallback = [&] {
    forest_[0].resize(n_);
    for (int j = 0; j < n_; ++j) forest_[0][j] = j;
    forest_[1].clear();
    separator_.clear();
    slots_ = 0;
    separator_share_ = 0.0;
  };
  const long total = static_cast<long>(row_.size()) + n_;
  if (!parallel || total < kParallelEntries) {
    serial_fallback();
    return;
  }

  // Split the largest subtree (moving its root into the separator) until no subtree holds much
  // of the work, then deal the subtrees to two threads, largest first, each to the lighter one.
  std::vector<long> subtree(n_, 0);
  std::vector<int> first_child(n_ + 1, 0), children(n_);  // children of j: CSR
  for (int j = 0; j < n_; ++j) {
    subtree[j] += 1 + start_[j + 1] - start_[j];
    if (parent[j] >= 0) {
      subtree[parent[j]] += subtree[j];
      ++first_child[parent[j] + 1];
    }
  }
  for (int j = 0; j < n_; ++j) first_child[j + 1] += first_child[j];
  {
    std::vector<int> next(first_child.begin(), first_child.end() - 1);
    for (int j = 0; j < n_; ++j)
      if (parent[j] >= 0) children[next[parent[j]]++] = j;
  }
  using Candidate = std::pair<long, int>;  // (subtree work, root)
  std::priority_queue<Candidate> candidates;
  for (int j = 0; j < n_; ++j)
    if (parent[j] < 0) candidates.emplace(subtree[j], j);
  std::vector<int> owner(n_, -1);  // thread, or 2: separator
  long separator_work = 0;
  while (!candidates.empty()) {
    const auto [work, root] = candidates.top();
    const long own = 1 + start_[root + 1] - start_[root];
    if (work <= kLargestShare * total || separator_work + own > kSeparatorCap * total) break;
    candidates.pop();
    owner[root] = 2;
    separator_work += own;
    for (int c = first_child[root]; c < first_child[root + 1]; ++c)
      candidates.emplace(subtree[children[c]], children[c]);
  }
  long load[2] = {0, 0};
  while (!candidates.empty()) {  // popped largest first
    const auto [work, root] = candidates.top();
    candidates.pop();
    const int t = load[0] <= load[1] ? 0 : 1;
    owner[root] = t;
    load[t] += work;
  }
  for (int j = n_ - 1; j >= 0; --j) {  // a parent comes after its children
    if (owner[j] < 0) owner[j] = owner[parent[j]];
  }
  for (int j = 0; j < n_; ++j) (owner[j] == 2 ? separator_ : forest_[owner[j]]).push_back(j);
  slots_ = static_cast<int>(separator_.size());
  std::vector<int> slot(n_, -1);
  for (int s = 0; s < slots_; ++s) slot[separator_[s]] = s;

  // Every entry of L lies on the path from its column to the root, so a forest's column reaches
  // only its own forest and the separator (checked all the same): its separator rows are
  // remapped to the thread's own copies.
  for (int j = 0; j < n_; ++j) {
    for (int e = start_[j]; e < start_[j + 1]; ++e) {
      const int i = row_[e];
      if (owner[i] == owner[j]) continue;
      if (owner[i] != 2) {  // not an elimination tree: redo the copy, for one thread
        copy(factor, false);
        return;
      }
      row_[e] = n_ + owner[j] * slots_ + slot[i];
    }
  }
  separator_share_ = static_cast<double>(separator_work) / total;
}

void TriangularSolver::solve_in_place(double* x, int width) const {
  if (width < 1 || width > kMaxWidth)
    throw InputError("triangular solve: 1 to 8 columns at a time");
  const Columns L{start_.data(), row_.data(), value_.data(), inv_diagonal_.data()};
  std::fill_n(x + static_cast<size_t>(n_) * width, static_cast<size_t>(2 * slots_) * width, 0.0);
  if (forest_[1].empty() && separator_.empty()) {
    forward_columns(L, forest_[0], x, width);
    backward_columns(L, forest_[0], x, width);
    return;
  }
  const auto row = [&](int i) { return x + static_cast<size_t>(i) * width; };
  std::barrier sync(2);
  const auto work = [&](int t) {
    forward_columns(L, forest_[t], x, width);
    sync.arrive_and_wait();
    if (t == 0) {
      for (int s = 0; s < slots_; ++s) {
        double* xs = row(separator_[s]);
        const double* a = row(n_ + s);
        const double* b = row(n_ + slots_ + s);
        for (int k = 0; k < width; ++k) xs[k] += a[k] + b[k];
      }
      forward_columns(L, separator_, x, width);
      backward_columns(L, separator_, x, width);
      for (int s = 0; s < slots_; ++s) {
        const double* xs = row(separator_[s]);
        std::copy(xs, xs + width, row(n_ + s));
        std::copy(xs, xs + width, row(n_ + slots_ + s));
      }
    }
    sync.arrive_and_wait();
    backward_columns(L, forest_[t], x, width);
  };
  run_pair([&] { work(0); }, [&] { work(1); });
}

Eigen::MatrixXd TriangularSolver::solve(const Eigen::Ref<const Eigen::MatrixXd>& B) const {
  Eigen::MatrixXd X;
  std::vector<double> workspace;
  solve(B, X, workspace);
  return X;
}

void TriangularSolver::solve(const Eigen::Ref<const Eigen::MatrixXd>& B, Eigen::MatrixXd& X,
                             std::vector<double>& x) const {
  if (B.rows() != n_) throw InputError("triangular solve: right-hand side of the wrong size");
  X.resize(n_, B.cols());
  for (Eigen::Index c0 = 0; c0 < B.cols(); c0 += kMaxWidth) {
    const int width = static_cast<int>(std::min<Eigen::Index>(kMaxWidth, B.cols() - c0));
    x.resize(static_cast<size_t>(workspace_rows()) * width);
    for (int k = 0; k < n_; ++k)
      for (int c = 0; c < width; ++c) x[static_cast<size_t>(k) * width + c] = B(order_[k], c0 + c);
    solve_in_place(x.data(), width);
    for (int k = 0; k < n_; ++k)
      for (int c = 0; c < width; ++c) X(order_[k], c0 + c) = x[static_cast<size_t>(k) * width + c];
  }
}

}  // namespace specdeform::detail
