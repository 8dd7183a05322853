#include "spectral/piecewise.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include <Eigen/Geometry>

#include "specdeform/deform/spectral_deformer.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/mesh_info.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

// 10 x 10 unit icospheres, 3 apart.
TriangleMesh sphere_grid(int subdivisions) {
  TriangleMesh grid{Vertices(0, 3), Faces(0, 3)};
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 10; ++j) {
      TriangleMesh sphere = make_icosphere(subdivisions);
      sphere.V.rowwise() += Eigen::RowVector3d(3.0 * i, 3.0 * j, 0.0);
      grid = test::concatenate(grid, sphere);
    }
  }
  return grid;
}

TEST(PieceModes, ShareOfTheAreaWithAFloorAndALimit) {
  const ManifoldHarmonicsPolicy policy;  // floor 16, limit 16 m
  EXPECT_EQ(detail::piece_modes({0.9, 0.05, 0.05}, {5000, 300, 4}, 100, policy),
            (std::vector<int>{90, 16, 4}));
  EXPECT_EQ(
      detail::piece_modes(std::vector<double>(100, 1.0), std::vector<int>(100, 500), 100, policy),
      std::vector<int>(100, 16));
  // 300 equal pieces at m = 100: 4,800 modes exceed 1,600; pieces keep their constant only
  // until 16 k + (300 - k) <= 1,600: k = 86 pieces keep 16.
  const std::vector<int> many =
      detail::piece_modes(std::vector<double>(300, 1.0), std::vector<int>(300, 500), 100, policy);
  EXPECT_LE(std::accumulate(many.begin(), many.end(), 0), 1600);
  EXPECT_EQ(std::count(many.begin(), many.end(), 16), 86);
  // 2,000 specks: 1,600 keep their constant, the 400 smallest none.
  std::vector<double> specks(2000);
  std::iota(specks.begin(), specks.end(), 1.0);
  const std::vector<int> few = detail::piece_modes(specks, std::vector<int>(2000, 3), 100, policy);
  EXPECT_EQ(std::accumulate(few.begin(), few.end(), 0), 1600);
  EXPECT_EQ(std::count(few.begin(), few.begin() + 400, 0), 400);
}

// The columns of dense basis stay within piece_basis_bytes: 1,899 teapots of 2,086 vertices
// (3.96M) at m = 100 would take 16 m = 1,600 columns (51 GB); within 4 GB, 126 (the largest
// pieces their constant, the smallest none), and never fewer than m.
TEST(PieceModes, TheDenseColumnsFitTheMemoryBudget) {
  const ManifoldHarmonicsPolicy policy;
  std::vector<double> area(1899);
  std::iota(area.begin(), area.end(), 1.0);
  const std::vector<int> vertices(1899, 2086);
  const std::vector<int> modes = detail::piece_modes(area, vertices, 100, policy);
  const long long columns = std::accumulate(modes.begin(), modes.end(), 0LL);
  EXPECT_EQ(columns, static_cast<long long>(policy.piece_basis_bytes / (8.0 * 1899 * 2086)));
  EXPECT_EQ(std::count(modes.begin(), modes.end(), 0), 1899 - columns);
  ManifoldHarmonicsPolicy tight = policy;
  tight.piece_basis_bytes = 1e6;  // fewer than m columns' worth: m all the same
  const std::vector<int> least = detail::piece_modes(area, vertices, 100, tight);
  EXPECT_EQ(std::accumulate(least.begin(), least.end(), 0), 100);
}

// 100 identical spheres at m = 1000: eigenvalues of multiplicity 100 to 700 (the whole mesh's
// shifts could not be placed among them). Piece by piece every sphere gets its own first 16
// (its share, 10, is below the floor), the same as one sphere alone, M-orthonormal, each mode
// on one sphere.
TEST(Piecewise, OneHundredIdenticalSpheres) {
  const TriangleMesh grid = sphere_grid(2);
  ManifoldHarmonicsOptions o;
  o.num_modes = 1000;
  const ManifoldHarmonics h = compute_manifold_harmonics(grid, o);
  EXPECT_EQ(h.status, SolveStatus::Converged);
  EXPECT_EQ(h.pieces, 100);
  EXPECT_EQ(h.requested_modes, 1000);
  ASSERT_EQ(h.basis.cols(), 1600);
  EXPECT_LT(h.max_orthogonality_error, 1e-10);
  EXPECT_LT(h.max_residual, 1e-8);
  ManifoldHarmonicsOptions one = o;
  one.num_modes = 16;
  const ManifoldHarmonics sphere = compute_manifold_harmonics(make_icosphere(2), one);
  for (int j = 0; j < 1600; ++j) {
    EXPECT_NEAR(h.eigenvalues[j], sphere.eigenvalues[j / 100], 1e-8 * (1 + sphere.eigenvalues[15]))
        << j;
  }
  const Eigen::VectorXi label = vertex_components(grid);
  for (int j = 0; j < 1600; ++j) {
    std::vector<char> on(100, 0);
    for (int v = 0; v < grid.num_vertices(); ++v)
      if (h.basis(v, j) != 0.0) on[label[v]] = 1;
    EXPECT_EQ(std::count(on.begin(), on.end(), 1), 1) << "mode " << j;
  }
}

// The assembly with default options (m = 100): the bottoms fixed, one sphere's top
// pulled by 0.8 radii and turned by 0.6 rad; its smooth base reaches the handle within 0.5% of
// the diagonal (the whole mesh's first 100 harmonics were its constants only, and missed by
// the whole move), and the other spheres stay.
TEST(Piecewise, AHundredPieceAssemblyDeforms) {
  const TriangleMesh grid = sphere_grid(2);
  const auto h = std::make_shared<const ManifoldHarmonics>(compute_manifold_harmonics(grid, {}));
  EXPECT_EQ(h->basis.cols(), 1600);
  const Eigen::VectorXi label = vertex_components(grid);
  Selection selection;
  selection.handles.resize(1);
  const int pulled = 45;
  for (int v = 0; v < grid.num_vertices(); ++v) {
    const double z = grid.V(v, 2);
    if (z < -0.7) selection.fixed.push_back(v);
    if (z > 0.7 && label[v] == pulled) selection.handles[0].push_back(v);
  }
  const Eigen::Vector3d top = grid.V.row(selection.handles[0][0]);
  const Eigen::Affine3d T = Eigen::Translation3d(0.3, 0.2, 0.8) * Eigen::Translation3d(top) *
                            Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitX()) *
                            Eigen::Translation3d(-top);
  SpectralDeformer deformer(grid, h);
  deformer.set_selection(selection);
  const Vertices out = deformer.solve({T});
  // The pulled sphere takes all of m (deform/moving_basis.h); the others are held in place.
  std::vector<int> modes(100, 0);
  modes[pulled] = 100;
  EXPECT_EQ(deformer.constrained_piece_modes(), modes);
  const double diagonal = bounding_box_diagonal(grid.V);
  double miss = 0.0;
  for (const int v : selection.handles[0]) {
    const Eigen::Vector3d target = T * deformer.base().row(v).transpose();
    miss = std::max(miss, (deformer.deformed_base().row(v).transpose() - target).norm());
  }
  EXPECT_LT(miss, 0.005 * diagonal);
  EXPECT_TRUE(deformer.arap_report().converged);
  for (int v = 0; v < grid.num_vertices(); ++v)
    if (label[v] != pulled) ASSERT_LT((out.row(v) - grid.V.row(v)).norm(), 1e-6 * diagonal);
}

}  // namespace
}  // namespace specdeform
