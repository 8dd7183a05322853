#include "specdeform/mesh/mesh_info.h"

#include <gtest/gtest.h>

#include <numbers>

#include "specdeform/mesh/generate.h"
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
    if (c.category == test::Category::Awkward) {
      EXPECT_EQ(i.degenerate_faces, 1) << c.name;
      EXPECT_EQ(i.non_manifold_edges, 1) << c.name;
    } else {
      EXPECT_EQ(i.degenerate_faces, 0) << c.name;
      EXPECT_EQ(i.non_manifold_edges, 0) << c.name;
    }
  }
}

}  // namespace
}  // namespace specdeform
