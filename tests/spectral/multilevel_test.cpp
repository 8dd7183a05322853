// The multilevel basis (spectral/multilevel.cpp): an approximation of the first m manifold
// harmonics that must be exactly M-orthonormal, hold the smooth shapes, and leave the
// deformation pipeline exact in its span.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "specdeform/deform/spectral_deformer.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/mesh_info.h"
#include "specdeform/operators/laplacian.h"
#include "specdeform/operators/mass_matrix.h"
#include "specdeform/spectral/manifold_harmonics.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

ManifoldHarmonics harmonics(const TriangleMesh& mesh, int m, EigenSolver solver,
                            int samples_per_mode = 10) {
  ManifoldHarmonicsOptions o;
  o.num_modes = m;
  o.solver = solver;
  o.policy.multilevel_min_samples = 1;  // N = samples_per_mode m: the corpus's small meshes
  o.policy.multilevel_samples_per_mode = samples_per_mode;
  return compute_manifold_harmonics(mesh, o);
}

// How well the span of U holds each of the first k columns of H (both M-orthonormal): the
// smallest norm of U^T M h_j, the cosine of the angle between h_j and the span.
double smallest_cosine(const ManifoldHarmonics& approximate, const ManifoldHarmonics& exact,
                       const TriangleMesh& mesh, int k) {
  const Eigen::SparseMatrix<double> M = mass_matrix(mesh, MassType::Lumped);
  const Eigen::MatrixXd C = approximate.basis.transpose() * (M * exact.basis.leftCols(k));
  return C.colwise().norm().minCoeff();
}

// The largest k <= most that ends at a gap of the exact spectrum (a cluster of equal eigenvalues
// is compared whole, not in the solver's arbitrary rotation of it).
int whole_clusters(const ManifoldHarmonics& exact, int most) {
  const Eigen::VectorXd& l = exact.eigenvalues;
  int k = most;
  while (k > 1 && l[k] - l[k - 1] < 0.01 * l[k]) --k;
  return k;
}

// The unit sphere: l(l + 1), 2l + 1 times. 16 modes = l <= 3.
TEST(MultilevelBasis, SphereSpectrumAndSpan) {
  const TriangleMesh sphere = make_icosphere(5);  // 10,242 vertices
  const ManifoldHarmonics exact = harmonics(sphere, 16, EigenSolver::BlockKrylov);
  const ManifoldHarmonics h = harmonics(sphere, 16, EigenSolver::Multilevel, 20);  // N = 320
  EXPECT_TRUE(h.approximate);
  EXPECT_EQ(h.coarse_functions, 320);
  EXPECT_EQ(h.status, SolveStatus::Converged);
  EXPECT_LT(h.max_orthogonality_error, 1e-10);
  EXPECT_NEAR(h.eigenvalues[0], 0.0, 1e-10);
  for (int i = 1; i < 16; ++i) {
    const int l = i < 4 ? 1 : i < 9 ? 2 : 3;
    EXPECT_NEAR(h.eigenvalues[i], l * (l + 1.0), 0.04 * l * (l + 1.0)) << i;  // measured 3.3%
    EXPECT_GE(h.eigenvalues[i], exact.eigenvalues[i] - 1e-9) << i;  // Galerkin: from above
  }
  EXPECT_GT(smallest_cosine(h, exact, sphere, 16), 0.9995);
  // Not eigenvectors: the residual says so (the exact basis's is below 1e-8).
  EXPECT_GT(h.max_residual, 1e-4);
}

// Every category of the corpus: M-orthonormal to 1e-10, the first 10 exact eigenvectors in the
// span (measured on these meshes of 170-1,000 vertices, with N = 10 m: smallest cosine 0.9978,
// the torus; 0.9995 on the sphere above), one zero eigenvalue per connected component.
TEST(MultilevelBasis, CorpusInvariants) {
  std::set<test::Category> tried;
  for (const test::CorpusMesh& c : test::corpus()) {
    const int n = c.mesh.num_vertices();
    const int m = std::min(12, n / 40);
    if (m < c.components + 3) continue;  // too small for a coarse space of 10 m functions
    const ManifoldHarmonics h = harmonics(c.mesh, m, EigenSolver::Multilevel);
    if (!h.approximate) continue;  // below multilevel_reduction N vertices: solved exactly
    tried.insert(c.category);
    const ManifoldHarmonics exact = harmonics(c.mesh, m, EigenSolver::BlockKrylov);
    EXPECT_LT(h.max_orthogonality_error, 1e-10) << c.name;
    EXPECT_GT(smallest_cosine(h, exact, c.mesh, whole_clusters(exact, std::min(m - 2, 10))), 0.99)
        << c.name;
    const int zeros = static_cast<int>((h.eigenvalues.array().abs() < 1e-8).count());
    EXPECT_EQ(zeros, c.components) << c.name;
  }
  EXPECT_EQ(tried.size(), 4u) << "closed, with boundary, several components, awkward";
}

