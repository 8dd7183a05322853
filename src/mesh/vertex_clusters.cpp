#include "specdeform/mesh/vertex_clusters.h"

#include <algorithm>

#include "linalg/locality_order.h"
#include "mesh/graph_distance.h"
#include "mesh/sub_mesh.h"
#include "mesh/vertex_rings.h"

namespace specdeform {

VertexClusters vertex_clusters(const TriangleMesh& mesh, int count) {
  const int n = mesh.num_vertices();
  VertexClusters out;
  if (n == 0) return out;
  // The sampling on the edge graph renumbered breadth first (neighbours close in memory: a
  // subdivided mesh numbers them far apart), its labels put back.
  const detail::VertexRings rings = detail::vertex_rings(mesh);
  const detail::Permutation P =
      detail::breadth_first_order(n, rings.start.data(), rings.neighbour.data());
  const detail::Sampling s = detail::farthest_points(
      detail::edge_graph(rings, mesh.V, std::span(P.indices().data(), n)), std::max(count, 1));
  out.count = static_cast<int>(s.seeds.size());
  out.label.resize(n);
  for (int i = 0; i < n; ++i) out.label[i] = s.owner[P.indices()[i]];
  return out;
}

// A region's clusters have this many vertices or more on average: a speck moved alone (a
// stray triangle) is one cluster and keeps its shape, not one per vertex.
constexpr int kRegionClusterVertices = 16;

VertexClusters vertex_clusters(const TriangleMesh& mesh, int count,
                               const std::vector<char>& region) {
  std::vector<int> original;
  const TriangleMesh part = detail::sub_mesh(mesh, region, original);
  const VertexClusters inside =
      vertex_clusters(part, std::min(count, part.num_vertices() / kRegionClusterVertices));
  VertexClusters out;
  out.count = inside.count + (static_cast<int>(original.size()) < mesh.num_vertices() ? 1 : 0);
  out.label = Eigen::VectorXi::Constant(mesh.num_vertices(), inside.count);
  for (size_t k = 0; k < original.size(); ++k) out.label[original[k]] = inside.label[k];
  return out;
}

}  // namespace specdeform
