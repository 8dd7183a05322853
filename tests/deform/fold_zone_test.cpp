#include "deform/fold_zone.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "specdeform/deform/detail_reconstruction.h"
#include "specdeform/mesh/generate.h"

namespace specdeform {
namespace {

using detail::FaceRows;
using detail::FoldZone;
using detail::RowVertices;

// The vertex nearest to the plane's centre.
int centre(const Vertices& V) {
  Eigen::Index i;
  (V.rowwise() - Eigen::RowVector3d(0.5, 0.5, V(0, 2))).rowwise().squaredNorm().minCoeff(&i);
  return static_cast<int>(i);
}

// A flat square whose centre vertex is pushed three cells across its neighbours: the faces
// around it turn over.
TEST(FoldZone, FindsAPlantedFoldAndNothingElse) {
  const TriangleMesh plane = make_bumpy_plane({.resolution = 16, .bump_height = 0.0});
  const FaceRows faces = plane.F;
  const RowVertices rest = plane.V;
  const FoldZone zone(faces, rest);
  const Eigen::Affine3d rigid(Eigen::Translation3d(0.3, -0.2, 1.0) *
                              Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  const RowVertices moved = (rigid * rest.transpose()).transpose();
  RowVertices normals;
  detail::unit_face_normals(faces, moved, normals);
  EXPECT_TRUE(zone.find(moved, normals).empty());

  RowVertices folded = rest;
  folded(centre(plane.V), 0) += 3.0 / 16;
  detail::unit_face_normals(faces, folded, normals);
  const std::vector<int> found = zone.find(folded, normals);
  std::vector<char> in(faces.rows(), 0);
  for (const int f : found) in[f] = 1;
  int turned = 0;
  for (int f = 0; f < faces.rows(); ++f) {
    if (normals(f, 2) < 0.0) {
      ++turned;
      EXPECT_TRUE(in[f]) << "face " << f;
    }
  }
  EXPECT_GT(turned, 0);
  EXPECT_LT(found.size(), size_t(faces.rows()) / 4);  // a zone, not the whole square
}

// A fold on a base stretched everywhere beyond the zone's stretch ratio: the zone grows over the
// whole surface, and the transfer and the frames give exactly the displacement result.
TEST(FoldZone, AZoneOverEverythingGivesTheDisplacementResult) {
  const TriangleMesh detailed = make_bumpy_plane({.resolution = 24, .bumps = 4});
  Vertices base = detailed.V;
  base.col(2).setZero();
  Vertices deformed = base;
  deformed.col(0) *= 2.0;  // stretch ratio 2
  deformed(centre(base), 0) += 2.0 * 3.0 / 24;
  const Vertices displaced = deformed + (detailed.V - base);
  const std::vector<int> anchors = {0, detailed.num_vertices() - 1};
  Eigen::MatrixX3d anchor_positions(2, 3);
  for (int i = 0; i < 2; ++i) anchor_positions.row(i) = displaced.row(anchors[i]);
  for (const DetailMethod method : {DetailMethod::Transfer, DetailMethod::Frames}) {
    DetailReconstruction details(detailed, base, method);
    details.set_anchors(anchors);
    const Vertices out = details.apply(deformed, anchor_positions);
    EXPECT_EQ(details.fold_zone(), detailed.num_faces());
    EXPECT_LE((out - displaced).cwiseAbs().maxCoeff(), 1e-10) << name(method);
    Vertices unfolded = base;
    unfolded.col(0) *= 2.0;
    details.apply(unfolded, anchor_positions);
    EXPECT_EQ(details.fold_zone(), 0) << name(method);
  }
}

}  // namespace
}  // namespace specdeform
