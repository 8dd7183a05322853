#include "specdeform/operators/intrinsic_delaunay.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "operators/sliver_meshes.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/io.h"
#include "specdeform/operators/cotan_laplacian.h"
#include "specdeform/operators/mollification.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

using Sparse = Eigen::SparseMatrix<double>;

double relative_difference(const Sparse& A, const Sparse& B) {
  return Sparse(A - B).norm() / std::max(A.norm(), 1e-300);
}

// Edges with a negative cotangent weight (positive off-diagonal entries of K).
int negative_weights(const Sparse& K) {
  int count = 0;
  for (int j = 0; j < K.outerSize(); ++j)
    for (Sparse::InnerIterator it(K, j); it; ++it)
      if (it.row() < it.col() && it.value() > 1e-12) ++count;
  return count;
}

// The gluing is an involution between halfedges of equal length running opposite ways, and
// every interior edge is Delaunay.
void expect_valid_delaunay(const IntrinsicTriangulation& tri, const std::string& name) {
  for (int t = 0; t < tri.F.rows(); ++t) {
    for (int c = 0; c < 3; ++c) {
      const int h = tri.twin(t, c);
      if (h < 0) continue;
      const int u = h / 3, d = h % 3;
      ASSERT_EQ(tri.twin(u, d), 3 * t + c) << name;
      EXPECT_EQ(tri.length(u, d), tri.length(t, c)) << name;
      EXPECT_EQ(tri.F(u, d), tri.F(t, (c + 1) % 3)) << name;
      EXPECT_EQ(tri.F(u, (d + 1) % 3), tri.F(t, c)) << name;
      EXPECT_GE(edge_weight(tri, t, c), -1e-10) << name << ": triangle " << t << ", corner " << c;
    }
  }
}

TEST(IntrinsicDelaunay, DelaunayMeshesKeepTheirTriangles) {
  const TriangleMesh meshes[] = {make_icosphere(3), test::skewed_grid(12, 6, 2.0, 1.0, 0)};
  for (const TriangleMesh& mesh : meshes) {
    const IntrinsicTriangulation tri = intrinsic_delaunay(mesh);
    EXPECT_EQ(tri.flips, 0);
    EXPECT_FALSE(tri.tufted);
    EXPECT_EQ(tri.F, mesh.F);
    EXPECT_LT(relative_difference(stiffness_matrix(tri), cotan_stiffness(mesh)), 1e-13);
    for (MassType type : {MassType::Lumped, MassType::Consistent})
      EXPECT_LT(relative_difference(mass_matrix(tri, type), mass_matrix(mesh, type)), 1e-13);
  }
}

TEST(IntrinsicDelaunay, FlipsLeaningTrianglesBackToTheDelaunayOnes) {
  // The same flat rectangle and vertices (jittered, so that the Delaunay triangulation is
  // unique), cut into two triangles per cell or into slivers leaning 2 to 6 cells sideways.
  const TriangleMesh good = test::skewed_grid(24, 12, 2.0, 1.0, 0, 0.05);
  const IntrinsicTriangulation reference = intrinsic_delaunay(good);
  for (int skew : {2, 4, 6}) {
    const TriangleMesh bad = test::skewed_grid(24, 12, 2.0, 1.0, skew, 0.05);
    ASSERT_GT(face_normals(bad).col(2).minCoeff(), 0.0) << skew;  // a flat, unfolded rectangle
    EXPECT_GT(negative_weights(cotan_stiffness(bad)), 200) << skew;
    const IntrinsicTriangulation tri = intrinsic_delaunay(bad);
    EXPECT_GT(tri.flips, 24 * 12) << skew;
    expect_valid_delaunay(tri, "skew " + std::to_string(skew));
    EXPECT_LT(relative_difference(stiffness_matrix(tri), stiffness_matrix(reference)), 1e-12);
    for (MassType type : {MassType::Lumped, MassType::Consistent}) {
      EXPECT_LT(relative_difference(mass_matrix(tri, type), mass_matrix(reference, type)), 1e-12);
    }
  }
}

