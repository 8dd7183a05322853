#include "specdeform/operators/intrinsic_delaunay.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "specdeform/exceptions.h"
#include "specdeform/operators/mollification.h"

namespace specdeform {

namespace {

using Sparse = Eigen::SparseMatrix<double>;

// An edge is flipped while the cotangents of its opposite angles sum to less than -kFlipMargin.
constexpr double kFlipMargin = 1e-10;
constexpr long long kFlipsPerEdge = 100;

// Halfedge h = 3 t + c is corner c's edge of triangle t, from vertex[h] to vertex[next(h)].
int next(int h) {
  return h % 3 == 2 ? h - 2 : h + 1;
}
int prev(int h) {
  return h % 3 == 0 ? h + 2 : h - 1;
}

double double_area(double a, double b, double c) {
  return double_area_from_lengths(a, b, c);
}

// The cotangent of the angle opposite to side a.
double cotangent(double a, double b, double c) {
  return (b * b + c * c - a * a) / (2.0 * double_area(a, b, c));
}

bool degenerate(double a, double b, double c) {
  const double longest = std::max({a, b, c});
  return double_area(a, b, c) <= kDegenerateTolerance * longest * longest;
}

// The triangulation while it is built and flipped: one entry per halfedge.
struct Halfedges {
  std::vector<int> vertex, twin;
  std::vector<double> length;

