#include "specdeform/spectral/manifold_harmonics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "specdeform/exceptions.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/io.h"
#include "specdeform/operators/cotan_laplacian.h"
#include "specdeform/spectral/spectral_transform.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

constexpr double kPi = std::numbers::pi;

ManifoldHarmonics harmonics(const TriangleMesh& mesh, int m,
                            EigenSolver solver = EigenSolver::BlockKrylov,
                            MassType mass = MassType::Lumped) {
  ManifoldHarmonicsOptions o;
  o.num_modes = m;
  o.solver = solver;
  o.mass = mass;
  return compute_manifold_harmonics(mesh, o);
}

void expect_sound(const ManifoldHarmonics& h, const std::string& name) {
  EXPECT_EQ(h.status, SolveStatus::Converged) << name;
  EXPECT_LT(h.max_residual, 1e-8) << name;
  EXPECT_LT(h.max_orthogonality_error, 1e-8) << name;
  for (int i = 1; i < h.eigenvalues.size(); ++i) {
    EXPECT_LE(h.eigenvalues[i - 1], h.eigenvalues[i] + 1e-9 * std::abs(h.eigenvalues[i])) << name;
  }
}

// Unit sphere: lambda = l (l + 1) with multiplicity 2l + 1. Lumped mass lies slightly below.
TEST(ManifoldHarmonics, UnitSphereSpectrum) {
  const TriangleMesh sphere = make_icosphere(5);  // 10,242 vertices
  ASSERT_EQ(sphere.num_vertices(), 10242);
  const ManifoldHarmonics h = harmonics(sphere, 25);
  expect_sound(h, "icosphere5");
  int i = 0;
  for (int l = 0; l <= 4; ++l) {
    for (int k = 0; k < 2 * l + 1; ++k, ++i) {
      const double exact = l * (l + 1.0);
      if (l == 0) {
        EXPECT_NEAR(h.eigenvalues[i], 0.0, 1e-10);
      } else {
        EXPECT_NEAR(h.eigenvalues[i], exact, 0.005 * exact) << "l = " << l;
      }
    }
  }
  EXPECT_FALSE(h.cluster_truncated);  // 25 = 1 + 3 + 5 + 7 + 9 ends at a gap
  EXPECT_TRUE(harmonics(sphere, 5).cluster_truncated);
}

TEST(ManifoldHarmonics, ConsistentMassBoundsTheSphereFromAbove) {
  const TriangleMesh sphere = make_icosphere(4);
  const ManifoldHarmonics lumped = harmonics(sphere, 9);
  const ManifoldHarmonics consistent =
      harmonics(sphere, 9, EigenSolver::BlockKrylov, MassType::Consistent);
  expect_sound(consistent, "consistent");
  for (int i = 1; i < 9; ++i) {
    const double exact = i < 4 ? 2.0 : 6.0;
    EXPECT_LT(lumped.eigenvalues[i], exact);
    EXPECT_GT(consistent.eigenvalues[i], exact);
  }
}

// Flat square of side a with a free (Neumann) boundary: lambda = pi^2 (i^2 + j^2) / a^2.
TEST(ManifoldHarmonics, FreeSquareSpectrum) {
  const TriangleMesh square = make_bumpy_plane({2.0, 80, 1, 0.0});
  const ManifoldHarmonics h = harmonics(square, 20);
  expect_sound(h, "square");
  std::vector<double> exact;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) exact.push_back(kPi * kPi * (i * i + j * j) / 4.0);
  std::sort(exact.begin(), exact.end());
  for (int k = 1; k < 20; ++k) EXPECT_NEAR(h.eigenvalues[k], exact[k], 0.01 * exact[k]) << k;
}

TEST(ManifoldHarmonics, CorpusInvariants) {
  for (const auto& c : test::corpus()) {
    const int m = std::min(40, c.mesh.num_vertices() / 4);
    const ManifoldHarmonics h = harmonics(c.mesh, m);
    expect_sound(h, c.name);
    // One zero eigenvalue per connected component.
    const int zeros = static_cast<int>((h.eigenvalues.array().abs() < 1e-8).count());
    EXPECT_EQ(zeros, c.components) << c.name;
  }
}

