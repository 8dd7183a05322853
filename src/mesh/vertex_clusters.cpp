#include "specdeform/mesh/vertex_clusters.h"

#include <algorithm>

#include "linalg/locality_order.h"
#include "mesh/graph_distance.h"
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

}  // namespace specdeform
