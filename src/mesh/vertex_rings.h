// Internal: each vertex's one-ring, the distinct vertices it shares an edge with, in compressed
// rows (the mesh's edge graph for Dijkstra and breadth-first walks, and the frames detail's
// rings).
#pragma once

#include <vector>

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform::detail {

struct VertexRings {
  std::vector<int> start;      // n + 1: vertex i's ring is neighbour[start[i] .. start[i + 1])
  std::vector<int> neighbour;  // each ring sorted, every neighbour once
  int size(int i) const { return start[i + 1] - start[i]; }
};

VertexRings vertex_rings(const TriangleMesh& mesh);

}  // namespace specdeform::detail
