#include "specdeform/mesh/mesh_info.h"

#include <algorithm>
#include <array>
#include <numeric>
#include <tuple>
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
  const Faces& F = mesh.F;
  // Every face's edges as (low vertex, high vertex, face, whether the face runs from low to high).
  struct HalfEdge {
    int lo, hi, face;
    bool forward;
    bool operator<(const HalfEdge& o) const {
      return std::tie(lo, hi, face) < std::tie(o.lo, o.hi, o.face);
    }
  };
  std::vector<HalfEdge> half;
  half.reserve(3 * size_t(info.faces));
  for (int f = 0; f < info.faces; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      half.push_back({std::min(a, b), std::max(a, b), f, a < b});
    }
  }
  std::sort(half.begin(), half.end());
  std::vector<std::array<int, 3>> corners(info.faces);
  for (int f = 0; f < info.faces; ++f) {
    corners[f] = {F(f, 0), F(f, 1), F(f, 2)};
    std::sort(corners[f].begin(), corners[f].end());
  }
  std::sort(corners.begin(), corners.end());
  for (size_t f = 1; f < corners.size(); ++f) info.duplicate_faces += corners[f] == corners[f - 1];
  const Eigen::VectorXi component = vertex_components(mesh, &info.components);
  std::vector<char> misoriented(info.components, 0);
  // Corner 3 f + k is face f at vertex F(f, k). Faces that share an edge join their corners at
  // both its ends, so the corners of a vertex fall into one set per fan of faces around it.
  UnionFind fans(3 * info.faces);
  const auto corner = [&](int f, int v) {
    return 3 * f + (F(f, 0) == v ? 0 : F(f, 1) == v ? 1 : 2);
  };
  UnionFind boundary(info.vertices);
  std::vector<char> on_boundary(info.vertices, 0);
  for (size_t i = 0; i < half.size();) {
    const HalfEdge& e = half[i];
    size_t j = i + 1;
    while (j < half.size() && half[j].lo == e.lo && half[j].hi == e.hi) ++j;
    ++info.edges;
    if (j - i == 1) {
      ++info.boundary_edges;
      boundary.unite(e.lo, e.hi);
      on_boundary[e.lo] = on_boundary[e.hi] = 1;
    } else if (j - i > 2) {
      ++info.non_manifold_edges;
    } else if (half[i + 1].forward == e.forward) {
      if (info.inconsistent_edges++ == 0) info.first_inconsistent_edge = {e.lo, e.hi};
      misoriented[component[e.lo]] = 1;
    }
    for (size_t k = i + 1; k < j; ++k) {
      fans.unite(corner(e.face, e.lo), corner(half[k].face, e.lo));
      fans.unite(corner(e.face, e.hi), corner(half[k].face, e.hi));
    }
    i = j;
  }
  for (int v = 0; v < info.vertices; ++v)
    if (on_boundary[v] && boundary.find(v) == v) ++info.boundary_loops;
  info.misoriented_components =
      static_cast<int>(std::count(misoriented.begin(), misoriented.end(), 1));
  info.euler_characteristic = info.vertices - info.edges + info.faces;

  std::vector<int> fan(info.vertices, -1);  // the set of the vertex's first corner
  std::vector<char> pinch(info.vertices, 0), has_area(info.vertices, 0);
  for (int f = 0; f < info.faces; ++f) {
    const bool degenerate =
        is_degenerate_triangle(mesh.V.row(F(f, 0)), mesh.V.row(F(f, 1)), mesh.V.row(F(f, 2)));
    info.degenerate_faces += degenerate;
    for (int k = 0; k < 3; ++k) {
      const int v = F(f, k), set = fans.find(3 * f + k);
      if (fan[v] < 0) fan[v] = set;
      if (fan[v] != set) pinch[v] = 1;
      if (!degenerate) has_area[v] = 1;
    }
  }
  for (int v = info.vertices - 1; v >= 0; --v) {
    if (pinch[v]) {
      ++info.pinch_vertices;
      info.first_pinch_vertex = v;
    }
    if (!has_area[v]) {
      ++info.zero_area_vertices;
      info.first_zero_area_vertex = v;
    }
  }
  // Coincident vertices: equal positions are neighbours in lexicographic order.
  std::vector<int> order(info.vertices);
  std::iota(order.begin(), order.end(), 0);
  const auto position = [&](int v) { return std::tuple(mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2)); };
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return std::tuple(position(a), a) < std::tuple(position(b), b); });
  for (int k = 1; k < info.vertices; ++k) {
    if (position(order[k]) != position(order[k - 1])) continue;
    ++info.coincident_vertices;
    if (info.first_coincident_vertices[0] < 0 || order[k - 1] < info.first_coincident_vertices[0]) {
      info.first_coincident_vertices = {order[k - 1], order[k]};
    }
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