// The basis keeps its factors, H = P Z exactly (to rounding), also through the breadth-first
// renumbering that large meshes get (forced here), and the sign convention applies to Z alike;
// a deformer reading P Z gives the frames of the dense basis. Several pieces keep no factors.
TEST(MultilevelBasis, KeepsItsFactors) {
  const TriangleMesh torus = make_torus(1.0, 0.35, 100, 40);
  for (const int reorder_from : {0, 1 << 30}) {
    ManifoldHarmonicsOptions o;
    o.num_modes = 60;  // below m of about 40, P Z is more bytes than H and not read per frame
    o.solver = EigenSolver::Multilevel;
    o.policy.reorder_from = reorder_from;
    const ManifoldHarmonics h = compute_manifold_harmonics(torus, o);
    ASSERT_TRUE(h.approximate);
    ASSERT_TRUE(h.factored.smaller_than_dense(4));  // the deformers below read P Z
    EXPECT_EQ(h.factored.prolongation.rows(), torus.num_vertices());
    EXPECT_EQ(h.factored.coarse.rows(), h.coarse_functions);
    const Eigen::MatrixXd PZ = h.factored.prolongation * h.factored.coarse;
    EXPECT_LT((PZ - h.basis).cwiseAbs().maxCoeff(), 1e-13 * h.basis.cwiseAbs().maxCoeff())
        << reorder_from;

    Selection selection;
    selection.handles.resize(1);
    for (int i = 0; i < torus.num_vertices(); ++i) {
      if (torus.V(i, 0) < -1.1) selection.fixed.push_back(i);
      if (torus.V(i, 0) > 1.1) selection.handles[0].push_back(i);
    }
    ManifoldHarmonics dense = h;
    dense.factored = FactoredBasis{};
    const Eigen::Affine3d T(Eigen::Translation3d(0.1, 0.3, -0.2) *
                            Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()));
    for (const bool float32 : {false, true}) {
      DeformOptions d;
      d.float32_basis = float32;
      SpectralDeformer factored(torus, std::make_shared<const ManifoldHarmonics>(h), d);
      SpectralDeformer plain(torus, std::make_shared<const ManifoldHarmonics>(dense), d);
      factored.set_selection(selection);
      plain.set_selection(selection);
      const double tolerance = (float32 ? 1e-5 : 1e-12) * bounding_box_diagonal(torus.V);
      EXPECT_LT((factored.solve({T}) - plain.solve({T})).cwiseAbs().maxCoeff(), tolerance);
      EXPECT_LT((factored.preview({T}) - plain.preview({T})).cwiseAbs().maxCoeff(), tolerance);
    }
  }
  TriangleMesh two;
  two.V.resize(2 * torus.num_vertices(), 3);
  two.V << torus.V, torus.V.rowwise() + Eigen::RowVector3d(3.0, 0.0, 0.0);
  two.F.resize(2 * torus.num_faces(), 3);
  two.F << torus.F, torus.F.array() + torus.num_vertices();
  ManifoldHarmonicsOptions o;
  o.num_modes = 12;
  o.solver = EigenSolver::Multilevel;
  EXPECT_TRUE(compute_manifold_harmonics(two, o).factored.empty());
}