TEST(IntrinsicDelaunay, InteriorWeightsAreNonNegativeOnEveryMesh) {
  for (const auto& c : test::corpus()) {
    const IntrinsicTriangulation tri = intrinsic_delaunay(c.mesh);
    expect_valid_delaunay(tri, c.name);
    EXPECT_EQ(tri.tufted, c.category == test::Category::Awkward) << c.name;  // the fin
  }
  // Closed: every weight is an interior one, so K has no positive off-diagonal entry.
  // A sphere with vertices pulled towards an edge opposite to them (obtuse angles).
  const TriangleMesh sphere = make_icosphere(2);
  TriangleMesh bent = sphere;
  for (int f = 0; f < sphere.num_faces(); f += 7) {
    const Eigen::RowVector3d middle =
        0.5 * (bent.V.row(sphere.F(f, 1)) + bent.V.row(sphere.F(f, 2)));
    bent.V.row(sphere.F(f, 0)) += 0.7 * (middle - bent.V.row(sphere.F(f, 0)));
  }
  EXPECT_GT(negative_weights(cotan_stiffness(bent)), 10);
  EXPECT_EQ(negative_weights(stiffness_matrix(intrinsic_delaunay(bent))), 0);
}

TEST(IntrinsicDelaunay, TuftedCoverOfAManifoldMeshGivesItsOwnOperators) {
  // Reversing one triangle makes the orientation inconsistent: the mesh goes through its
  // tufted cover, which is two copies of the surface, and must give the same operators.
  const TriangleMesh mesh = test::skewed_grid(16, 8, 2.0, 1.0, 4, 0.05);
  TriangleMesh reversed = mesh;
  reversed.F.row(37) = mesh.F.row(37).reverse().eval();
  const IntrinsicTriangulation plain = intrinsic_delaunay(mesh),
                               cover = intrinsic_delaunay(reversed);
  ASSERT_FALSE(plain.tufted);
  ASSERT_TRUE(cover.tufted);
  EXPECT_EQ(cover.F.rows(), 2 * mesh.num_faces());
  EXPECT_GT(plain.flips, 0);
  expect_valid_delaunay(cover, "cover");
  EXPECT_LT(relative_difference(stiffness_matrix(cover), stiffness_matrix(plain)), 1e-12);
  for (MassType type : {MassType::Lumped, MassType::Consistent})
    EXPECT_LT(relative_difference(mass_matrix(cover, type), mass_matrix(plain, type)), 1e-12);
}

TEST(IntrinsicDelaunay, NonManifoldSpineGluesFacingSides) {
  // Three pages around a spine: each spine edge has three triangles. On the cover, each side
  // of a page is glued to the facing side of the next page around the spine, so a spine edge
  // has three interior edges on the cover, each between two different pages.
  const TriangleMesh mesh = test::book(3, 6, 0);
  const IntrinsicTriangulation tri = intrinsic_delaunay(mesh);
  ASSERT_TRUE(tri.tufted);
  EXPECT_EQ(tri.flips, 0);  // unfolded, two pages make a flat Delaunay rectangle
  expect_valid_delaunay(tri, "book");
  const int page_faces = mesh.num_faces() / 3;
  const auto page = [&](int halfedge) { return (halfedge / 3) % mesh.num_faces() / page_faces; };
  int spine_halfedges = 0;
  for (int t = 0; t < tri.F.rows(); ++t) {
    for (int c = 0; c < 3; ++c) {
      const int a = tri.F(t, c), b = tri.F(t, (c + 1) % 3);
      if (a > 6 || b > 6) continue;  // the spine's vertices are 0..6
      ++spine_halfedges;
      ASSERT_GE(tri.twin(t, c), 0);
      EXPECT_NE(page(tri.twin(t, c)), page(3 * t + c));
    }
  }
  EXPECT_EQ(spine_halfedges, 6 * 3 * 2);  // 6 spine edges x 3 pages x 2 sides
}

