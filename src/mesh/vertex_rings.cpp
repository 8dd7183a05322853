#include "mesh/vertex_rings.h"

#include <algorithm>

namespace specdeform::detail {

VertexRings vertex_rings(const TriangleMesh& mesh) {
  const int n = mesh.num_vertices();
  std::vector<int> start(n + 1, 0);  // first with repeats: two entries per face corner
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) start[mesh.F(f, k) + 1] += 2;
  for (int i = 0; i < n; ++i) start[i + 1] += start[i];
  std::vector<int> listed(start[n]);
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int i = mesh.F(f, k);
      listed[fill[i]++] = mesh.F(f, (k + 1) % 3);
      listed[fill[i]++] = mesh.F(f, (k + 2) % 3);
    }
  }
  VertexRings out;
  out.start.assign(n + 1, 0);
  out.neighbour.reserve(listed.size() / 2);
  for (int i = 0; i < n; ++i) {
    const auto begin = listed.begin() + start[i], end = listed.begin() + start[i + 1];
    std::sort(begin, end);
    out.neighbour.insert(out.neighbour.end(), begin, std::unique(begin, end));
    out.start[i + 1] = static_cast<int>(out.neighbour.size());
  }
  return out;
}

}  // namespace specdeform::detail