// The residuals, the orthonormality and the signs come from P and Z without H (the
// verification gathers H's columns from P's rows, the orthonormality is the coarse problem's,
// and H is formed last, in the mesh's numbering): each must be H's own.
TEST(MultilevelBasis, ItsChecksFromTheFactorsAreTheBasisOwn) {
  const TriangleMesh torus = make_torus(1.0, 0.35, 100, 40);
  const LaplacianOperators L = laplacian_operators(torus, MassType::Lumped, LaplacianType::Cotan);
  for (const int reorder_from : {0, 1 << 30}) {
    ManifoldHarmonicsOptions o;
    o.num_modes = 40;
    o.solver = EigenSolver::Multilevel;
    o.policy.reorder_from = reorder_from;
    const ManifoldHarmonics h = compute_manifold_harmonics(torus, o);
    ASSERT_FALSE(h.factored.empty());
    const double residual = eigen_residual(L.stiffness, L.mass, h.basis, h.eigenvalues);
    EXPECT_NEAR(h.max_residual, residual, 1e-12 * residual) << reorder_from;
    EXPECT_NEAR(h.max_orthogonality_error, orthonormality_error(L.mass, h.basis), 1e-13);
    EXPECT_LT(h.max_orthogonality_error, 1e-12);
    for (int j = 0; j < h.basis.cols(); ++j) {
      Eigen::Index i;
      h.basis.col(j).cwiseAbs().maxCoeff(&i);
      EXPECT_GT(h.basis(i, j), 0.0) << j;
    }
  }
}

// The profile names the multilevel path's stages in the order they ran; their seconds add up to
// the computation's (the clock runs from the first stage to the return).
TEST(MultilevelBasis, ProfilesItsStages) {
  const TriangleMesh torus = make_torus(1.0, 0.35, 100, 40);
  ManifoldHarmonicsOptions o;
  o.num_modes = 40;
  o.solver = EigenSolver::Multilevel;
  o.policy.reorder_from = 0;
  std::vector<std::string> reported;
  o.progress = [&](double, std::string_view stage) {
    if (reported.empty() || reported.back() != stage) reported.emplace_back(stage);
  };
  const auto start = std::chrono::steady_clock::now();
  const ManifoldHarmonics h = compute_manifold_harmonics(torus, o);
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::vector<std::string> stages;
  double sum = 0.0;
  for (const StageTime& t : h.stages) {
    stages.push_back(t.stage);
    EXPECT_GE(t.seconds, 0.0) << t.stage;
    sum += t.seconds;
  }
  EXPECT_EQ(stages, reported);  // each once: one piece
  for (const char* stage :
       {"the Laplacian", "edge lengths", "ordering", "sampling", "coarse space", "coarse operators",
        "coarse eigenvectors", "verification", "numbering back", "prolongation"}) {
    EXPECT_NE(std::ranges::find(stages, stage), stages.end()) << stage;
  }
  EXPECT_EQ(stages.back(), "prolongation");
  EXPECT_LE(sum, elapsed);
  EXPECT_GT(sum, 0.9 * elapsed - 0.01);
}

// A mesh smaller than multilevel_reduction times the coarse space gets the exact solver.
TEST(MultilevelBasis, SmallMeshesAreSolvedExactly) {
  const ManifoldHarmonics h = harmonics(make_icosphere(2), 10, EigenSolver::Multilevel);
  EXPECT_FALSE(h.approximate);
  EXPECT_LT(h.max_residual, 1e-8);
}

// The pipeline stays exact in the span: a zero deformation gives the input back, with every
// detail method and both energies.
TEST(MultilevelBasis, IdentityReproducesTheInput) {
  BumpyBarOptions bar;
  bar.cells_per_unit = 12;
  const TriangleMesh mesh = make_bumpy_bar(bar);
  const ManifoldHarmonics h = harmonics(mesh, 30, EigenSolver::Multilevel);
  ASSERT_TRUE(h.approximate);
  Selection selection;
  selection.handles.resize(1);
  for (int i = 0; i < mesh.num_vertices(); ++i) {
    if (mesh.V(i, 0) < 0.3) selection.fixed.push_back(i);
    if (mesh.V(i, 0) > 3.7) selection.handles[0].push_back(i);
  }
  const double diagonal = bounding_box_diagonal(mesh.V);
  for (const DeformEnergy energy : {DeformEnergy::Linear, DeformEnergy::Arap}) {
    for (const DetailMethod method :
         {DetailMethod::Displacement, DetailMethod::Frames, DetailMethod::Transfer}) {
      DeformOptions o;
      o.energy = energy;
      o.detail = method;
      const Vertices out = deform(mesh, h, selection, {Eigen::Affine3d::Identity()}, o);
      EXPECT_LT((out - mesh.V).cwiseAbs().maxCoeff(), 1e-9 * diagonal)
          << name(energy) << " " << name(method);
    }
  }
}

}  // namespace
}  // namespace specdeform