  // The cotangent of the angle opposite to halfedge h in its triangle.
  double opposite_cotangent(int h) const {
    return cotangent(length[h], length[next(h)], length[prev(h)]);
  }
  void flip(int h);
};

// Replaces the edge of h (triangles A = (i, j, k) and B = (j, i, l)) by the edge k - l:
// A becomes (l, k, i) and B (k, l, j). The outer edges keep their lengths and neighbours.
void Halfedges::flip(int h) {
  const int g = twin[h], a = h - h % 3, b = g - g % 3;
  const int hn = next(h), hp = prev(h), gn = next(g), gp = prev(g);
  const int i = vertex[h], j = vertex[hn], k = vertex[hp], l = vertex[gp];
  // Lay the quadrilateral out flat with i at the origin and j on the positive x axis.
  const double L = length[h];
  const double xk = (L * L + length[hp] * length[hp] - length[hn] * length[hn]) / (2 * L);
  const double yk = double_area(L, length[hn], length[hp]) / L;
  const double xl = (L * L + length[gn] * length[gn] - length[gp] * length[gp]) / (2 * L);
  const double yl = -double_area(L, length[gn], length[gp]) / L;
  const double diagonal = std::hypot(xk - xl, yk - yl);

  const int old_slot[4] = {hp, gn, gp, hn};
  const int new_slot[4] = {a + 1, a + 2, b + 1, b + 2};
  int old_twin[4];
  double old_length[4];
  for (int r = 0; r < 4; ++r) {
    old_twin[r] = twin[old_slot[r]];
    old_length[r] = length[old_slot[r]];
  }
  const auto moved = [&](int x) {
    for (int r = 0; r < 4; ++r)
      if (x == old_slot[r]) return new_slot[r];
    return x;
  };
  vertex[a] = l, vertex[a + 1] = k, vertex[a + 2] = i;
  vertex[b] = k, vertex[b + 1] = l, vertex[b + 2] = j;
  twin[a] = b, twin[b] = a;
  length[a] = length[b] = diagonal;
  for (int r = 0; r < 4; ++r) {
    const int t = moved(old_twin[r]);
    twin[new_slot[r]] = t;
    length[new_slot[r]] = old_length[r];
    if (t >= 0) twin[t] = new_slot[r];
  }
}

// The mesh's halfedges 3 f + c ordered by undirected edge (smaller vertex, then larger); `first`
// holds where each edge's run starts, and one past the last.
struct EdgeGroups {
  std::vector<int> order, first;
};

EdgeGroups group_edges(const TriangleMesh& mesh) {
  const int n = mesh.num_vertices(), halfedges = 3 * mesh.num_faces();
  const auto ends = [&](int h) {
    const int u = mesh.F(h / 3, h % 3), v = mesh.F(h / 3, (h % 3 + 1) % 3);
    return std::pair{std::min(u, v), std::max(u, v)};
  };
  // Counting sort by the smaller vertex, then each vertex's few halfedges by the larger one.
  std::vector<int> start(n + 1, 0);
  for (int h = 0; h < halfedges; ++h) ++start[ends(h).first + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  EdgeGroups out;
  out.order.resize(halfedges);
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (int h = 0; h < halfedges; ++h) out.order[fill[ends(h).first]++] = h;
  for (int v = 0; v < n; ++v) {
    std::sort(out.order.begin() + start[v], out.order.begin() + start[v + 1], [&](int x, int y) {
      return std::pair{ends(x).second, x} < std::pair{ends(y).second, y};
    });
  }
  for (int r = 0; r < halfedges; ++r) {
    if (r == 0 || ends(out.order[r]) != ends(out.order[r - 1])) out.first.push_back(r);
  }
  out.first.push_back(halfedges);
  return out;
}

// True where the mesh needs its tufted cover: an edge of three or more triangles, or two
// triangles that run along their shared edge in the same direction.
bool needs_cover(const TriangleMesh& mesh, const EdgeGroups& groups) {
  for (size_t e = 0; e + 1 < groups.first.size(); ++e) {
    const int size = groups.first[e + 1] - groups.first[e];
    const int x = groups.order[groups.first[e]];
    if (mesh.F(x / 3, x % 3) == mesh.F(x / 3, (x % 3 + 1) % 3)) continue;  // collapsed face
    if (size >= 3) return true;
    const int y = groups.order[groups.first[e] + size - 1];
    if (size == 2 && mesh.F(x / 3, x % 3) == mesh.F(y / 3, y % 3)) return true;
  }
  return false;
}

// The triangles of edge (u, v), u < v, given by their halfedges, in the order of their angle
// about the edge (right-handed about v - u).
void sort_about_edge(const TriangleMesh& mesh, int u, int v, std::vector<int>& halfedges) {
  const Eigen::Vector3d p = mesh.V.row(u), d = mesh.V.row(v) - mesh.V.row(u);
  if (!(d.norm() > 0.0)) return;
  const Eigen::Vector3d x = d.unitOrthogonal(), y = d.normalized().cross(x);
  std::vector<std::pair<double, int>> angles;
  for (int h : halfedges) {
    const Eigen::Vector3d w = mesh.V.row(mesh.F(h / 3, (h % 3 + 2) % 3)).transpose() - p;
    angles.emplace_back(std::atan2(w.dot(y), w.dot(x)), h);
  }
  std::sort(angles.begin(), angles.end());
  for (size_t r = 0; r < angles.size(); ++r) halfedges[r] = angles[r].second;
}

// The mesh's triangles (or its tufted cover's) with their Euclidean edge lengths plus eps (the
// mollification), glued.
Halfedges initial_triangulation(const TriangleMesh& mesh, const EdgeGroups& groups, bool cover,
                                double eps) {
  const int faces = mesh.num_faces(), sheets = cover ? 2 : 1;
  Halfedges t;
  t.vertex.resize(3 * size_t(faces) * sheets);
  t.twin.assign(t.vertex.size(), -1);
  t.length.resize(t.vertex.size());
  // Sheet 1 of face f is face f + faces with the corners reversed: its halfedge 2 - c runs along
  // sheet 0's halfedge c the other way.
  const auto reversed = [&](int h) { return 3 * (h / 3 + faces) + 2 - h % 3; };
  for (int h = 0; h < 3 * faces; ++h) {
    const int u = mesh.F(h / 3, h % 3), v = mesh.F(h / 3, (h % 3 + 1) % 3);
    t.vertex[h] = u;
    t.length[h] = (mesh.V.row(v) - mesh.V.row(u)).norm() + eps;
    if (cover) {
      t.vertex[reversed(h)] = v;
      t.length[reversed(h)] = t.length[h];
    }
  }
  std::vector<int> run;
  for (size_t e = 0; e + 1 < groups.first.size(); ++e) {
    run.assign(groups.order.begin() + groups.first[e], groups.order.begin() + groups.first[e + 1]);
    const int x = run[0];
    const int u = std::min(t.vertex[x], t.vertex[next(x)]);
    const int v = std::max(t.vertex[x], t.vertex[next(x)]);
    if (run.size() < 2 || u == v) continue;  // boundary, or an edge of a collapsed face
    if (!cover) {
      t.twin[run[0]] = run[1], t.twin[run[1]] = run[0];
      continue;
    }
    // Each triangle's side facing increasing angle holds its halfedge u -> v, the side facing
    // decreasing angle its halfedge v -> u; glue the sides that face each other across a wedge.
    if (run.size() > 2) sort_about_edge(mesh, u, v, run);
    const auto forward = [&](int h) { return t.vertex[h] == u ? h : reversed(h); };
    const auto backward = [&](int h) { return t.vertex[h] == u ? reversed(h) : h; };
    for (size_t r = 0; r < run.size(); ++r) {
      const int from = forward(run[r]), to = backward(run[(r + 1) % run.size()]);
      t.twin[from] = to, t.twin[to] = from;
    }
  }
  return t;
}

// Flips edges until every interior edge is Delaunay; returns the number of flips.
long long flip_to_delaunay(Halfedges& t) {
  const int halfedges = static_cast<int>(t.vertex.size());
  const long long limit = kFlipsPerEdge * (halfedges / 2 + 1);
  std::vector<int> stack;
  std::vector<char> queued(halfedges, 0);
  const auto push = [&](int h) {
    if (t.twin[h] >= 0 && !queued[h]) queued[h] = 1, stack.push_back(h);
  };
  for (int h = halfedges - 1; h >= 0; --h)
    if (t.twin[h] > h) push(h);
  long long flips = 0;
  while (!stack.empty()) {
    const int h = stack.back();
    stack.pop_back();
    queued[h] = 0;
    const int g = t.twin[h];
    if (g < 0 || g / 3 == h / 3) continue;
    if (!(t.opposite_cotangent(h) + t.opposite_cotangent(g) < -kFlipMargin)) continue;
    t.flip(h);
    if (++flips > limit) {
      throw SolverError("intrinsic Delaunay triangulation: more than " + std::to_string(limit) +
                        " edge flips; rounding keeps the flips going");
    }
    for (int s = 0; s < 3; ++s) push(h - h % 3 + s), push(g - g % 3 + s);
  }
  return flips;
}

// Twice the area of triangle t, or 0 if it is degenerate.
double double_area_or_zero(const IntrinsicTriangulation& tri, int t) {
  const double a = tri.length(t, 0), b = tri.length(t, 1), c = tri.length(t, 2);
  return degenerate(a, b, c) ? 0.0 : double_area(a, b, c);
}

// Half the cotangent of the angle opposite to each corner's edge of triangle t; 0 if degenerate.
Eigen::Array3d half_cotangents(const IntrinsicTriangulation& tri, int t) {
  const double area = double_area_or_zero(tri, t);
  if (area == 0.0) return Eigen::Array3d::Zero();
  const Eigen::Array3d squared = tri.length.row(t).array().square().transpose();
  // (b^2 + c^2 - a^2) / (4 A) for the edge a of each corner
  return (squared.sum() - 2.0 * squared) / (4.0 * area);
}

}  // namespace

IntrinsicTriangulation intrinsic_delaunay(const TriangleMesh& mesh) {
  const int n = mesh.num_vertices();
  if (mesh.num_faces() > 0 && (mesh.F.minCoeff() < 0 || mesh.F.maxCoeff() >= n)) {
    throw InputError("intrinsic Delaunay triangulation: a face refers to a vertex outside 0.." +
                     std::to_string(n - 1));
  }
  IntrinsicTriangulation out;
  out.num_vertices = n;
  const EdgeGroups groups = group_edges(mesh);
  out.tufted = needs_cover(mesh, groups);
  out.sheet_weight = out.tufted ? 0.5 : 1.0;
  Halfedges t = initial_triangulation(mesh, groups, out.tufted, mollification(mesh));
  out.flips = flip_to_delaunay(t);
  const int triangles = static_cast<int>(t.vertex.size() / 3);
  out.F.resize(triangles, 3);
  out.length.resize(triangles, 3);
  out.twin.resize(triangles, 3);
  for (int h = 0; h < 3 * triangles; ++h) {
    out.F(h / 3, h % 3) = t.vertex[h];
    out.length(h / 3, h % 3) = t.length[h];
    out.twin(h / 3, h % 3) = t.twin[h];
  }
  return out;
}

IntrinsicTriangulation mollified_triangulation(const TriangleMesh& mesh) {
  IntrinsicTriangulation out;
  out.num_vertices = mesh.num_vertices();
  out.F = mesh.F;
  out.length = mollified_lengths(mesh, mollification(mesh));
  out.twin.setConstant(mesh.num_faces(), 3, -1);
  return out;
}

double edge_weight(const IntrinsicTriangulation& tri, int t, int c) {
  double w = half_cotangents(tri, t)[c];
  const int h = tri.twin(t, c);
  if (h >= 0) w += half_cotangents(tri, h / 3)[h % 3];
  return tri.sheet_weight * w;
}

Sparse stiffness_matrix(const IntrinsicTriangulation& tri) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(12 * size_t(tri.F.rows()));
  for (int t = 0; t < tri.F.rows(); ++t) {
    const Eigen::Array3d half_cot = tri.sheet_weight * half_cotangents(tri, t);
    for (int c = 0; c < 3; ++c) {
      const double w = half_cot[c];
      if (w == 0.0) continue;
      const int i = tri.F(t, c), j = tri.F(t, (c + 1) % 3);
      triplets.emplace_back(i, j, -w);
      triplets.emplace_back(j, i, -w);
      triplets.emplace_back(i, i, w);
      triplets.emplace_back(j, j, w);
    }
  }
  Sparse K(tri.num_vertices, tri.num_vertices);
  K.setFromTriplets(triplets.begin(), triplets.end());
  K.makeCompressed();
  return K;
}

Sparse mass_matrix(const IntrinsicTriangulation& tri, MassType type) {
  const auto area = [&](int t) { return 0.5 * tri.sheet_weight * double_area_or_zero(tri, t); };
  Sparse M(tri.num_vertices, tri.num_vertices);
  if (type == MassType::Lumped) {
    Eigen::VectorXd m = Eigen::VectorXd::Zero(tri.num_vertices);
    for (int t = 0; t < tri.F.rows(); ++t)
      for (int a = 0; a < 3; ++a) m[tri.F(t, a)] += area(t) / 3.0;
    M = Sparse(m.asDiagonal());
  } else {
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(9 * size_t(tri.F.rows()));
    for (int t = 0; t < tri.F.rows(); ++t)
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          triplets.emplace_back(tri.F(t, a), tri.F(t, b), area(t) / (a == b ? 6.0 : 12.0));
    M.setFromTriplets(triplets.begin(), triplets.end());
  }
  M.makeCompressed();
  return M;
}

}  // namespace specdeform
