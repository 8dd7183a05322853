#include "mesh/sub_mesh.h"

namespace specdeform::detail {

TriangleMesh sub_mesh(const TriangleMesh& mesh, const std::vector<char>& keep,
                      std::vector<int>& original) {
  original.clear();
  std::vector<int> index(mesh.num_vertices(), -1);
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    if (keep[v]) {
      index[v] = static_cast<int>(original.size());
      original.push_back(v);
    }
  }
  TriangleMesh out{Vertices(static_cast<Eigen::Index>(original.size()), 3), Faces(0, 3)};
  for (size_t k = 0; k < original.size(); ++k) out.V.row(k) = mesh.V.row(original[k]);
  std::vector<int> faces;
  for (int f = 0; f < mesh.num_faces(); ++f)
    if (keep[mesh.F(f, 0)] && keep[mesh.F(f, 1)] && keep[mesh.F(f, 2)]) faces.push_back(f);
  out.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t k = 0; k < faces.size(); ++k)
    for (int j = 0; j < 3; ++j) out.F(k, j) = index[mesh.F(faces[k], j)];
  return out;
}

}  // namespace specdeform::detail
