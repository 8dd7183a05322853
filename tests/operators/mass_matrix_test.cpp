#include "specdeform/operators/mass_matrix.h"

#include <gtest/gtest.h>

#include "support/corpus.h"

namespace specdeform {
namespace {

using Sparse = Eigen::SparseMatrix<double>;

TEST(MassMatrix, SumsToTheAreaAndLumpsToRowSums) {
  for (const auto& c : test::corpus()) {
    const double area = surface_area(c.mesh);
    const Sparse lumped = mass_matrix(c.mesh, MassType::Lumped);
    const Sparse consistent = mass_matrix(c.mesh, MassType::Consistent);
    EXPECT_NEAR(lumped.sum(), area, 1e-12 * area) << c.name;
    EXPECT_NEAR(consistent.sum(), area, 1e-12 * area) << c.name;
    const Eigen::VectorXd rows = consistent * Eigen::VectorXd::Ones(c.mesh.num_vertices());
    EXPECT_LT((rows - Eigen::VectorXd(lumped.diagonal())).cwiseAbs().maxCoeff(), 1e-14 * area)
        << c.name;
    EXPECT_LT(Sparse(consistent - Sparse(consistent.transpose())).norm(), 1e-15) << c.name;
    EXPECT_EQ(lumped.nonZeros(), c.mesh.num_vertices()) << c.name;
    EXPECT_EQ(lumped_mass(c.mesh), Eigen::VectorXd(lumped.diagonal())) << c.name;
  }
}

TEST(MassMatrix, ConsistentMassIntegratesProducts) {
  // For linear functions f, g: f^T M g is the exact integral of f g over the surface.
  const auto& plane = test::corpus()[3].mesh;  // bumpy plane over [0,1]^2 (nearly flat)
  TriangleMesh flat = plane;
  flat.V.col(2).setZero();
  const Sparse M = mass_matrix(flat, MassType::Consistent);
  const Eigen::VectorXd x = flat.V.col(0), y = flat.V.col(1);
  EXPECT_NEAR(x.dot(M * x), 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(x.dot(M * y), 1.0 / 4.0, 1e-12);
}

}  // namespace
}  // namespace specdeform
