#include "mesh/polygon_soup.h"

#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

namespace specdeform::detail {
namespace {

// Copies at one position weld into the first, -0.0 with +0.0; a NaN welds with nothing.
TEST(PositionIndex, WeldsExactCopiesIntoTheFirst) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> xyz = {1, 2,   3,    0.0, -0.0, 0,   1,
                                   2, 3,   -0.0, 0.0, -0.0, nan, 0,
                                   0, nan, 0,    0,   1,    2,   3.0000000000000004};
  EXPECT_EQ(weld_coincident(xyz), (std::vector<int>{0, 1, 0, 1, 4, 5, 6}));
}

// Vertices added one by one (a triangle soup's corners) past the table's first size: every copy
// finds its first and nothing else does.
TEST(PositionIndex, GrowsAsVerticesAreAdded) {
  std::vector<double> xyz;
  PositionIndex index(xyz);
  constexpr int kDistinct = 5000;
  for (int round = 0; round < 3; ++round) {
    for (int i = 0; i < kDistinct; ++i) {
      const int v = static_cast<int>(xyz.size() / 3);
      xyz.insert(xyz.end(), {std::cos(i * 0.1), std::sin(i * 0.1), i * 1e-3});
      const int first = index.first_at(v);
      ASSERT_EQ(first, round == 0 ? v : i);
      if (first != v) xyz.resize(3 * v);
    }
  }
  EXPECT_EQ(xyz.size(), 3u * kDistinct);
}

}  // namespace
}  // namespace specdeform::detail
