// Internal: the Poisson system of deformation transfer with its anchors, K_anchored x = b, K the
// cotangent stiffness of the detailed mesh and the anchors' rows and columns made identity.
//
// A simplicial LDL^T factorisation (CHOLMOD). When the anchor set changes, newly anchored
// vertices are removed with cholmod_rowdel and released ones put back with cholmod_rowadd (a
// rank-2 update each), so a selection change costs in proportion to its difference; a change of
// more than a quarter of the vertices is refactored from scratch.
#pragma once

#include <vector>

#include <Eigen/Sparse>

struct cholmod_common_struct;
struct cholmod_factor_struct;

namespace specdeform::detail {

class AnchoredPoisson {
 public:
  explicit AnchoredPoisson(const Eigen::SparseMatrix<double>& K);
  ~AnchoredPoisson();
  AnchoredPoisson(const AnchoredPoisson&) = delete;
  AnchoredPoisson& operator=(const AnchoredPoisson&) = delete;

  // Throws SolverError if the system is singular (a component without anchors).
  void set_anchors(const std::vector<int>& anchors);

  Eigen::MatrixX3d solve(const Eigen::MatrixX3d& rhs) const;

 private:
  void factorize();
  void release(int vertex);
  Eigen::SparseMatrix<double> K_;
  std::vector<char> anchored_;
  std::vector<int> position_;  // vertex -> its row in the permuted factor
  cholmod_common_struct* common_;
  cholmod_factor_struct* factor_ = nullptr;
  bool factored_ = false;
};

}  // namespace specdeform::detail
