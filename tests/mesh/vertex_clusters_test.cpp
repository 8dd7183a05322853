#include "specdeform/mesh/vertex_clusters.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <queue>
#include <set>

#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/mesh_info.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

// Every cluster is connected through edges inside it.
bool clusters_connected(const TriangleMesh& mesh, const VertexClusters& c) {
  std::vector<std::vector<int>> neighbours(mesh.num_vertices());
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) neighbours[mesh.F(f, k)].push_back(mesh.F(f, (k + 1) % 3));
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) neighbours[mesh.F(f, (k + 1) % 3)].push_back(mesh.F(f, k));
  std::vector<char> seen(mesh.num_vertices(), 0);
  std::vector<char> cluster_seen(c.count, 0);
  for (int start = 0; start < mesh.num_vertices(); ++start) {
    if (seen[start]) continue;
    if (cluster_seen[c.label[start]]) return false;  // a second piece of this cluster
    cluster_seen[c.label[start]] = 1;
    std::queue<int> queue;
    queue.push(start);
    seen[start] = 1;
    while (!queue.empty()) {
      const int i = queue.front();
      queue.pop();
      for (const int j : neighbours[i]) {
        if (!seen[j] && c.label[j] == c.label[i]) {
          seen[j] = 1;
          queue.push(j);
        }
      }
    }
  }
  return true;
}

TEST(VertexClusters, CorpusInvariants) {
  for (const test::CorpusMesh& m : test::corpus()) {
    int components = 0;
    const Eigen::VectorXi component = vertex_components(m.mesh, &components);
    for (const int requested : {1, 7, 40}) {
      const VertexClusters c = vertex_clusters(m.mesh, requested);
      EXPECT_EQ(c.count, std::min(m.mesh.num_vertices(), std::max(requested, components)))
          << m.name;
      ASSERT_EQ(c.label.size(), m.mesh.num_vertices());
      EXPECT_GE(c.label.minCoeff(), 0);
      EXPECT_LT(c.label.maxCoeff(), c.count);
      std::set<int> used(c.label.data(), c.label.data() + c.label.size());
      EXPECT_EQ(static_cast<int>(used.size()), c.count) << m.name << ": an empty cluster";
      EXPECT_TRUE(clusters_connected(m.mesh, c)) << m.name;
      for (int i = 0; i < m.mesh.num_vertices(); ++i) {  // never across components
        for (int j = 0; j < m.mesh.num_vertices(); ++j) {
          if (c.label[i] == c.label[j]) ASSERT_EQ(component[i], component[j]) << m.name;
        }
      }
      EXPECT_EQ(vertex_clusters(m.mesh, requested).label, c.label) << "deterministic";
    }
  }
}

// Clusters within a region: one sphere of two (642 vertices each) gets min(200, 642 / 16) = 40
// clusters, each inside it; the other sphere is one cluster, the last. A region of a stray
// triangle alone is one cluster.
TEST(VertexClusters, WithinARegion) {
  TriangleMesh shifted = make_icosphere(3);
  shifted.V.col(0).array() += 3.0;
  const TriangleMesh mesh = test::concatenate(make_icosphere(3), shifted);
  const int n = mesh.num_vertices(), half = n / 2;
  std::vector<char> region(n, 0);
  std::fill(region.begin(), region.begin() + half, 1);
  const VertexClusters c = vertex_clusters(mesh, 200, region);
  EXPECT_EQ(c.count, 41);
  for (int v = 0; v < half; ++v) EXPECT_LT(c.label[v], 40);
  for (int v = half; v < n; ++v) EXPECT_EQ(c.label[v], 40);
  for (int k = 0; k < 40; ++k)
    EXPECT_NE(std::find(c.label.begin(), c.label.end(), k), c.label.end());
  TriangleMesh stray{Vertices(3, 3), Faces(1, 3)};
  stray.V << 5, 0, 0, 5.1, 0, 0, 5, 0.1, 0;
  stray.F << 0, 1, 2;
  const TriangleMesh with_stray = test::concatenate(mesh, stray);
  std::vector<char> speck(with_stray.num_vertices(), 0);
  std::fill(speck.end() - 3, speck.end(), 1);
  const VertexClusters one = vertex_clusters(with_stray, 200, speck);
  EXPECT_EQ(one.count, 2);
  EXPECT_EQ(one.label.tail(3), Eigen::Vector3i::Zero());
  EXPECT_EQ(one.label.head(n), Eigen::VectorXi::Ones(n));
}

}  // namespace
}  // namespace specdeform
