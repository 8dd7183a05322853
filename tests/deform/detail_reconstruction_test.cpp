#include "specdeform/deform/detail_reconstruction.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <atomic>

#include "specdeform/deform/deformation_quality.h"
#include "specdeform/deform/spectral_deformer.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/mesh_info.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

const DetailMethod kMethods[] = {DetailMethod::Displacement, DetailMethod::Frames,
                                 DetailMethod::Transfer};

std::shared_ptr<const ManifoldHarmonics> harmonics(const TriangleMesh& mesh, int m) {
  ManifoldHarmonicsOptions o;
  o.num_modes = std::min(m, mesh.num_vertices() - 1);
  return std::make_shared<ManifoldHarmonics>(compute_manifold_harmonics(mesh, o));
}

// The first vertex of every connected component.
std::vector<int> one_vertex_per_piece(const TriangleMesh& mesh) {
  int count = 0;
  const Eigen::VectorXi label = vertex_components(mesh, &count);
  std::vector<int> first(count, -1);
  for (int v = mesh.num_vertices() - 1; v >= 0; --v) first[label[v]] = v;
  return first;
}

Vertices moved(const Vertices& V, const Eigen::Affine3d& T) {
  return (T * V.transpose()).transpose();
}

// The teapot's failure: a small piece's base is a point (its constant mode only), and per-face
// frames of collapsed triangles are rounding noise; with s' = s every method must still return x.
TEST(DetailReconstruction, PiecesWithACollapsedBaseComeBackUnderTheIdentity) {
  for (const test::CorpusMesh& m : test::corpus()) {
    if (m.category != test::Category::Components) continue;
    const auto h = harmonics(m.mesh, 100);
    const std::vector<int> pinned = one_vertex_per_piece(m.mesh);
    const Selection selection{{{pinned[0]}}, {pinned.begin() + 1, pinned.end()}};
    const double diagonal = bounding_box_diagonal(m.mesh.V);
    for (const DetailMethod method : kMethods) {
      for (const DeformEnergy energy : {DeformEnergy::Linear, DeformEnergy::Arap}) {
        DeformOptions o;
        o.detail = method;
        o.energy = energy;
        SpectralDeformer deformer(m.mesh, h, o);
        deformer.set_selection(selection);
        const Vertices out = deformer.solve({Eigen::Affine3d::Identity()});
        EXPECT_LT(point_distances(out, m.mesh.V).max, 1e-6 * diagonal)
            << m.name << " " << name(method) << " " << name(energy);
      }
    }
  }
}

// A stray triangle held by one of its vertices, that vertex moved and turned: the triangle
// follows and keeps its shape (its base is a point: no rotation to take from it).
TEST(DetailReconstruction, AStrayTriangleKeepsItsShape) {
  const test::CorpusMesh& m =
      *std::find_if(test::corpus().begin(), test::corpus().end(),
                    [](const auto& c) { return c.name == "bar_and_stray_triangle"; });
  const int n = m.mesh.num_vertices();
  Selection selection;
  selection.handles = {{n - 3}};
  for (int v = 0; v < n - 3; ++v)
    if (m.mesh.V(v, 0) < 0.5) selection.fixed.push_back(v);
  const Eigen::Affine3d T = Eigen::Translation3d(0.2, 0.3, -0.1) *
                            Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 2, 0).normalized());
  const auto h = harmonics(m.mesh, 100);
  for (const DetailMethod method : kMethods) {
    DeformOptions o;
    o.detail = method;
    SpectralDeformer deformer(m.mesh, h, o);
    deformer.set_selection(selection);
    const Vertices out = deformer.solve({T});
    for (int a = n - 3; a < n; ++a) {
      const int b = a + 1 < n ? a + 1 : n - 3;
      EXPECT_NEAR((out.row(a) - out.row(b)).norm(), (m.mesh.V.row(a) - m.mesh.V.row(b)).norm(),
                  1e-9)
          << name(method);
    }
    if (method == DetailMethod::Transfer) {
      EXPECT_LT((out.row(n - 3) - (T * m.mesh.V.row(n - 3).transpose()).transpose()).norm(),
                1e-12);  // anchored
    }
  }
}

// Pieces without a handle or fixed vertex stay where they are under Keep (or are an error when
// asked); the deformed pieces fold no more faces over than the hard spatial solve of the same
// scene. (Follow, the default: free_pieces_test.cpp.)
TEST(DetailReconstruction, UnconstrainedPiecesStayAndNothingFolds) {
  for (const test::CorpusMesh& m : test::corpus()) {
    if (m.category != test::Category::Components) continue;
    int pieces = 0;
    const Eigen::VectorXi label = vertex_components(m.mesh, &pieces);
    const auto [selection, T] = test::first_piece_scene(m.mesh, label);
    const auto h = harmonics(m.mesh, 100);
    DeformOptions hard;
    hard.energy = DeformEnergy::Linear;
    hard.solver = DeformSolver::Spatial;
    hard.constraints = ConstraintMode::Hard;
    hard.detail = DetailMethod::None;
    SpectralDeformer reference(m.mesh, nullptr, hard);  // the detailed mesh itself
    reference.set_selection(selection);
    const int reference_folds = inverted_faces(m.mesh, reference.solve({T}));
    for (const DetailMethod method : kMethods) {
      DeformOptions o;
      o.detail = method;
      o.unconstrained = UnconstrainedPieces::Keep;
      SpectralDeformer deformer(m.mesh, h, o);
      deformer.set_selection(selection);
      const Vertices out = deformer.solve({T});
      EXPECT_EQ(deformer.free_pieces(), pieces - 1) << m.name;
      for (int v = 0; v < m.mesh.num_vertices(); ++v) {
        if (label[v] != 0) ASSERT_EQ(out.row(v), m.mesh.V.row(v)) << m.name << " " << v;
      }
      EXPECT_LE(inverted_faces(m.mesh, out), reference_folds) << m.name << " " << name(method);
    }
    DeformOptions strict;
    strict.unconstrained = UnconstrainedPieces::Error;
    SpectralDeformer deformer(m.mesh, h, strict);
    try {
      deformer.set_selection(selection);
      ADD_FAILURE() << m.name << ": no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("connected component 2 of"), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find("vertices, the first vertex"), std::string::npos)
          << e.what();
    }
  }
}

