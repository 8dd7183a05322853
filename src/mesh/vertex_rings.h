// Internal: each vertex's one-ring, the distinct vertices it shares an edge with, in compressed
// rows (the mesh's edge graph for Dijkstra and breadth-first walks, and the frames detail's
// rings); and each vertex's faces (the faces across an edge: the transfer's donors, the fold
// zone).
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

struct VertexFaces {
  std::vector<int> start;  // n + 1: vertex i's faces are face[start[i] .. start[i + 1])
  std::vector<int> face;   // each vertex's faces ascending
};

// F: f x 3 vertex indices in [0, n) (any storage order); by counting, O(n + f).
template <typename FaceMatrix>
VertexFaces vertex_faces(const FaceMatrix& F, int n) {
  const int nf = static_cast<int>(F.rows());
  VertexFaces out;
  out.start.assign(n + 1, 0);
  out.face.resize(3 * size_t(nf));
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) ++out.start[F(f, k) + 1];
  for (int i = 0; i < n; ++i) out.start[i + 1] += out.start[i];
  std::vector<int> fill(out.start.begin(), out.start.end() - 1);
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) out.face[fill[F(f, k)]++] = f;
  return out;
}

}  // namespace specdeform::detail
