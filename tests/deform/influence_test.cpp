#include "specdeform/deform/influence.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "specdeform/deform/scene.h"
#include "specdeform/deform/spectral_deformer.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/generate.h"

namespace specdeform {
namespace {

// On a flat grid the distances along the edges are at least the straight ones and at most a few
// percent more (its diagonals are edges).
TEST(Influence, DistancesAlongTheEdges) {
  const TriangleMesh plane = make_bumpy_plane({1.0, 20, 1, 0.0});
  const Selection corner{{{0}}, {}};
  const Eigen::VectorXd d = handle_distances(plane, corner);
  for (int v = 1; v < plane.num_vertices(); ++v) {
    const double straight = (plane.V.row(v) - plane.V.row(0)).norm();
    EXPECT_GE(d[v], straight * (1.0 - 1e-6));  // single precision
    EXPECT_LE(d[v], 1.09 * straight);
  }
  EXPECT_THROW(handle_distances(plane, Selection{{{plane.num_vertices()}}, {}}), InputError);
  EXPECT_THROW(limit_influence(plane, corner, 0.0), InputError);
}

// The bar's end turned and lifted with a radius of 1.5 (of its length 4): the surface beyond the
// radius stays exactly where it was, the surface within it moves; without the radius the
// deformation reaches the fixed end.
TEST(Influence, TheSurfaceBeyondTheRadiusStays) {
  BumpyBarOptions options;
  options.cells_per_unit = 8;
  const TriangleMesh bar = make_bumpy_bar(options);
  Selection selection;
  selection.handles.resize(1);
  for (int v = 0; v < bar.num_vertices(); ++v) {
    if (bar.V(v, 0) < 0.4) selection.fixed.push_back(v);
    if (bar.V(v, 0) > 3.6) selection.handles[0].push_back(v);
  }
  const Selection limited = limit_influence(bar, selection, 1.5);
  EXPECT_EQ(limited.handles, selection.handles);
  EXPECT_GT(limited.fixed.size(), 2 * selection.fixed.size());
  const Eigen::VectorXd d = handle_distances(bar, selection);
  const Eigen::Affine3d T =
      Eigen::Translation3d(0, 0, 0.4) * Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY());
  const auto basis = std::make_shared<const ManifoldHarmonics>(
      compute_manifold_harmonics(bar, {.num_modes = 100}));
  SpectralDeformer deformer(bar, basis);
  deformer.set_selection(limited);
  const Vertices out = deformer.solve({T});
  double moved_inside = 0.0;
  for (int v = 0; v < bar.num_vertices(); ++v) {
    const double moved = (out.row(v) - bar.V.row(v)).norm();
    if (d[v] > 1.5) EXPECT_EQ(moved, 0.0) << v;
    if (d[v] > 0.0 && d[v] < 1.0) moved_inside = std::max(moved_inside, moved);
  }
  EXPECT_GT(moved_inside, 0.1);
  deformer.set_selection(selection);
  const Vertices free = deformer.solve({T});
  double moved_far = 0.0;
  for (int v = 0; v < bar.num_vertices(); ++v)
    if (d[v] > 2.0 && bar.V(v, 0) > 0.4)
      moved_far = std::max(moved_far, (free.row(v) - bar.V.row(v)).norm());
  EXPECT_GT(moved_far, 0.05);
}

}  // namespace
}  // namespace specdeform