// In the background, a transfer adds displacements until the newest anchors are factored, then
// gives exactly what the synchronous one gives; anchor sets that arrive while it works replace
// each other.
TEST(DetailReconstruction, BackgroundTransferSwitchesOverToTheSameResult) {
  const TriangleMesh mesh = make_bumpy_bar();
  const auto h = harmonics(mesh, 40);
  DeformOptions o;
  o.energy = DeformEnergy::Linear;
  SpectralDeformer deformer(mesh, h, o);
  const Vertices& base = deformer.base();
  const Vertices turned = moved(
      base, Eigen::Translation3d(0.1, 0.2, 0.0) * Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()));
  std::vector<int> first, second;
  for (int i = 0; i < mesh.num_vertices(); ++i) (mesh.V(i, 0) < 0.5 ? first : second).push_back(i);
  const auto targets = [&](const std::vector<int>& anchors) {
    Eigen::MatrixX3d t(anchors.size(), 3);
    for (size_t k = 0; k < anchors.size(); ++k)
      t.row(k) = turned.row(anchors[k]) + (mesh.V - base).row(anchors[k]);
    return t;
  };
  DetailReconstruction now(mesh, base, DetailMethod::Transfer);
  now.set_anchors(second);
  const Vertices expected = now.apply(turned, targets(second));

  std::atomic<int> calls = 0;
  DetailReconstruction later(mesh, base, DetailMethod::Transfer, TransferSolves::Background);
  later.on_ready([&] { ++calls; });
  EXPECT_TRUE(later.ready());  // no anchors asked for yet
  later.set_anchors(first);
  later.set_anchors(second);  // the newest wins
  if (!later.ready()) {
    const Vertices meanwhile = later.apply(turned, targets(second));
    EXPECT_EQ(later.applied(), DetailMethod::Displacement);
    EXPECT_LT((meanwhile - (turned + mesh.V - base)).cwiseAbs().maxCoeff(), 1e-15);
  }
  later.wait();
  EXPECT_TRUE(later.ready());
  EXPECT_GE(calls.load(), 1);
  const Vertices out = later.apply(turned, targets(second));
  EXPECT_EQ(later.applied(), DetailMethod::Transfer);
  EXPECT_LT((out - expected).cwiseAbs().maxCoeff(), 1e-12);
  later.set_anchors(first);  // destroyed while it may still work: waits, no crash
}

// The deformer in the background: the same result once the transfer is ready, and displacements
// (its own result with DetailMethod::Displacement) before.
TEST(DetailReconstruction, DeformerWithABackgroundTransfer) {
  const TriangleMesh mesh = make_bumpy_bar();
  const auto h = harmonics(mesh, 40);
  Selection selection;
  selection.handles.resize(1);
  for (int i = 0; i < mesh.num_vertices(); ++i) {
    if (mesh.V(i, 0) < 0.3) selection.fixed.push_back(i);
    if (mesh.V(i, 0) > 3.7) selection.handles[0].push_back(i);
  }
  const std::vector<Eigen::Affine3d> turn = {Eigen::Affine3d(
      Eigen::Translation3d(-0.5, 1.0, 0.2) * Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitZ()))};
  DeformOptions o;
  SpectralDeformer sync(mesh, h, o);
  sync.set_selection(selection);
  const Vertices expected = sync.solve(turn);
  o.detail = DetailMethod::Displacement;
  SpectralDeformer displaced(mesh, h, o);
  displaced.set_selection(selection);
  const Vertices meanwhile = displaced.solve(turn);
  o.detail = DetailMethod::Transfer;
  o.background_transfer = true;
  SpectralDeformer deformer(mesh, h, o);
  deformer.set_selection(selection);
  const Vertices first = deformer.solve(turn);
  const bool pending = deformer.applied_detail() == DetailMethod::Displacement;
  EXPECT_LT((first - (pending ? meanwhile : expected)).cwiseAbs().maxCoeff(), 1e-12);
  deformer.wait_for_detail();
  EXPECT_FALSE(deformer.detail_pending());
  EXPECT_LT((deformer.solve(turn) - expected).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(deformer.applied_detail(), DetailMethod::Transfer);
}

}  // namespace
}  // namespace specdeform
