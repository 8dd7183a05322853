#include "specdeform/operators/mollification.h"

#include <gtest/gtest.h>

#include "operators/sliver_meshes.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/operators/cotan_laplacian.h"
#include "specdeform/operators/intrinsic_delaunay.h"
#include "specdeform/operators/laplacian.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

using Sparse = Eigen::SparseMatrix<double>;

// A grid whose every other cell has a vertex on its diagonal, touched by one zero-area face and
// the two halves of the cell: T-junctions and zero-area vertices, as room scenes have them.
TriangleMesh t_junctions(int n) {
  TriangleMesh grid = test::skewed_grid(n, n, 1.0, 1.0, 0, 0.0);
  const int faces = grid.num_faces();
  for (int f = 0; f < faces; f += 4) {
    const int a = grid.F(f, 0), b = grid.F(f, 1), c = grid.F(f, 2);
    const int q = grid.num_vertices();
    grid.V.conservativeResize(q + 1, 3);
    grid.V.row(q) = 0.5 * (grid.V.row(a) + grid.V.row(b));
    grid.F.row(f) << a, q, c;
    grid.F.conservativeResize(grid.num_faces() + 2, 3);
    grid.F.row(grid.num_faces() - 2) << q, b, c;
    grid.F.row(grid.num_faces() - 1) << a, b, q;  // zero area
  }
  return grid;
}

// Clean meshes need no mollification: their operators are their positions', bit for bit.
TEST(Mollification, NoneOnCleanMeshes) {
  for (const auto& c : test::corpus()) {
    if (c.category == test::Category::Awkward) continue;
    EXPECT_EQ(mollification(c.mesh), 0.0) << c.name;
    EXPECT_EQ(
        Sparse(stiffness_matrix(c.mesh, LaplacianType::Cotan) - cotan_stiffness(c.mesh)).norm(),
        0.0)
        << c.name;
  }
}

// Mollified, every triangle meets its inequalities by the margin, the stiffness is finite and
// positive semidefinite, and every vertex has an area; eps is the smallest that does it.
TEST(Mollification, EveryTriangleMeetsTheMargin) {
  const MollificationPolicy policy;
  std::vector<TriangleMesh> meshes = {t_junctions(8)};
  for (const test::MessyMesh& m : test::messy()) meshes.push_back(m.mesh);
  for (const TriangleMesh& mesh : meshes) {
    const double eps = mollification(mesh, policy);
    ASSERT_GT(eps, 0.0);
    const auto length = mollified_lengths(mesh, eps);
    const double delta = policy.margin * mollified_lengths(mesh, 0.0).mean();
    double slack = 1e300;
    for (int t = 0; t < length.rows(); ++t)
      for (int c = 0; c < 3; ++c)
        slack = std::min(slack, length(t, c) + length(t, (c + 1) % 3) - length(t, (c + 2) % 3));
    EXPECT_NEAR(slack, delta, 1e-9 * delta);
    const LaplacianOperators L = laplacian_operators(mesh, MassType::Lumped, LaplacianType::Cotan);
    EXPECT_TRUE(Eigen::MatrixXd(L.stiffness).allFinite());
    EXPECT_GT(L.mass.diagonal().minCoeff(), 0.0);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Eigen::MatrixXd(L.stiffness));
    EXPECT_GT(eig.eigenvalues().minCoeff(), -1e-9 * eig.eigenvalues().maxCoeff());
  }
  EXPECT_THROW(MollificationPolicy{0.0}.validate(), InputError);
}

// A zero-length edge (two vertices at one place, both used) gets the margin's length.
TEST(Mollification, ZeroLengthEdge) {
  TriangleMesh mesh;
  mesh.V.resize(4, 3);
  mesh.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0;
  mesh.F.resize(2, 3);
  mesh.F << 0, 1, 2, 0, 2, 3;
  const double eps = mollification(mesh);
  EXPECT_GT(eps, 0.0);
  EXPECT_GT(vertex_areas(mesh).minCoeff(), 0.0);
}

// The intrinsic Delaunay flips end on a mesh of T-junctions (before mollification their flat
// triangles flipped on and on), and its operators keep the contract.
TEST(Mollification, IntrinsicDelaunayEndsOnTJunctions) {
  const TriangleMesh mesh = t_junctions(12);
  const IntrinsicTriangulation tri = intrinsic_delaunay(mesh);
  EXPECT_LT(tri.flips, 10LL * mesh.num_faces());
  const Sparse K = stiffness_matrix(tri);
  EXPECT_LT((K * Eigen::VectorXd::Ones(mesh.num_vertices())).cwiseAbs().maxCoeff(),
            1e-10 * K.norm());
  EXPECT_GT(mass_matrix(tri, MassType::Lumped).diagonal().minCoeff(), 0.0);
}

}  // namespace
}  // namespace specdeform