// The first modes of larger meshes go through the iterative solvers (the corpus is small enough
// for the dense path); the two solvers and the band-by-band split must agree.
TEST(ManifoldHarmonics, SolversAndBandsAgree) {
  BumpyBarOptions o;
  o.cells_per_unit = 12;  // ~2,600 vertices
  TriangleMesh bar = make_bumpy_bar(o);
  // Jitter the vertices to break the bar's symmetries: simple eigenvalues, unique eigenvectors.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.01, 0.01);
  for (Eigen::Index i = 0; i < bar.V.size(); ++i) bar.V.data()[i] += jitter(rng);
  ASSERT_GT(bar.num_vertices(), 2000);
  const ManifoldHarmonics krylov = harmonics(bar, 120);
  const ManifoldHarmonics lanczos = harmonics(bar, 120, EigenSolver::Lanczos);
  ManifoldHarmonicsOptions banded;
  banded.num_modes = 120;
  banded.band_size = 30;
  const ManifoldHarmonics bands = compute_manifold_harmonics(bar, banded);
  expect_sound(krylov, "krylov");
  expect_sound(lanczos, "lanczos");
  expect_sound(bands, "bands");
  EXPECT_GT(bands.bands, 3);
  const double scale = krylov.eigenvalues[119];
  EXPECT_LT((krylov.eigenvalues - lanczos.eigenvalues).cwiseAbs().maxCoeff(), 1e-8 * scale);
  EXPECT_LT((krylov.eigenvalues - bands.eigenvalues).cwiseAbs().maxCoeff(), 1e-8 * scale);
  // Eigenvectors of simple eigenvalues agree up to the sign convention, i.e. exactly.
  for (int i = 0; i < 10; ++i) {
    EXPECT_LT((krylov.basis.col(i) - bands.basis.col(i)).cwiseAbs().maxCoeff(), 1e-6) << i;
  }
}

// Large meshes are solved in a breadth-first numbering (policy.reorder_from): the same pairs,
// in the mesh's numbering, for the exact and the multilevel solver.
TEST(ManifoldHarmonics, TheRenumberedSolveGivesTheSamePairs) {
  BumpyBarOptions bo;
  bo.cells_per_unit = 14;
  TriangleMesh bar = make_bumpy_bar(bo);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> jitter(-0.01, 0.01);
  for (Eigen::Index i = 0; i < bar.V.size(); ++i) bar.V.data()[i] += jitter(rng);
  for (const EigenSolver solver : {EigenSolver::BlockKrylov, EigenSolver::Multilevel}) {
    ManifoldHarmonicsOptions o;
    o.num_modes = 30;
    o.solver = solver;
    o.policy.multilevel_min_samples = 300;
    const ManifoldHarmonics plain = compute_manifold_harmonics(bar, o);
    o.policy.reorder_from = 0;
    const ManifoldHarmonics renumbered = compute_manifold_harmonics(bar, o);
    EXPECT_EQ(plain.approximate, solver == EigenSolver::Multilevel);
    EXPECT_LT((plain.eigenvalues - renumbered.eigenvalues).cwiseAbs().maxCoeff(),
              1e-9 * plain.eigenvalues[29]);
    EXPECT_LT((plain.basis - renumbered.basis).cwiseAbs().maxCoeff(), 1e-6);
    EXPECT_LT(renumbered.max_orthogonality_error, 1e-10);
  }
}

TEST(ManifoldHarmonics, FullBasisReconstructsTheMesh) {
  const TriangleMesh mesh = test::corpus()[2].mesh;  // bumpy bar, a few hundred vertices
  const int n = mesh.num_vertices();
  ASSERT_LT(n, 1500);
  const ManifoldHarmonics h = harmonics(mesh, n);
  expect_sound(h, "full");
  const auto M = mass_matrix(mesh, MassType::Lumped);
  const Eigen::MatrixXd back = harmonics_inverse(h.basis, harmonics_forward(h.basis, M, mesh.V));
  EXPECT_LT((back - mesh.V).cwiseAbs().maxCoeff(), 1e-9 * bounding_box_diagonal(mesh.V));
}

