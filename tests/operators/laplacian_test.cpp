#include "specdeform/operators/laplacian.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "operators/sliver_meshes.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/operators/cotan_laplacian.h"
#include "specdeform/operators/mollification.h"
#include "specdeform/spectral/manifold_harmonics.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

using Sparse = Eigen::SparseMatrix<double>;
constexpr double kPi = std::numbers::pi;
constexpr LaplacianType kTypes[] = {LaplacianType::Cotan, LaplacianType::IntrinsicDelaunay};

double relative_difference(const Sparse& A, const Sparse& B) {
  return Sparse(A - B).norm() / std::max(A.norm(), 1e-300);
}

TEST(Laplacian, Names) {
  for (LaplacianType type : kTypes) EXPECT_EQ(laplacian_type_from_name(name(type)), type);
  EXPECT_EQ(name(LaplacianType::IntrinsicDelaunay), "intrinsic-delaunay");
  EXPECT_THROW(laplacian_type_from_name("delaunay"), InputError);
}

TEST(Laplacian, ContractOnEveryMesh) {
  std::vector<test::CorpusMesh> meshes = test::corpus();
  meshes.push_back({"slivers", test::Category::Boundary, test::skewed_grid(16, 8, 2, 1, 5, 0.05)});
  meshes.push_back({"book", test::Category::Awkward, test::book(3, 8, 3)});
  std::mt19937 rng(11);
  std::normal_distribution<double> normal;
  for (const auto& c : meshes) {
    const int n = c.mesh.num_vertices();
    const double area = surface_area(c.mesh);
    for (LaplacianType type : kTypes) {
      const std::string label = c.name + " " + std::string(name(type));
      const LaplacianOperators L = laplacian_operators(c.mesh, MassType::Consistent, type);
      const Sparse& K = L.stiffness;
      EXPECT_LT(Sparse(K - Sparse(K.transpose())).norm(), 1e-12 * K.norm()) << label;
      EXPECT_LT((K * Eigen::VectorXd::Ones(n)).cwiseAbs().maxCoeff(), 1e-10 * K.norm()) << label;
      for (int trial = 0; trial < 5; ++trial) {
        Eigen::VectorXd x(n);
        for (int i = 0; i < n; ++i) x[i] = normal(rng);
        EXPECT_GE(x.dot(K * x), -1e-10 * x.squaredNorm() * K.norm()) << label;
      }
      for (int k = 0; k < K.outerSize(); ++k)
        for (Sparse::InnerIterator it(K, k); it; ++it) ASSERT_TRUE(std::isfinite(it.value()));
      const Sparse lumped = mass_matrix(c.mesh, MassType::Lumped, type);
      // A mollified mesh's zero-area triangles gain a sliver of area (mollification.h).
      const double mollified = mollification(c.mesh) > 0.0 ? 1e-4 : 1e-12;
      EXPECT_NEAR(L.mass.sum(), area, mollified * area) << label;
      EXPECT_NEAR(lumped.sum(), area, mollified * area) << label;
      EXPECT_EQ(lumped.nonZeros(), n) << label;
      EXPECT_GT(lumped.diagonal().minCoeff(), 0.0) << label;  // no vertex without area
      const Eigen::VectorXd rows = L.mass * Eigen::VectorXd::Ones(n);
      EXPECT_LT((rows - Eigen::VectorXd(lumped.diagonal())).cwiseAbs().maxCoeff(), 1e-14 * area)
          << label;
      EXPECT_EQ(relative_difference(stiffness_matrix(c.mesh, type), K), 0.0) << label;
    }
  }
}

TEST(Laplacian, ScaleInvariantStiffness) {
  TriangleMesh mesh = test::skewed_grid(10, 10, 1, 1, 4, 0.05);
  const Sparse K = stiffness_matrix(mesh, LaplacianType::IntrinsicDelaunay);
  mesh.V *= 17.0;
  EXPECT_LT(relative_difference(stiffness_matrix(mesh, LaplacianType::IntrinsicDelaunay), K),
            1e-12);
}

