#include "specdeform/spectral/spectral_transform.h"

#include <gtest/gtest.h>

#include "specdeform/exceptions.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/operators/mass_matrix.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform {
namespace {

TEST(SpectralTransform, ForwardInverseAndFilters) {
  const TriangleMesh sphere = make_icosphere(3);
  ManifoldHarmonicsOptions o;
  o.num_modes = 16;
  const ManifoldHarmonics h = compute_manifold_harmonics(sphere, o);
  const auto M = mass_matrix(sphere, MassType::Lumped);
  // A signal inside the basis is reproduced exactly.
  const Eigen::MatrixXd X = h.basis.leftCols(4) * Eigen::MatrixXd::Random(4, 3);
  const Eigen::MatrixXd C = harmonics_forward(h.basis, M, X);
  EXPECT_LT((harmonics_inverse(h.basis, C) - X).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT(C.bottomRows(12).cwiseAbs().maxCoeff(), 1e-10);
  // The sphere's coordinates are l = 1 harmonics: 4 frequencies rebuild it (up to discretisation).
  const Eigen::MatrixXd low =
      harmonics_inverse(h.basis, harmonics_forward(h.basis, M, sphere.V), 4);
  EXPECT_LT((low - sphere.V).rowwise().norm().maxCoeff(), 0.02);
  // Gains: zero removes, one keeps, the residual gain restores what the basis misses.
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(16);
  const Eigen::MatrixXd Y = Eigen::MatrixXd::Random(sphere.num_vertices(), 3);
  EXPECT_LT((spectral_filter(h.basis, M, Y, ones, 1.0) - Y).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT(spectral_filter(h.basis, M, X, Eigen::VectorXd::Zero(16)).cwiseAbs().maxCoeff(), 1e-12);
  const Eigen::VectorXd g = band_gains(h.eigenvalues, {{1.0, 1.0}, {3.0, 0.5}});
  EXPECT_EQ(g[0], 1.0);
  EXPECT_EQ(g[1], 0.5);
  EXPECT_EQ(g[15], 1.0);
  EXPECT_THROW(harmonics_inverse(h.basis, C, 17), InputError);
  EXPECT_THROW(spectral_filter(h.basis, M, Y, Eigen::VectorXd::Ones(3)), InputError);
}

}  // namespace
}  // namespace specdeform
