#include "mesh/graph_distance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/mesh_info.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

// Bellman-Ford's fixed point: the shortest distances from `sources`, in double precision.
std::vector<double> reference_distances(const detail::EdgeGraph& g,
                                        const std::vector<int>& sources) {
  std::vector<double> d(g.size(), std::numeric_limits<double>::infinity());
  for (const int s : sources) d[s] = 0.0;
  for (bool changed = true; changed;) {
    changed = false;
    for (int i = 0; i < g.size(); ++i) {
      for (int e = g.start[i]; e < g.start[i + 1]; ++e) {
        const double through = d[i] + g.arcs[e].length;
        if (through < d[g.arcs[e].to]) {
          d[g.arcs[e].to] = through;
          changed = true;
        }
      }
    }
  }
  return d;
}

// From several sources at once, limited or not, over the corpus: the shortest distances to
// single precision, each vertex visited once and in the order of its distance.
TEST(GraphDistance, DijkstraFromSeveralSources) {
  for (const test::CorpusMesh& c : test::corpus()) {
    const detail::EdgeGraph g = detail::edge_graph(c.mesh);
    ASSERT_EQ(g.size(), c.mesh.num_vertices());
    const std::vector<int> sources{0, c.mesh.num_vertices() / 2};
    const std::vector<double> expected = reference_distances(g, sources);
    const double limit =
        0.5 * *std::max_element(expected.begin(), expected.end(), [](double a, double b) {
          return (std::isfinite(a) ? a : 0.0) < (std::isfinite(b) ? b : 0.0);
        });
    for (const float bound : {detail::kFar, static_cast<float>(limit)}) {
      std::vector<float> d(g.size(), detail::kFar);
      detail::DistanceHeap heap;
      std::vector<int> visits(g.size(), 0);
      float last = 0.0f;
      detail::pruned_dijkstra(g, sources, bound, d, heap, [&](int i, float at) {
        ++visits[i];
        EXPECT_GE(at, last);
        last = at;
      });
      for (int i = 0; i < g.size(); ++i) {
        if (std::abs(expected[i] - bound) < 1e-6 * bound) continue;  // rounded either way
        if (std::isfinite(expected[i]) && expected[i] <= bound) {
          EXPECT_EQ(visits[i], 1) << c.name << " " << i;
          EXPECT_NEAR(d[i], expected[i], 1e-6 * (1.0 + expected[i])) << c.name << " " << i;
        } else {
          EXPECT_EQ(visits[i], 0) << c.name << " " << i;
        }
      }
    }
  }
}

// A renumbered graph is the same graph: each vertex's distances come out at its new number.
TEST(GraphDistance, RenumberedGraph) {
  for (const test::CorpusMesh& c : test::corpus()) {
    const int n = c.mesh.num_vertices();
    std::vector<int> reversed(n);
    for (int i = 0; i < n; ++i) reversed[i] = n - 1 - i;
    const detail::EdgeGraph plain = detail::edge_graph(c.mesh);
    const detail::EdgeGraph turned =
        detail::edge_graph(detail::vertex_rings(c.mesh), c.mesh.V, reversed);
    const std::vector<double> expected = reference_distances(plain, {0});
    const std::vector<double> got = reference_distances(turned, {n - 1});
    for (int i = 0; i < n; ++i) EXPECT_EQ(got[n - 1 - i], expected[i]) << c.name << " " << i;
  }
}

// Every component seeded, each vertex owned by a nearest seed, the covering radius the largest
// distance; on a sphere the seeds spread about as N equal discs would.
TEST(GraphDistance, FarthestPoints) {
  for (const test::CorpusMesh& c : test::corpus()) {
    const detail::EdgeGraph g = detail::edge_graph(c.mesh);
    int components = 0;
    const Eigen::VectorXi piece = vertex_components(c.mesh, &components);
    for (const int samples : {1, 9}) {
      const detail::Sampling s = detail::farthest_points(g, samples);
      EXPECT_EQ(static_cast<int>(s.seeds.size()),
                std::min(c.mesh.num_vertices(), std::max(samples, components)))
          << c.name;
      EXPECT_EQ(s.seeds[0], 0);
      std::set<int> seeded;
      for (const int seed : s.seeds) seeded.insert(piece[seed]);
      EXPECT_EQ(static_cast<int>(seeded.size()), components) << c.name;
      std::vector<std::vector<double>> from(s.seeds.size());
      for (size_t k = 0; k < s.seeds.size(); ++k) from[k] = reference_distances(g, {s.seeds[k]});
      for (int i = 0; i < g.size(); ++i) {
        double nearest = std::numeric_limits<double>::infinity();
        for (const auto& d : from) nearest = std::min(nearest, d[i]);
        EXPECT_NEAR(s.distance[i], nearest, 1e-6 * (1.0 + nearest)) << c.name;
        EXPECT_NEAR(from[s.owner[i]][i], nearest, 1e-6 * (1.0 + nearest)) << c.name;
      }
      EXPECT_EQ(s.covering_radius(), *std::max_element(s.distance.begin(), s.distance.end()));
    }
  }
  const TriangleMesh sphere = make_icosphere(4);  // 2,562 vertices, area 4 pi
  const int N = 100;
  const detail::Sampling s = detail::farthest_points(detail::edge_graph(sphere), N);
  const double disc = std::sqrt(4.0 / N);  // pi r^2 N = 4 pi
  EXPECT_GT(s.covering_radius(), 0.8 * disc);
  EXPECT_LT(s.covering_radius(), 1.6 * disc);
}

}  // namespace
}  // namespace specdeform
