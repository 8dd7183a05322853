#include "specdeform/mesh/generate.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "specdeform/mesh/mesh_info.h"

namespace specdeform {
namespace {

// Signed volume: positive for a closed mesh with outward (counter-clockwise) faces.
double signed_volume(const TriangleMesh& m) {
  double v = 0.0;
  for (int f = 0; f < m.num_faces(); ++f) {
    const Eigen::Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    v += a.dot(b.cross(c)) / 6.0;
  }
  return v;
}

TEST(Generate, ClosedShapesAreOutwardManifolds) {
  const TriangleMesh bar = make_bumpy_bar();
  const TriangleMesh sphere = make_icosphere(3);
  const TriangleMesh torus = make_torus();
  for (const TriangleMesh* m : {&bar, &sphere, &torus}) {
    const MeshInfo i = compute_mesh_info(*m);
    EXPECT_EQ(i.boundary_edges, 0);
    EXPECT_EQ(i.non_manifold_edges, 0);
    EXPECT_EQ(i.components, 1);
    EXPECT_GT(signed_volume(*m), 0.0);
  }
  EXPECT_EQ(compute_mesh_info(bar).euler_characteristic, 2);
  EXPECT_EQ(compute_mesh_info(torus).euler_characteristic, 0);
  EXPECT_EQ(sphere.num_vertices(), 642);
  EXPECT_NEAR(signed_volume(make_bumpy_bar({4.0, 1.0, 8, 3, 0.0})), 4.0, 1e-12);
}

TEST(Generate, BumpsStayOffTheBarsEdges) {
  BumpyBarOptions o;
  const TriangleMesh bar = make_bumpy_bar(o);
  const double half = 0.5 * o.thickness;
  int bumped = 0;
  for (int i = 0; i < bar.num_vertices(); ++i) {
    const Eigen::RowVector3d p = bar.V.row(i);
    const double y = std::abs(p.y()), z = std::abs(p.z());
    EXPECT_LE(std::max(y, z), half + o.bump_height + 1e-12);
    if (std::max(y, z) > half + 1e-12) ++bumped;
  }
  EXPECT_GT(bumped, bar.num_vertices() / 4);
}

TEST(Generate, PlaneIsOpenAndSized) {
  const TriangleMesh plane = make_bumpy_plane({1.0, 16, 4, 0.0});
  EXPECT_EQ(plane.num_vertices(), 17 * 17);
  EXPECT_EQ(plane.num_faces(), 2 * 16 * 16);
  EXPECT_DOUBLE_EQ(plane.V.col(2).cwiseAbs().maxCoeff(), 0.0);
  const TriangleMesh face_up = make_bumpy_plane({1.0, 2, 1, 0.0});
  EXPECT_GT(face_normals(face_up).col(2).minCoeff(), 0.0);
}

}  // namespace
}  // namespace specdeform
