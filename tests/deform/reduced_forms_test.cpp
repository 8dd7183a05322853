#include "deform/reduced_forms.h"

#include <gtest/gtest.h>

#include <Eigen/QR>

#include "specdeform/mesh/generate.h"
#include "specdeform/operators/cotan_laplacian.h"
#include "specdeform/operators/mass_matrix.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform {
namespace {

// For exact manifold harmonics of K and the lumped mass the forms are Lambda and Lambda^2, and
// the mixed bending equals the fine U^T K M^-1 K U; for any other basis they are the products.
TEST(ReducedForms, EigenvaluesForEigenvectorsProductsForAnyBasis) {
  const TriangleMesh torus = make_torus(1.0, 0.35, 40, 16);
  const Eigen::SparseMatrix<double> K = cotan_stiffness(torus);
  const Eigen::VectorXd area = lumped_mass(torus);
  ManifoldHarmonicsOptions o;
  o.num_modes = 20;
  const ManifoldHarmonics h = compute_manifold_harmonics(torus, o);
  const Eigen::VectorXd& l = h.eigenvalues;
  const double scale = l.maxCoeff();
  const Eigen::MatrixXd S = detail::reduced_stiffness(K, h.basis);
  EXPECT_LT((S - Eigen::MatrixXd(l.asDiagonal())).cwiseAbs().maxCoeff(), 1e-8 * scale);
  const Eigen::MatrixXd KH = K * h.basis;
  const Eigen::MatrixXd fine = KH.transpose() * area.cwiseInverse().asDiagonal() * KH;
  for (const bool orthonormal : {true, false}) {
    const Eigen::MatrixXd B = detail::reduced_bending(S, area, h.basis, orthonormal);
    EXPECT_LT((B - Eigen::MatrixXd(l.cwiseAbs2().asDiagonal())).cwiseAbs().maxCoeff(),
              1e-7 * scale * scale);
    EXPECT_LT((B - fine).cwiseAbs().maxCoeff(), 1e-7 * scale * scale);
  }

  const Eigen::MatrixXd U = h.basis + 0.1 * Eigen::MatrixXd::Random(h.basis.rows(), 20);
  const Eigen::MatrixXd expected = U.transpose() * (K * U);
  const Eigen::MatrixXd SU = detail::reduced_stiffness(K, U);
  EXPECT_LT((SU - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
  const Eigen::MatrixXd G = U.transpose() * area.asDiagonal() * U;
  const Eigen::MatrixXd bending = SU * G * SU;
  EXPECT_LT((detail::reduced_bending(SU, area, U, false) - bending).cwiseAbs().maxCoeff(),
            1e-12 * bending.cwiseAbs().maxCoeff());
}

// A multilevel basis is a Rayleigh-Ritz basis of K: its stiffness form is its eigenvalues, which
// the basis's flag lets the deformer take as they are.
TEST(ReducedForms, ARayleighRitzBasisHasItsEigenvaluesForStiffness) {
  const TriangleMesh sphere = make_icosphere(5);
  ManifoldHarmonicsOptions o;
  o.num_modes = 20;
  o.solver = EigenSolver::Multilevel;
  o.policy.multilevel_min_samples = 400;
  const ManifoldHarmonics h = compute_manifold_harmonics(sphere, o);
  ASSERT_TRUE(h.approximate);
  ASSERT_TRUE(h.rayleigh_ritz);
  const Eigen::SparseMatrix<double> K = cotan_stiffness(sphere);
  const Eigen::MatrixXd product = detail::reduced_stiffness(K, h.basis);
  const Eigen::MatrixXd taken = detail::reduced_stiffness(K, h);
  EXPECT_LT((taken - product).cwiseAbs().maxCoeff(), 1e-9 * h.eigenvalues.maxCoeff());
  ManifoldHarmonics turned = h;
  turned.rayleigh_ritz = false;
  turned.basis =
      h.basis *
      Eigen::MatrixXd(
          Eigen::HouseholderQR<Eigen::MatrixXd>(Eigen::MatrixXd::Random(20, 20)).householderQ());
  EXPECT_GT((detail::reduced_stiffness(K, turned) - taken).cwiseAbs().maxCoeff(),
            1e-3 * h.eigenvalues.maxCoeff());
}

}  // namespace
}  // namespace specdeform
