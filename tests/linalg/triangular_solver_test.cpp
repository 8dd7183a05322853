#include "linalg/triangular_solver.h"

#include <cholmod.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include <Eigen/CholmodSupport>

#include "specdeform/mesh/generate.h"
#include "specdeform/operators/cotan_laplacian.h"
#include "specdeform/operators/mass_matrix.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

using Sparse = Eigen::SparseMatrix<double>;

// K + M / 10 of a mesh: symmetric positive definite, with K's sparsity.
Sparse shifted_laplacian(const TriangleMesh& mesh) {
  return cotan_stiffness(mesh) + 0.1 * mass_matrix(mesh, MassType::Lumped);
}

// The forms of CHOLMOD factorisation the solver reads.
enum class Form { Supernodal, SimplicialLDL, SimplicialLL };

// A CHOLMOD factorisation of A, in the form the test asks for.
class Factorization {
 public:
  Factorization(const Sparse& A, Form form) : lower_(A.triangularView<Eigen::Lower>()) {
    cholmod_start(&common_);
    common_.supernodal = form == Form::Supernodal ? CHOLMOD_SUPERNODAL : CHOLMOD_SIMPLICIAL;
    common_.final_ll = form == Form::SimplicialLL;
    cholmod_sparse view = Eigen::viewAsCholmod(lower_);
    view.stype = -1;
    factor_ = cholmod_analyze(&view, &common_);
    cholmod_factorize(&view, factor_, &common_);
  }
  ~Factorization() {
    cholmod_free_factor(&factor_, &common_);
    cholmod_finish(&common_);
  }
  detail::TriangularSolver solver() { return detail::TriangularSolver(factor_); }

 private:
  Sparse lower_;
  cholmod_common common_;
  cholmod_factor* factor_ = nullptr;
};

double relative_residual(const Sparse& A, const Eigen::MatrixXd& X, const Eigen::MatrixXd& B) {
  return (A * X - B).norm() / B.norm();
}

Eigen::MatrixXd random_block(Eigen::Index rows, Eigen::Index cols) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd B(rows, cols);
  for (Eigen::Index i = 0; i < B.size(); ++i) B.data()[i] = normal(rng);
  return B;
}

TEST(TriangularSolver, SolvesOnTwoThreadsWithAnySupernodalOrSimplicialFactor) {
  BumpyBarOptions o;
  o.cells_per_unit = 40;  // ~27k vertices: large enough for the two-thread split
  const Sparse A = shifted_laplacian(make_bumpy_bar(o));
  for (const Form form : {Form::Supernodal, Form::SimplicialLDL, Form::SimplicialLL}) {
    Factorization factorization(A, form);
    const detail::TriangularSolver solver = factorization.solver();
    EXPECT_GT(solver.separator_share(), 0.0) << "expected the two-thread split";
    EXPECT_LT(solver.separator_share(), 0.25);
    for (const int columns : {1, 2, 3, 4, 5, 6, 7, 8, 11}) {  // 11: a block of 8, then one of 3
      const Eigen::MatrixXd B = random_block(A.rows(), columns);
      EXPECT_LT(relative_residual(A, solver.solve(B), B), 1e-12)
          << "form " << static_cast<int>(form) << ", " << columns << " columns";
    }
  }
}

TEST(TriangularSolver, SolvesAnIndefiniteSystem) {
  // K - sigma M with sigma between eigenvalues: D has negative entries (simplicial LDL^T).
  BumpyBarOptions o;
  o.cells_per_unit = 30;
  const TriangleMesh bar = make_bumpy_bar(o);
  const Sparse M = mass_matrix(bar, MassType::Lumped);
  const Sparse A = cotan_stiffness(bar) - 37.3 / M.sum() * M;
  Factorization factorization(A, Form::SimplicialLDL);
  const detail::TriangularSolver solver = factorization.solver();
  const Eigen::MatrixXd B = random_block(A.rows(), 8);
  EXPECT_LT(relative_residual(A, solver.solve(B), B), 1e-9);
}

TEST(TriangularSolver, SolvesOverTheCorpusIncludingSeveralComponents) {
  for (const auto& entry : test::corpus()) {
    const Sparse A = shifted_laplacian(entry.mesh);
    for (const Form form : {Form::Supernodal, Form::SimplicialLDL}) {
      Factorization factorization(A, form);
      const detail::TriangularSolver solver = factorization.solver();
      const Eigen::MatrixXd B = random_block(A.rows(), 3);
      EXPECT_LT(relative_residual(A, solver.solve(B), B), 1e-10)
          << entry.name << ", form " << static_cast<int>(form);
    }
  }
  // Two large components: a forest of two trees, split between the threads.
  BumpyBarOptions o;
  o.cells_per_unit = 30;
  const TriangleMesh bar = make_bumpy_bar(o);
  const Sparse A = shifted_laplacian(test::concatenate(bar, bar));
  Factorization factorization(A, Form::SimplicialLDL);
  const detail::TriangularSolver solver = factorization.solver();
  const Eigen::MatrixXd B = random_block(A.rows(), 3);
  EXPECT_LT(relative_residual(A, solver.solve(B), B), 1e-12);
}

TEST(TriangularSolver, SolveInPlaceWorksInTheFactorsOrder) {
  const Sparse A = shifted_laplacian(make_icosphere(3));
  Factorization factorization(A, Form::SimplicialLDL);
  const detail::TriangularSolver solver = factorization.solver();
  const Eigen::MatrixXd B = random_block(A.rows(), 2);
  Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor> x(solver.workspace_rows(), 2);
  for (int k = 0; k < A.rows(); ++k) x.row(k) = B.row(solver.order()[k]);
  solver.solve_in_place(x.data(), 2);
  Eigen::MatrixXd X(A.rows(), 2);
  for (int k = 0; k < A.rows(); ++k) X.row(solver.order()[k]) = x.row(k);
  EXPECT_LT(relative_residual(A, X, B), 1e-12);
}

}  // namespace
}  // namespace specdeform
