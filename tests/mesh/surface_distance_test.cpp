#include "specdeform/mesh/surface_distance.h"

#include <gtest/gtest.h>

#include "specdeform/exceptions.h"
#include "specdeform/mesh/generate.h"

namespace specdeform {
namespace {

TEST(SurfaceDistance, PointsToATriangle) {
  TriangleMesh t{Vertices(3, 3), Faces(1, 3)};
  t.V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  t.F << 0, 1, 2;
  Vertices p(4, 3);
  p << 0.2, 0.2, 0.5,  // above the inside: the height
      2, 0, 0,         // beyond a corner: to the corner
      0.5, -1, 0,      // beside an edge: to the edge
      1, 1, 0;         // beyond the hypotenuse: to its midpoint
  const Eigen::VectorXd d = distances_to_surface(p, t);
  EXPECT_NEAR(d[0], 0.5, 1e-15);
  EXPECT_NEAR(d[1], 1.0, 1e-15);
  EXPECT_NEAR(d[2], 1.0, 1e-15);
  EXPECT_NEAR(d[3], std::sqrt(0.5), 1e-15);
}

TEST(SurfaceDistance, HausdorffOfMovedAndScaledShapes) {
  const TriangleMesh plane = make_bumpy_plane();
  EXPECT_EQ(hausdorff_distance(plane, plane), 0.0);
  TriangleMesh lifted = plane;
  lifted.V.col(2).array() += 0.25;
  // Each vertex lies 0.25 above or below its twin on the other surface, and no farther from
  // that surface; on the flat parts exactly 0.25.
  const double lift = hausdorff_distance(plane, lifted);
  EXPECT_LE(lift, 0.25 + 1e-12);
  EXPECT_GT(lift, 0.2);

  const TriangleMesh sphere = make_icosphere(3);
  TriangleMesh larger = sphere;
  larger.V *= 1.1;
  // The larger sphere's vertices are 0.1 from the unit sphere and a little more from its
  // inscribed polyhedron; the other way round, a little less.
  const double h = hausdorff_distance(sphere, larger);
  EXPECT_GT(h, 0.1);
  EXPECT_LT(h, 0.11);
}

TEST(SurfaceDistance, RefusesAnEmptySurface) {
  const TriangleMesh empty{Vertices(0, 3), Faces(0, 3)};
  EXPECT_THROW(distances_to_surface(Vertices::Zero(1, 3), empty), InputError);
}

}  // namespace
}  // namespace specdeform
