// Internal: solves A X = B with a sparse Cholesky factorisation from CHOLMOD,
//     P A P^T = L D L^T   (L unit lower triangular, D diagonal, P the fill-reducing ordering),
// by forward and back substitution, faster than cholmod_solve for the many small solves of this
// library (a deformation frame: 3 right-hand sides; a Krylov block: 8):
//  - the right-hand sides are interleaved, one row of up to 8 values per unknown (a cache line),
//    so that each entry of L is loaded once for all of them;
//  - the elimination tree is cut into two forests of about equal work, solved on two threads,
//    and the separator above them, solved on one. Each thread accumulates its updates of the
//    separator's rows in rows of its own, so the two never write the same memory.
// The factor is copied (its explicit zeros dropped); later changes to it are not seen.
#pragma once

#include <vector>

#include <Eigen/Core>

struct cholmod_common_struct;
struct cholmod_factor_struct;

namespace specdeform::detail {

class TriangularSolver {
 public:
  TriangularSolver() = default;
  // `factor`: numeric, simplicial or supernodal, LL^T or LDL^T. A supernodal factor is first
  // converted, in place, to a simplicial LDL^T one (cholmod_change_factor).
  TriangularSolver(cholmod_factor_struct* factor, cholmod_common_struct* common);
  // The same for a new factor, reusing this solver's memory.
  void assign(cholmod_factor_struct* factor, cholmod_common_struct* common);

  // A^-1 B for B n x k, any k.
  Eigen::MatrixXd solve(const Eigen::Ref<const Eigen::MatrixXd>& B) const;
  // The same into X, with scratch memory `workspace`: neither is reallocated when its size fits.
  void solve(const Eigen::Ref<const Eigen::MatrixXd>& B, Eigen::MatrixXd& X,
             std::vector<double>& workspace) const;

  // In place, without the permutation: x is row-major, workspace_rows() x width (1 to 8), and
  // its first n rows hold the right-hand side in the factor's order (row k: unknown order()[k])
  // and get the solution; the rows below are scratch.
  void solve_in_place(double* x, int width) const;
  int workspace_rows() const { return n_ + 2 * slots_; }
  const std::vector<int>& order() const { return order_; }

  // Share of the factor's entries in the separator, solved on one thread (0 when the whole
  // factor is solved on one thread).
  double separator_share() const { return separator_share_; }

 private:
  void copy(const cholmod_factor_struct* factor, bool parallel);

  int n_ = 0;
  std::vector<int> order_;            // factor row k is unknown order_[k]
  std::vector<double> inv_diagonal_;  // 1 / D
  std::vector<int> start_;            // L by columns (diagonal excluded): entries start_[j] ...
  std::vector<int> row_;              // ... start_[j + 1] - 1; rows of the separator are remapped
  std::vector<double> value_;         // into each thread's copy of them: n + t * slots_ + slot
  std::vector<int> forest_[2];        // each thread's columns, ascending
  std::vector<int> separator_;        // separator columns, ascending; slot s is separator_[s]
  int slots_ = 0;
  double separator_share_ = 0.0;
};

}  // namespace specdeform::detail
