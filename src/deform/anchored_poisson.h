// Internal: the Poisson system of deformation transfer with its anchors, K_anchored x = b, K the
// cotangent stiffness of the detailed mesh and the anchors' rows and columns made identity.
//
// An LDL^T factorisation (CHOLMOD) in a nested-dissection ordering (METIS): it keeps neighbours
// close in memory and splits the work evenly between two threads. Computed supernodal; at the
// first change of the anchor set that is updated rather than refactored it turns simplicial
// (both forms held for a moment: a solve needs neither, so a one-off solve never pays it).
// Newly anchored vertices are removed with cholmod_rowdel and released ones put back with
// cholmod_rowadd (a rank-2 update each), so a selection change costs in proportion to its
// difference; a change of more than max(16, n / 2000) vertices is refactored from scratch
// (cheaper than so many updates). Solves run on two threads (linalg/triangular_solver.h).
// For one solve (Solves::One) the ordering is AMD instead: it orders in a quarter of METIS's
// time for a factor of 1.6 times the entries, and one factorisation and one solve cost less in
// all (692k vertices: 2.9 against 5.1 s; 2.77M: 17.7 against 30.5 s); the factor is solved
// as it is, by CHOLMOD, with no copy for the two-thread solver.
#pragma once

#include <vector>

#include <Eigen/Sparse>

#include "linalg/triangular_solver.h"

struct cholmod_common_struct;
struct cholmod_factor_struct;

namespace specdeform::detail {

class AnchoredPoisson {
 public:
  enum class Solves { Many, One };  // One: one anchor set, solved once (see above)

  explicit AnchoredPoisson(const Eigen::SparseMatrix<double>& K, Solves solves = Solves::Many);
  ~AnchoredPoisson();
  AnchoredPoisson(const AnchoredPoisson&) = delete;
  AnchoredPoisson& operator=(const AnchoredPoisson&) = delete;

  // Throws SolverError if the system is singular (a component without anchors).
  void set_anchors(const std::vector<int>& anchors);

  const Eigen::SparseMatrix<double>& stiffness() const { return K_; }
  // The factor's ordering: its row k is vertex order()[k].
  const std::vector<int>& order() const { return order_; }
  // Solves in place, in the factor's ordering: see TriangularSolver::solve_in_place (width 3).
  int workspace_rows() const;
  void solve_in_place(double* x) const;

 private:
  void factorize();
  void release(int vertex);
  Solves solves_;
  Eigen::SparseMatrix<double> K_;
  std::vector<char> anchored_;
  std::vector<int> order_;     // the factor's row -> vertex
  std::vector<int> position_;  // vertex -> its row in the factor
  cholmod_common_struct* common_;
  cholmod_factor_struct* factor_ = nullptr;
  cholmod_factor_struct* symbolic_ = nullptr;  // the supernodal analysis, copied per factorisation
  bool factored_ = false;
  TriangularSolver solver_;
};

}  // namespace specdeform::detail
