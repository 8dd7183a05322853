#include "specdeform/mesh/mesh_info.h"

#include <gtest/gtest.h>

#include <numbers>

#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/io.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

TEST(MeshInfo, ClosedSphere) {
  const MeshInfo i = compute_mesh_info(make_icosphere(2));
  EXPECT_EQ(i.vertices, 162);
  EXPECT_EQ(i.faces, 320);
  EXPECT_EQ(i.edges, 480);
  EXPECT_EQ(i.euler_characteristic, 2);
  EXPECT_EQ(i.components, 1);
  EXPECT_EQ(i.boundary_loops, 0);
  EXPECT_EQ(i.non_manifold_edges, 0);
  EXPECT_NEAR(i.area, 4 * std::numbers::pi, 0.3);
}

TEST(MeshInfo, TorusAndPlane) {
  EXPECT_EQ(compute_mesh_info(make_torus(1.0, 0.3, 20, 8)).euler_characteristic, 0);
  const MeshInfo plane = compute_mesh_info(make_bumpy_plane({2.0, 10, 1, 0.0}));
  EXPECT_EQ(plane.boundary_loops, 1);
  EXPECT_EQ(plane.boundary_edges, 40);
  EXPECT_EQ(plane.euler_characteristic, 1);
  EXPECT_DOUBLE_EQ(plane.area, 4.0);
  EXPECT_DOUBLE_EQ(plane.bbox_diagonal, std::sqrt(8.0));
}

TEST(MeshInfo, ComponentsAndAwkward) {
  for (const auto& c : test::corpus()) {
    const MeshInfo i = compute_mesh_info(c.mesh);
    EXPECT_EQ(i.components, c.components) << c.name;
    // The awkward mesh's zero-area triangle runs along the boundary edge (1, 2) the same way as
    // the face beside it.
    const int awkward = c.category == test::Category::Awkward;
    EXPECT_EQ(i.degenerate_faces, awkward) << c.name;
    EXPECT_EQ(i.non_manifold_edges, awkward) << c.name;
    EXPECT_EQ(i.inconsistent_edges, awkward) << c.name;
    EXPECT_EQ(i.misoriented_components, awkward) << c.name;
    EXPECT_EQ(i.zero_area_vertices, 0) << c.name;
    EXPECT_EQ(i.pinch_vertices, 0) << c.name;
    EXPECT_EQ(i.first_pinch_vertex, -1) << c.name;
    EXPECT_EQ(i.coincident_vertices, 0) << c.name;
  }
}

TriangleMesh mesh(Vertices V, Faces F) {
  return {std::move(V), std::move(F)};
}

