#include "deform/moving_basis.h"

#include <gtest/gtest.h>

#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/mesh_info.h"
#include "specdeform/operators/mass_matrix.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

// Ten spheres (642 vertices each) at m = 100 get 16 modes each; the solve of sphere 3 moved
// alone takes m = 100 modes, all on it, M-orthonormal, the first 100 harmonics of the sphere
// alone (eigenvalues to 1e-8); a sphere that had its share keeps its columns as they were.
TEST(MovingBasis, TheMovingPiecesTakeTheModes) {
  TriangleMesh mesh = make_icosphere(3);
  for (int k = 1; k < 10; ++k) {
    TriangleMesh next = make_icosphere(3);
    next.V.col(0).array() += 3.0 * k;
    mesh = test::concatenate(mesh, next);
  }
  const int per = 642;
  int count = 0;
  const Eigen::VectorXi label = vertex_components(mesh, &count);
  ASSERT_EQ(count, 10);
  const ManifoldHarmonics basis = compute_manifold_harmonics(mesh, {.num_modes = 100});
  ASSERT_EQ(basis.basis.cols(), 160);
  std::vector<int> piece_of_mode(basis.basis.cols());
  for (Eigen::Index j = 0; j < basis.basis.cols(); ++j) {
    Eigen::Index i;
    basis.basis.col(j).cwiseAbs().maxCoeff(&i);
    piece_of_mode[j] = label[i];
  }
  std::vector<char> moving(10, 0);
  moving[label[3 * per]] = 1;
  const auto H = detail::moving_basis(mesh, basis, label, piece_of_mode, moving);
  ASSERT_EQ(H->basis.cols(), 100);
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    if (v / per != 3) ASSERT_EQ(H->basis.row(v).cwiseAbs().maxCoeff(), 0.0) << v;
  }
  const Eigen::SparseMatrix<double> M = mass_matrix(mesh, basis.mass);
  const Eigen::MatrixXd gram = H->basis.transpose() * M * H->basis;
  EXPECT_LT((gram - Eigen::MatrixXd::Identity(100, 100)).cwiseAbs().maxCoeff(), 1e-10);
  const ManifoldHarmonics alone = compute_manifold_harmonics(make_icosphere(3), {.num_modes = 100});
  for (int j = 0; j < 100; ++j)
    EXPECT_NEAR(H->eigenvalues[j], alone.eigenvalues[j], 1e-8 * (1 + alone.eigenvalues[j])) << j;
  // All ten moving: each has its share (10 modes, at least 16), nothing solved again.
  const auto all =
      detail::moving_basis(mesh, basis, label, piece_of_mode, std::vector<char>(10, 1));
  EXPECT_EQ((all->basis - basis.basis).cwiseAbs().maxCoeff(), 0.0);
}

}  // namespace
}  // namespace specdeform