TEST(IntrinsicDelaunay, TuftedCoverGluesNeighbouringPages) {
  // Four pages at 0, 90, 180 and 270 degrees about the spine, stored in the order 0, 180, 90,
  // 270: each side of a page faces the page 90 degrees away, never the one opposite.
  const TriangleMesh four = test::book(4, 4, 0);
  const int per_page = four.num_faces() / 4;
  const int order[4] = {0, 2, 1, 3};  // the stored block b holds page order[b]
  TriangleMesh mesh = four;
  for (int b = 0; b < 4; ++b)
    mesh.F.middleRows(b * per_page, per_page) = four.F.middleRows(order[b] * per_page, per_page);
  const IntrinsicTriangulation tri = intrinsic_delaunay(mesh);
  ASSERT_TRUE(tri.tufted);
  const auto page = [&](int halfedge) {
    return order[(halfedge / 3) % mesh.num_faces() / per_page];
  };
  int spine_halfedges = 0;
  for (int t = 0; t < tri.F.rows(); ++t) {
    for (int c = 0; c < 3; ++c) {
      if (tri.F(t, c) > 4 || tri.F(t, (c + 1) % 3) > 4) continue;  // the spine is 0..4
      ++spine_halfedges;
      const int apart = (page(tri.twin(t, c)) - page(3 * t + c) + 4) % 4;
      EXPECT_TRUE(apart == 1 || apart == 3)
          << "pages " << page(3 * t + c) << ", " << page(tri.twin(t, c));
    }
  }
  EXPECT_EQ(spine_halfedges, 4 * 4 * 2);  // 4 spine edges x 4 pages x 2 sides
}

TEST(IntrinsicDelaunay, FlatCapIsFlippedAway) {
  // A vertex q exactly on the diagonal a-b of a cell: the triangle (a, b, q) is flat (its angle
  // at q is pi); mollified, it is a sliver whose angle at q is just below pi, intrinsically the
  // diagonal flips to q-d, and the result is that of the cell split into four, to the
  // mollification's margin (the sliver's area, of the order of its length^1.5 margin^0.5).
  const TriangleMesh grid = test::skewed_grid(4, 4, 1.0, 1.0, 0, 0.1);
  const int f = 10, a = grid.F(f, 0), b = grid.F(f, 1), c = grid.F(f, 2);
  int g = -1, d = -1;  // the triangle (b, a, d) across a-b
  for (int k = 0; k < grid.num_faces(); ++k)
    for (int e = 0; e < 3; ++e)
      if (grid.F(k, e) == b && grid.F(k, (e + 1) % 3) == a) g = k, d = grid.F(k, (e + 2) % 3);
  ASSERT_GE(g, 0);
  TriangleMesh capped = grid, split = grid;
  const int q = grid.num_vertices();
  for (TriangleMesh* m : {&capped, &split}) {
    m->V.conservativeResize(q + 1, 3);
    m->V.row(q) = 0.5 * (grid.V.row(a) + grid.V.row(b));
    m->F.conservativeResize(grid.num_faces() + 2, 3);
    m->F.row(f) << a, q, c;
    m->F.row(grid.num_faces()) << q, b, c;
  }
  capped.F.row(grid.num_faces() + 1) << a, b, q;
  split.F.row(g) << b, q, d;
  split.F.row(grid.num_faces() + 1) << q, a, d;
  const IntrinsicTriangulation tri = intrinsic_delaunay(capped);
  EXPECT_GE(tri.flips, 1);
  expect_valid_delaunay(tri, "capped");
  const IntrinsicTriangulation reference = intrinsic_delaunay(split);
  EXPECT_LT(relative_difference(stiffness_matrix(tri), stiffness_matrix(reference)), 1e-3);
  EXPECT_LT(relative_difference(mass_matrix(tri, MassType::Lumped),
                                mass_matrix(reference, MassType::Lumped)),
            1e-3);
}

TEST(IntrinsicDelaunay, RejectsFacesOutsideTheVertices) {
  TriangleMesh mesh = make_icosphere(1);
  mesh.F(3, 1) = mesh.num_vertices();
  EXPECT_THROW(intrinsic_delaunay(mesh), InputError);
}

TEST(IntrinsicDelaunay, SharedMeshes) {
  const auto shared = test::shared_dir();
  if (shared.empty()) GTEST_SKIP() << "../shared is absent";
  for (const auto& entry : std::filesystem::directory_iterator(shared / "meshes" / "models")) {
    const auto ext = entry.path().extension();
    if (ext != ".obj" && ext != ".off") continue;
    const TriangleMesh mesh = read_mesh(entry.path()).mesh;
    const IntrinsicTriangulation tri = intrinsic_delaunay(mesh);
    const std::string name = entry.path().filename().string();
    expect_valid_delaunay(tri, name);
    // A mesh with caps (decimated-max.obj) is mollified: its area grows by 2e-5.
    const double tolerance = mollification(mesh) > 0.0 ? 1e-4 : 1e-10;
    EXPECT_NEAR(mass_matrix(tri, MassType::Lumped).sum(), surface_area(mesh),
                tolerance * surface_area(mesh))
        << name;
  }
}

}  // namespace
}  // namespace specdeform