TEST(MeshInfo, VertexTouchedOnlyByDegenerateFaces) {
  Vertices V(5, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0, 3, 0, 0;
  Faces F(3, 3);
  F << 0, 1, 2, 1, 0, 3, 2, 1, 4;  // vertex 3 on the line through 0 and 1; 4 has area
  const MeshInfo i = compute_mesh_info(mesh(V, F));
  EXPECT_EQ(i.degenerate_faces, 1);
  EXPECT_EQ(i.zero_area_vertices, 1);
  EXPECT_EQ(i.first_zero_area_vertex, 3);
  EXPECT_EQ(i.inconsistent_edges, 0);
}

TEST(MeshInfo, PinchVertices) {
  // A bow tie: two triangles that share vertex 0 only.
  Vertices V(5, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0;
  Faces F(2, 3);
  F << 0, 1, 2, 0, 3, 4;
  const MeshInfo bow = compute_mesh_info(mesh(V, F));
  EXPECT_EQ(bow.pinch_vertices, 1);
  EXPECT_EQ(bow.first_pinch_vertex, 0);
  EXPECT_EQ(bow.components, 1);
  // Two spheres touching at one vertex: the second, moved by twice the first's vertex 5, shares
  // its vertex j (antipodal to 5) with the first's vertex 5.
  const TriangleMesh a = make_icosphere(1);
  const int n = a.num_vertices();
  int j = 0;
  (a.V.rowwise() + a.V.row(5)).rowwise().norm().minCoeff(&j);
  TriangleMesh glued;
  glued.V.resize(2 * n - 1, 3);
  glued.F.resize(2 * a.num_faces(), 3);
  glued.V.topRows(n) = a.V;
  for (int v = 0, k = n; v < n; ++v)
    if (v != j) glued.V.row(k++) = a.V.row(v) + 2 * a.V.row(5);
  for (int f = 0; f < a.num_faces(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int v = a.F(f, c);
      glued.F(f, c) = v;
      glued.F(a.num_faces() + f, c) = v == j ? 5 : v < j ? n + v : n + v - 1;
    }
  }
  const MeshInfo g = compute_mesh_info(glued);
  EXPECT_EQ(g.pinch_vertices, 1);
  EXPECT_EQ(g.first_pinch_vertex, 5);
  EXPECT_EQ(g.non_manifold_edges, 0);
  EXPECT_EQ(g.inconsistent_edges, 0);
  EXPECT_EQ(g.zero_area_vertices, 0);
  EXPECT_EQ(g.components, 1);
}

TEST(MeshInfo, InconsistentOrientation) {
  TriangleMesh flipped = make_icosphere(1);
  flipped.F.row(7) = flipped.F.row(7).reverse().eval();
  const MeshInfo one = compute_mesh_info(flipped);
  EXPECT_EQ(one.inconsistent_edges, 3);  // the flipped face's three edges
  EXPECT_EQ(one.misoriented_components, 1);
  const Eigen::Vector3i f = flipped.F.row(7);
  const int lo = f.minCoeff(), mid = f.sum() - f.minCoeff() - f.maxCoeff();
  EXPECT_EQ(one.first_inconsistent_edge, Eigen::Vector2i(lo, mid));
  // Beside a sound sphere: one of two components affected.
  TriangleMesh sound = make_icosphere(1);
  sound.V.col(0).array() += 3.0;
  const MeshInfo two = compute_mesh_info(test::concatenate(sound, flipped));
  EXPECT_EQ(two.components, 2);
  EXPECT_EQ(two.misoriented_components, 1);
  // Every face turned: consistent again (inward).
  TriangleMesh inward = make_icosphere(1);
  inward.F = inward.F.rowwise().reverse().eval();
  EXPECT_EQ(compute_mesh_info(inward).inconsistent_edges, 0);
}

TEST(MeshInfo, CoincidentVertices) {
  // Copies of vertices 9 and 3 (as 12 and 13), as a seam cut open would have them: only the
  // positions count.
  TriangleMesh cut = make_icosphere(0);
  cut.V.conservativeResize(14, 3);
  cut.V.row(12) = cut.V.row(9);
  cut.V.row(13) = cut.V.row(3);
  const MeshInfo i = compute_mesh_info(cut);
  EXPECT_EQ(i.coincident_vertices, 2);
  EXPECT_EQ(i.first_coincident_vertices, Eigen::Vector2i(3, 13));
}

// The shared cow is closed and manifold but has two vertices at one point (621 and 2761, sharing
// the neighbour 620): welded, they would be a pinch vertex.
TEST(MeshInfo, SharedCow) {
  const auto shared = test::shared_dir();
  if (shared.empty()) GTEST_SKIP() << "../shared is absent";
  const MeshInfo cow = compute_mesh_info(read_mesh(shared / "meshes/models/cow.off").mesh);
  EXPECT_EQ(cow.pinch_vertices, 0);
  EXPECT_EQ(cow.non_manifold_edges, 0);
  EXPECT_EQ(cow.coincident_vertices, 1);
  EXPECT_EQ(cow.first_coincident_vertices, Eigen::Vector2i(621, 2761));
  EXPECT_EQ(cow.zero_area_vertices, 0);
}

}  // namespace
}  // namespace specdeform
