#include "deform/reduced_forms.h"

#include <gtest/gtest.h>

#include "specdeform/mesh/generate.h"
#include "specdeform/operators/cotan_laplacian.h"
#include "specdeform/operators/mass_matrix.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform {
namespace {

// For exact manifold harmonics of K and the lumped mass the forms are Lambda and Lambda^2; for
// any other basis they are the plain products, formed here densely.
TEST(ReducedForms, EigenvaluesForEigenvectorsProductsForAnyBasis) {
  const TriangleMesh torus = make_torus(1.0, 0.35, 40, 16);
  const Eigen::SparseMatrix<double> K = cotan_stiffness(torus);
  const Eigen::VectorXd area = lumped_mass(torus);
  ManifoldHarmonicsOptions o;
  o.num_modes = 20;
  const ManifoldHarmonics h = compute_manifold_harmonics(torus, o);
  const detail::ReducedForms exact = detail::reduced_forms(K, area, h.basis, detail::Bending::Fine);
  const detail::ReducedForms mixed =
      detail::reduced_forms(K, area, h.basis, detail::Bending::Mixed);
  const Eigen::VectorXd l = h.eigenvalues;
  const double scale = l.maxCoeff();
  EXPECT_LT((exact.stiffness - Eigen::MatrixXd(l.asDiagonal())).cwiseAbs().maxCoeff(),
            1e-8 * scale);
  EXPECT_LT((exact.bending - Eigen::MatrixXd(l.cwiseAbs2().asDiagonal())).cwiseAbs().maxCoeff(),
            1e-7 * scale * scale);
  EXPECT_LT((mixed.bending - exact.bending).cwiseAbs().maxCoeff(), 1e-7 * scale * scale);

  const Eigen::MatrixXd U = h.basis + 0.1 * Eigen::MatrixXd::Random(h.basis.rows(), 20);
  const detail::ReducedForms forms = detail::reduced_forms(K, area, U, detail::Bending::Fine);
  const Eigen::MatrixXd KU = K * U;
  const Eigen::MatrixXd stiffness = U.transpose() * KU;
  const Eigen::MatrixXd bending = KU.transpose() * area.cwiseInverse().asDiagonal() * KU;
  EXPECT_LT((forms.stiffness - stiffness).cwiseAbs().maxCoeff(),
            1e-12 * stiffness.cwiseAbs().maxCoeff());
  EXPECT_LT((forms.bending - bending).cwiseAbs().maxCoeff(), 1e-12 * bending.cwiseAbs().maxCoeff());
  const Eigen::MatrixXd mixed_bending =
      detail::reduced_forms(K, area, U, detail::Bending::Mixed).bending;
  EXPECT_LT((mixed_bending - stiffness * stiffness).cwiseAbs().maxCoeff(),
            1e-12 * bending.cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace specdeform
