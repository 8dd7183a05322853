#include "specdeform/operators/cotan_laplacian.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "specdeform/mesh/generate.h"
#include "specdeform/operators/mass_matrix.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

using Sparse = Eigen::SparseMatrix<double>;

TEST(CotanStiffness, SymmetricPositiveSemidefiniteWithConstantKernel) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  for (const auto& c : test::corpus()) {
    const Sparse K = cotan_stiffness(c.mesh);
    const int n = c.mesh.num_vertices();
    EXPECT_LT(Sparse(K - Sparse(K.transpose())).norm(), 1e-12 * K.norm()) << c.name;
    EXPECT_LT((K * Eigen::VectorXd::Ones(n)).cwiseAbs().maxCoeff(), 1e-10) << c.name;
    for (int trial = 0; trial < 5; ++trial) {
      Eigen::VectorXd x(n);
      for (int i = 0; i < n; ++i) x[i] = normal(rng);
      EXPECT_GE(x.dot(K * x), -1e-10 * x.squaredNorm() * K.norm()) << c.name;
    }
    for (int k = 0; k < K.outerSize(); ++k)
      for (Sparse::InnerIterator it(K, k); it; ++it) EXPECT_TRUE(std::isfinite(it.value()));
  }
}

// The assembly by counting against the textbook one (four triplets per corner of each sound face):
// the same entries, explicit zeros of right angles included, no entry from a degenerate face and
// none for a vertex without a sound face.
TEST(CotanStiffness, EqualsTheTripletAssembly) {
  for (const auto& c : test::corpus()) {
    const TriangleMesh& mesh = c.mesh;
    std::vector<Eigen::Triplet<double>> triplets;
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const Eigen::Vector3d p[3] = {mesh.V.row(mesh.F(f, 0)), mesh.V.row(mesh.F(f, 1)),
                                    mesh.V.row(mesh.F(f, 2))};
      if (is_degenerate_triangle(p[0], p[1], p[2])) continue;
      const double double_area = (p[1] - p[0]).cross(p[2] - p[0]).norm();
      for (int k = 0; k < 3; ++k) {
        const int i = mesh.F(f, (k + 1) % 3), j = mesh.F(f, (k + 2) % 3);
        const double w = 0.5 * (p[(k + 1) % 3] - p[k]).dot(p[(k + 2) % 3] - p[k]) / double_area;
        triplets.insert(triplets.end(), {{i, j, -w}, {j, i, -w}, {i, i, w}, {j, j, w}});
      }
    }
    Sparse expected(mesh.num_vertices(), mesh.num_vertices());
    expected.setFromTriplets(triplets.begin(), triplets.end());
    const Sparse K = cotan_stiffness(mesh);
    ASSERT_EQ(K.nonZeros(), expected.nonZeros()) << c.name;
    EXPECT_TRUE(
        std::equal(K.outerIndexPtr(), K.outerIndexPtr() + K.cols() + 1, expected.outerIndexPtr()))
        << c.name;
    EXPECT_TRUE(
        std::equal(K.innerIndexPtr(), K.innerIndexPtr() + K.nonZeros(), expected.innerIndexPtr()))
        << c.name;
    EXPECT_EQ(Sparse(K - expected).norm(), 0.0) << c.name;
  }
}

TEST(CotanStiffness, EqualsGradientTransposeAreaGradient) {
  for (const auto& c : test::corpus()) {
    const Sparse K = cotan_stiffness(c.mesh);
    const Sparse G = gradient_operator(c.mesh);
    Eigen::VectorXd d(3 * c.mesh.num_faces());
    const Eigen::VectorXd areas = face_areas(c.mesh);
    for (int f = 0; f < c.mesh.num_faces(); ++f) d.segment<3>(3 * f).setConstant(areas[f]);
    const Sparse GtDG = G.transpose() * d.asDiagonal() * G;
    if (c.category == test::Category::Awkward) continue;  // the sliver is in D but not in K
    EXPECT_LT(Sparse(K - GtDG).norm(), 1e-10 * K.norm()) << c.name;
  }
}

TEST(CotanStiffness, LinearPrecisionOnAPlane) {
  // The Dirichlet energy of f = a x + b y on a flat square of area 4 is |(a, b)|^2 * 4, and
  // K f vanishes at interior vertices (the discrete Laplacian of a linear function).
  const TriangleMesh plane = make_bumpy_plane({2.0, 12, 1, 0.0});
  const Sparse K = cotan_stiffness(plane);
  const Eigen::VectorXd f = 0.3 * plane.V.col(0) - 1.7 * plane.V.col(1);
  EXPECT_NEAR(f.dot(K * f), (0.09 + 2.89) * 4.0, 1e-10);
  const Eigen::VectorXd Kf = K * f;
  for (int i = 0; i < plane.num_vertices(); ++i) {
    const double x = plane.V(i, 0), y = plane.V(i, 1);
    if (x > 0 && x < 2 && y > 0 && y < 2) EXPECT_NEAR(Kf[i], 0.0, 1e-12);
  }
  const Sparse G = gradient_operator(plane);
  const Eigen::VectorXd g = G * f;
  for (int t = 0; t < plane.num_faces(); ++t) {
    EXPECT_NEAR(g[3 * t], 0.3, 1e-12);
    EXPECT_NEAR(g[3 * t + 1], -1.7, 1e-12);
    EXPECT_NEAR(g[3 * t + 2], 0.0, 1e-12);
  }
}

TEST(CotanStiffness, ScaleInvariant) {
  TriangleMesh sphere = make_icosphere(2);
  const Sparse K1 = cotan_stiffness(sphere);
  sphere.V *= 17.0;
  EXPECT_LT(Sparse(K1 - cotan_stiffness(sphere)).norm(), 1e-12 * K1.norm());
}

}  // namespace
}  // namespace specdeform
