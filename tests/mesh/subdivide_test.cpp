#include "specdeform/mesh/subdivide.h"

#include <gtest/gtest.h>

#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/mesh_info.h"

namespace specdeform {
namespace {

TEST(Subdivide, CountsAndTopology) {
  const TriangleMesh torus = make_torus(1.0, 0.3, 12, 6);
  const MeshInfo before = compute_mesh_info(torus);
  for (const auto scheme : {SubdivisionScheme::Loop, SubdivisionScheme::Midpoint}) {
    const TriangleMesh fine = subdivide(torus, 2, scheme);
    const MeshInfo after = compute_mesh_info(fine);
    EXPECT_EQ(after.faces, 16 * before.faces);
    EXPECT_EQ(after.euler_characteristic, before.euler_characteristic);
    EXPECT_EQ(after.non_manifold_edges, 0);
  }
  EXPECT_EQ(subdivide(torus, 0).V, torus.V);
}

TEST(Subdivide, MidpointKeepsTheGeometry) {
  const TriangleMesh plane = make_bumpy_plane({1.0, 4, 1, 0.0});
  const TriangleMesh fine = subdivide(plane, 1, SubdivisionScheme::Midpoint);
  EXPECT_EQ(fine.V.topRows(plane.num_vertices()), plane.V);
  EXPECT_NEAR(surface_area(fine), surface_area(plane), 1e-12);
  EXPECT_EQ(compute_mesh_info(fine).boundary_loops, 1);
}

TEST(Subdivide, LoopSmoothsTowardsTheLimitSurface) {
  // Loop subdivision of a coarse sphere shrinks it a little but keeps it round.
  const TriangleMesh fine = subdivide(make_icosphere(1), 2);
  const Eigen::VectorXd r = fine.V.rowwise().norm();
  EXPECT_LT(r.maxCoeff() - r.minCoeff(), 0.05);
  EXPECT_GT(r.minCoeff(), 0.85);
  // Boundary vertices of a flat plane stay in the plane and on the boundary lines.
  const TriangleMesh plane = subdivide(make_bumpy_plane({1.0, 4, 1, 0.0}), 1);
  EXPECT_DOUBLE_EQ(plane.V.col(2).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_DOUBLE_EQ(plane.V.col(0).minCoeff(), 0.0);
}

}  // namespace
}  // namespace specdeform
