#include "specdeform/deform/deformation_quality.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <numbers>

#include "specdeform/exceptions.h"
#include "specdeform/mesh/generate.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

Vertices transformed(const Vertices& V, const Eigen::Affine3d& T) {
  return (T * V.transpose()).transpose();
}

TEST(DeformationQuality, CrossSectionsOfATube) {
  BumpyTubeOptions o;
  o.cells_per_unit = 4;
  const TriangleMesh tube = make_bumpy_tube(o);
  const Eigen::Affine3d rigid = Eigen::Translation3d(1, 2, 3) *
                                Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, -1, 2).normalized());
  const std::vector<double> same = cross_section_ratios(tube.V, transformed(tube.V, rigid), 0);
  EXPECT_EQ(same.size(), static_cast<size_t>(o.length * o.cells_per_unit + 1));  // the rings
  for (const double r : same) EXPECT_NEAR(r, 1.0, 1e-12);
  // Halving the cross-section's size, more towards the middle: the ratios follow.
  Vertices squeezed = tube.V;
  for (int i = 0; i < tube.num_vertices(); ++i) {
    const double s = 1.0 - 0.5 * std::sin(std::numbers::pi * tube.V(i, 0) / o.length);
    squeezed.row(i).tail<2>() *= s;
  }
  const std::vector<double> ratios = cross_section_ratios(tube.V, squeezed, 0);
  EXPECT_NEAR(*std::min_element(ratios.begin(), ratios.end()), 0.5, 1e-12);
  EXPECT_NEAR(ratios.front(), 1.0, 1e-12);
  EXPECT_THROW(cross_section_ratios(tube.V, tube.V.topRows(3), 0), InputError);
  EXPECT_THROW(cross_section_ratios(tube.V, tube.V, 3), InputError);
}

TEST(DeformationQuality, InvertedFaces) {
  for (const test::CorpusMesh& m : test::corpus()) {
    const Eigen::Affine3d rigid(Eigen::AngleAxisd(2.5, Eigen::Vector3d(0, 1, 1).normalized()));
    EXPECT_EQ(inverted_faces(m.mesh, transformed(m.mesh.V, rigid)), 0) << m.name;
  }
  // A vertex of a flat grid pushed through its neighbours' plane: its fan folds over.
  const TriangleMesh plane = make_bumpy_plane({1.0, 10, 1, 0.0});
  Vertices folded = plane.V;
  const int middle = 5 * 11 + 5;
  folded.row(middle) = 0.5 * (plane.V.row(middle - 1) + plane.V.row(middle + 1));
  folded.row(middle).x() += 0.3;  // beyond its right neighbour
  EXPECT_GT(inverted_faces(plane, folded), 0);
  EXPECT_EQ(inverted_faces(plane, plane.V), 0);
}

TEST(DeformationQuality, PointDistances) {
  Vertices a = Vertices::Zero(4, 3), b = a;
  b(0, 0) = 3.0;
  b(1, 1) = 4.0;
  const PointDistances d = point_distances(a, b);
  EXPECT_DOUBLE_EQ(d.max, 4.0);
  EXPECT_DOUBLE_EQ(d.rms, std::sqrt((9.0 + 16.0) / 4.0));
}

}  // namespace
}  // namespace specdeform
