#include "specdeform/mesh/mesh_info.h"

#include <algorithm>
#include <numeric>
#include <utility>
#include <vector>

namespace specdeform {

namespace {

class UnionFind {
 public:
  explicit UnionFind(int n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  int find(int i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  void unite(int a, int b) { parent_[find(a)] = find(b); }

 private:
  std::vector<int> parent_;
};

}  // namespace

Eigen::VectorXi vertex_components(const TriangleMesh& mesh, int* count) {
  const int n = mesh.num_vertices();
  UnionFind uf(n);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    uf.unite(mesh.F(f, 0), mesh.F(f, 1));
    uf.unite(mesh.F(f, 1), mesh.F(f, 2));
  }
  Eigen::VectorXi label = Eigen::VectorXi::Constant(n, -1);
  std::vector<int> root_label(n, -1);
  int next = 0;
  for (int i = 0; i < n; ++i) {
    int& l = root_label[uf.find(i)];
    if (l < 0) l = next++;
    label[i] = l;
  }
  if (count != nullptr) *count = next;
  return label;
}

MeshInfo compute_mesh_info(const TriangleMesh& mesh) {
  MeshInfo info;
  info.vertices = mesh.num_vertices();
  info.faces = mesh.num_faces();
  std::vector<std::pair<int, int>> half;
  half.reserve(3 * size_t(info.faces));
  for (int f = 0; f < info.faces; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.F(f, k), b = mesh.F(f, (k + 1) % 3);
      half.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(half.begin(), half.end());
  UnionFind boundary(info.vertices);
  std::vector<char> on_boundary(info.vertices, 0);
  for (size_t i = 0; i < half.size();) {
    size_t j = i;
    while (j < half.size() && half[j] == half[i]) ++j;
    ++info.edges;
    if (j - i == 1) {
      ++info.boundary_edges;
      boundary.unite(half[i].first, half[i].second);
      on_boundary[half[i].first] = on_boundary[half[i].second] = 1;
    } else if (j - i > 2) {
      ++info.non_manifold_edges;
    }
    i = j;
  }
  for (int v = 0; v < info.vertices; ++v)
    if (on_boundary[v] && boundary.find(v) == v) ++info.boundary_loops;
  vertex_components(mesh, &info.components);
  info.euler_characteristic = info.vertices - info.edges + info.faces;
  for (int f = 0; f < info.faces; ++f) {
    if (is_degenerate_triangle(mesh.V.row(mesh.F(f, 0)), mesh.V.row(mesh.F(f, 1)),
                               mesh.V.row(mesh.F(f, 2))))
      ++info.degenerate_faces;
  }
  info.area = surface_area(mesh);
  if (info.vertices > 0) {
    info.bbox_min = mesh.V.colwise().minCoeff();
    info.bbox_max = mesh.V.colwise().maxCoeff();
  }
  info.bbox_diagonal = bounding_box_diagonal(mesh.V);
  return info;
}

}  // namespace specdeform
