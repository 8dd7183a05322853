#include "mesh/vertex_rings.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "specdeform/mesh/generate.h"

namespace specdeform {
namespace {

// An icosphere's rings have 5 or 6 vertices, sorted, distinct, symmetric; a lone triangle's two.
TEST(VertexRings, DistinctSortedSymmetricNeighbours) {
  const TriangleMesh sphere = make_icosphere(2);
  const detail::VertexRings r = detail::vertex_rings(sphere);
  ASSERT_EQ(r.start.size(), static_cast<size_t>(sphere.num_vertices() + 1));
  int fives = 0;
  for (int i = 0; i < sphere.num_vertices(); ++i) {
    const auto begin = r.neighbour.begin() + r.start[i], end = r.neighbour.begin() + r.start[i + 1];
    EXPECT_TRUE(r.size(i) == 5 || r.size(i) == 6) << i;
    fives += r.size(i) == 5;
    EXPECT_TRUE(std::is_sorted(begin, end));
    EXPECT_EQ(std::adjacent_find(begin, end), end);
    for (auto j = begin; j != end; ++j) {
      EXPECT_NE(*j, i);
      const auto back = r.neighbour.begin();
      EXPECT_TRUE(std::binary_search(back + r.start[*j], back + r.start[*j + 1], i));
    }
  }
  EXPECT_EQ(fives, 12);
  TriangleMesh triangle;
  triangle.V = Vertices::Identity(3, 3);
  triangle.F = (Faces(1, 3) << 0, 1, 2).finished();
  const detail::VertexRings t = detail::vertex_rings(triangle);
  EXPECT_EQ(t.neighbour, (std::vector<int>{1, 2, 0, 2, 0, 1}));
}

}  // namespace
}  // namespace specdeform
