// Internal: solves A X = B with a sparse Cholesky factorisation from CHOLMOD,
//     P A P^T = L D L^T   (L unit lower triangular, D diagonal, P the fill-reducing ordering),
// by forward and back substitution, faster than cholmod_solve for the many small solves of this
// library (a deformation frame: 3 right-hand sides; a Krylov block: 8):
//  - L is held by supernodes: runs of columns that share their rows below the diagonal block
//    (CHOLMOD's own for a supernodal factor; the fundamental ones of a simplicial factor), each
//    a dense row-major block. A row below is loaded once for the supernode's columns, and every
//    entry of L once for all right-hand sides;
//  - the right-hand sides are interleaved, one row of up to 8 values per unknown (a cache line);
//  - the elimination tree of the supernodes is cut into two forests of about equal work, solved
//    on two threads, and the separator above them, solved on one. Each thread accumulates its
//    updates of the separator's rows in rows of its own, so the two never write the same memory.
// The factor is copied (explicit zero rows of a supernode dropped); a supernodal factor is
// read as it is, not converted. Later changes to the factor are not seen.
#pragma once

#include <algorithm>
#include <vector>

#include <Eigen/Core>

#include "specdeform/exceptions.h"

struct cholmod_factor_struct;

namespace specdeform::detail {

// Columns first ... first + width - 1 of L (a supernode). Their values, from `values` on: the
// strict lower triangle of the diagonal block by rows (row i: i values), then one row of `width`
// values for each row below the block, rows `rows` ... `rows_end` - 1 of the row list.
struct Supernode {
  int first, width;
  int rows, rows_end;
  long values;
};

class TriangularSolver {
 public:
  static constexpr int kMaxWidth = 8;  // right-hand sides per solve_in_place

  TriangularSolver() = default;
  // `factor`: numeric, simplicial or supernodal, LL^T or LDL^T (left unchanged).
  explicit TriangularSolver(const cholmod_factor_struct* factor);
  // The same for a new factor, reusing this solver's memory.
  void assign(const cholmod_factor_struct* factor);

  // A^-1 B for B n x k, any k.
  Eigen::MatrixXd solve(const Eigen::Ref<const Eigen::MatrixXd>& B) const;
  // The same into X, with scratch memory `workspace`: neither is reallocated when its size fits.
  // Row-major B and X are faster for large n: the permutation then reads and writes whole rows.
  template <typename In, typename Out>
  void solve(const Eigen::MatrixBase<In>& B, Eigen::PlainObjectBase<Out>& X,
             std::vector<double>& workspace) const;

  // In place, without the permutation: x is row-major, workspace_rows() x width (1 to 8), and
  // its first n rows hold the right-hand side in the factor's order (row k: unknown order()[k])
  // and get the solution; the rows below are scratch.
  void solve_in_place(double* x, int width) const;
  int workspace_rows() const { return n_ + 2 * static_cast<int>(slot_column_.size()); }
  const std::vector<int>& order() const { return order_; }

  // Share of the factor's entries in the separator, solved on one thread (0 when the whole
  // factor is solved on one thread).
  double separator_share() const { return separator_share_; }

 private:
  // Each fills nodes_, row_, value_ and inv_diagonal_, and returns the supernodes' elimination
  // tree: the parent of each (-1: a root).
  std::vector<int> read_supernodal(const cholmod_factor_struct* factor);
  std::vector<int> read_simplicial(const cholmod_factor_struct* factor);
  void split(const std::vector<int>& parent, bool parallel);

  int n_ = 0;
  std::vector<int> order_;            // factor row k is unknown order_[k]
  std::vector<double> inv_diagonal_;  // 1 / D
  std::vector<Supernode> nodes_;      // ascending columns: a child before its parent
  std::vector<int> row_;              // rows of the separator are remapped into each thread's
  std::vector<double> value_;         // copy of them: n + t * slots + slot
  std::vector<int> forest_[2];        // each thread's supernodes, ascending
  std::vector<int> separator_;        // the separator's supernodes, ascending
  std::vector<int> slot_column_;      // slot s holds column slot_column_[s]
  double separator_share_ = 0.0;
};

template <typename In, typename Out>
void TriangularSolver::solve(const Eigen::MatrixBase<In>& B, Eigen::PlainObjectBase<Out>& X,
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