TEST(Laplacian, EqualOnADelaunayMesh) {
  const TriangleMesh sphere = make_icosphere(3);
  EXPECT_LT(relative_difference(stiffness_matrix(sphere, LaplacianType::IntrinsicDelaunay),
                                cotan_stiffness(sphere)),
            1e-13);
  EXPECT_LT(
      relative_difference(mass_matrix(sphere, MassType::Lumped, LaplacianType::Cotan),
                          mass_matrix(sphere, MassType::Lumped, LaplacianType::IntrinsicDelaunay)),
      1e-13);
}

// The first m eigenvalues with the Laplacian `type`, and their relative errors against `exact`
// (the zero eigenvalue left out): median and max.
struct SpectrumError {
  double median = 0.0, max = 0.0;
};
SpectrumError spectrum_error(const TriangleMesh& mesh, LaplacianType type,
                             const std::vector<double>& exact) {
  ManifoldHarmonicsOptions o;
  o.num_modes = static_cast<int>(exact.size());
  o.laplacian = type;
  const ManifoldHarmonics h = compute_manifold_harmonics(mesh, o);
  EXPECT_EQ(h.status, SolveStatus::Converged);
  EXPECT_EQ(h.laplacian, type);
  EXPECT_NEAR(h.eigenvalues[0], 0.0, 1e-9);
  std::vector<double> errors;
  for (size_t i = 1; i < exact.size(); ++i)
    errors.push_back(std::abs(h.eigenvalues[i] - exact[i]) / exact[i]);
  std::sort(errors.begin(), errors.end());
  return {errors[errors.size() / 2], errors.back()};
}

// Free (Neumann) rectangle a x b: lambda = pi^2 (i^2 / a^2 + j^2 / b^2).
TEST(Laplacian, SliversOfAFlatRectangle) {
  std::vector<double> exact;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) exact.push_back(kPi * kPi * (i * i / 4.0 + j * j));
  std::sort(exact.begin(), exact.end());
  exact.resize(20);
  const TriangleMesh good = test::skewed_grid(32, 16, 2.0, 1.0, 0);
  const SpectrumError reference = spectrum_error(good, LaplacianType::Cotan, exact);
  EXPECT_LT(reference.max, 0.04);
  // The same vertices in slivers leaning 4 cells (angles up to ~166 degrees).
  const TriangleMesh bad = test::skewed_grid(32, 16, 2.0, 1.0, 4);
  const SpectrumError cotan = spectrum_error(bad, LaplacianType::Cotan, exact);
  const SpectrumError intrinsic = spectrum_error(bad, LaplacianType::IntrinsicDelaunay, exact);
  EXPECT_GT(cotan.median, 0.2);
  EXPECT_LT(intrinsic.max, reference.max * 1.01);
  EXPECT_LT(intrinsic.max, cotan.median / 10);
}

// A book of three unit pages: functions cos(j pi y) g(x), x the distance to the spine, either
// the same cos(k pi x) on every page, or cos((k + 1/2) pi x) with amplitudes summing to zero
// (multiplicity 2).
TEST(Laplacian, NonManifoldBookSpectrum) {
  std::vector<double> exact;
  for (int k = 0; k < 8; ++k) {
    for (int j = 0; j < 8; ++j) {
      exact.push_back(kPi * kPi * (k * k + j * j));
      const double half = (k + 0.5) * (k + 0.5) + j * j;
      exact.insert(exact.end(), 2, kPi * kPi * half);
    }
  }
  std::sort(exact.begin(), exact.end());
  exact.resize(16);
  const SpectrumError good = spectrum_error(test::book(3, 16, 0), LaplacianType::Cotan, exact);
  EXPECT_LT(good.max, 0.03);
  const TriangleMesh bad = test::book(3, 16, 4);
  const SpectrumError cotan = spectrum_error(bad, LaplacianType::Cotan, exact);
  const SpectrumError intrinsic = spectrum_error(bad, LaplacianType::IntrinsicDelaunay, exact);
  EXPECT_GT(cotan.median, 0.2);
  EXPECT_LT(intrinsic.max, good.max * 1.01);
}

}  // namespace
}  // namespace specdeform