TEST(ManifoldHarmonics, DeterministicSigns) {
  const TriangleMesh torus = make_torus(1.0, 0.35, 60, 20);
  const ManifoldHarmonics a = harmonics(torus, 30), b = harmonics(torus, 30);
  EXPECT_EQ(a.eigenvalues, b.eigenvalues);
  EXPECT_EQ(a.basis, b.basis);
  for (int j = 0; j < 30; ++j) {
    Eigen::Index i;
    a.basis.col(j).cwiseAbs().maxCoeff(&i);
    EXPECT_GT(a.basis(i, j), 0.0);
  }
}

TEST(ManifoldHarmonics, ScaleCovariance) {
  TriangleMesh torus = make_torus(1.0, 0.35, 60, 20);
  const ManifoldHarmonics a = harmonics(torus, 12);
  torus.V *= 10.0;
  const ManifoldHarmonics b = harmonics(torus, 12);
  EXPECT_LT((a.eigenvalues - 100.0 * b.eigenvalues).cwiseAbs().maxCoeff(), 1e-8);
}

TEST(ManifoldHarmonics, RejectsBadArguments) {
  const TriangleMesh sphere = make_icosphere(1);
  EXPECT_THROW(harmonics(sphere, 0), InputError);
  EXPECT_THROW(harmonics(sphere, sphere.num_vertices() + 1), InputError);
  ManifoldHarmonicsOptions o;
  o.shift = 0.0;
  EXPECT_THROW(compute_manifold_harmonics(sphere, o), InputError);
}

// A vertex that only a zero-area face touches (q on an edge a-b) has an area once the lengths are
// mollified (operators/mollification.h): the basis converges, and each harmonic at q is the mean
// of its values at the edge's ends (Cotan: the mollified sliver's stiff edges tie q to them), or
// close to it (intrinsic Delaunay: q becomes a vertex of the surface's own triangles, its value
// the harmonic's there, 2% of its range from the chord's).
TEST(ManifoldHarmonics, AVertexOfZeroAreaFacesAloneFollowsItsEdge) {
  TriangleMesh lonely = make_icosphere(2);
  const int q = lonely.num_vertices();
  int a = -1, b = -1;
  for (int c = 0; c < 3 && a < 0; ++c) a = lonely.F(0, c), b = lonely.F(0, (c + 1) % 3);
  lonely.V.conservativeResize(q + 1, 3);
  lonely.V.row(q) = 0.5 * (lonely.V.row(a) + lonely.V.row(b));
  lonely.F.conservativeResize(lonely.F.rows() + 1, 3);
  lonely.F.row(lonely.F.rows() - 1) << a, q, b;
  ManifoldHarmonicsOptions o;
  o.num_modes = 9;
  for (LaplacianType type : {LaplacianType::Cotan, LaplacianType::IntrinsicDelaunay}) {
    o.laplacian = type;
    const ManifoldHarmonics h = compute_manifold_harmonics(lonely, o);
    EXPECT_EQ(h.status, SolveStatus::Converged) << residual_summary(h);
    const Eigen::RowVectorXd mid = 0.5 * (h.basis.row(a) + h.basis.row(b));
    const double tolerance = type == LaplacianType::Cotan ? 1e-3 : 3e-2;
    EXPECT_LT((h.basis.row(q) - mid).cwiseAbs().maxCoeff(),
              tolerance * h.basis.cwiseAbs().maxCoeff())
        << name(type);
  }
}

TEST(ManifoldHarmonics, RealMeshes) {
  const auto shared = test::shared_dir();
  if (shared.empty()) GTEST_SKIP() << "../shared is absent";
  for (const char* name : {"models/bumpy.off", "models/fertility.off", "models/camelhead.off"}) {
    const TriangleMesh mesh = read_mesh(shared / "meshes" / name).mesh;
    expect_sound(harmonics(mesh, 60), name);
  }
}

}  // namespace
}  // namespace specdeform
