#include "specdeform/mesh/subdivide.h"

#include <algorithm>
#include <vector>

#include "specdeform/exceptions.h"

namespace specdeform {

namespace {

struct EdgeRecord {
  int a, b;  // a < b
  int face, opposite;
  bool operator<(const EdgeRecord& o) const { return a != o.a ? a < o.a : b < o.b; }
};

TriangleMesh subdivide_once(const TriangleMesh& mesh, SubdivisionScheme scheme) {
  const int n = mesh.num_vertices(), nf = mesh.num_faces();
  std::vector<EdgeRecord> rec;
  rec.reserve(3 * size_t(nf));
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int i = mesh.F(f, k), j = mesh.F(f, (k + 1) % 3);
      rec.push_back({std::min(i, j), std::max(i, j), f, mesh.F(f, (k + 2) % 3)});
    }
  }
  std::sort(rec.begin(), rec.end());
  // Per face corner k: the new vertex on edge (k, k+1).
  std::vector<int> edge_vertex(3 * size_t(nf));
  std::vector<Eigen::Vector3d> odd;
  std::vector<char> crease_vertex(n, 0);
  Eigen::MatrixX3d neighbour_sum = Eigen::MatrixX3d::Zero(n, 3), crease_sum = neighbour_sum;
  std::vector<int> valence(n, 0), crease_valence(n, 0);
  for (size_t s = 0; s < rec.size();) {
    size_t e = s;
    while (e < rec.size() && rec[e].a == rec[s].a && rec[e].b == rec[s].b) ++e;
    const int a = rec[s].a, b = rec[s].b, id = n + static_cast<int>(odd.size());
    const Eigen::Vector3d pa = mesh.V.row(a), pb = mesh.V.row(b);
    const bool crease = e - s != 2;
    if (scheme == SubdivisionScheme::Midpoint || crease) {
      odd.push_back(0.5 * (pa + pb));
    } else {
      const Eigen::Vector3d c = mesh.V.row(rec[s].opposite), d = mesh.V.row(rec[s + 1].opposite);
      odd.push_back(0.375 * (pa + pb) + 0.125 * (c + d));
    }
    for (size_t r = s; r < e; ++r) {
      const int f = rec[r].face;
      for (int k = 0; k < 3; ++k) {
        const int i = mesh.F(f, k), j = mesh.F(f, (k + 1) % 3);
        if (std::min(i, j) == a && std::max(i, j) == b) edge_vertex[3 * size_t(f) + k] = id;
      }
    }
    neighbour_sum.row(a) += pb.transpose();
    neighbour_sum.row(b) += pa.transpose();
    ++valence[a];
    ++valence[b];
    if (crease) {
      crease_vertex[a] = crease_vertex[b] = 1;
      crease_sum.row(a) += pb.transpose();
      crease_sum.row(b) += pa.transpose();
      ++crease_valence[a];
      ++crease_valence[b];
    }
    s = e;
  }
  TriangleMesh out;
  out.V.resize(n + static_cast<int>(odd.size()), 3);
  for (int i = 0; i < n; ++i) {
    const Eigen::RowVector3d p = mesh.V.row(i);
    if (scheme == SubdivisionScheme::Midpoint || valence[i] == 0) {
      out.V.row(i) = p;
    } else if (crease_vertex[i]) {
      // A regular boundary vertex follows the boundary curve; corners stay put.
      out.V.row(i) =
          crease_valence[i] == 2 ? Eigen::RowVector3d(0.75 * p + 0.125 * crease_sum.row(i)) : p;
    } else {
      const int k = valence[i];
      const double beta = k == 3 ? 3.0 / 16.0 : 3.0 / (8.0 * k);
      out.V.row(i) = (1.0 - k * beta) * p + beta * neighbour_sum.row(i);
    }
  }
  for (size_t e = 0; e < odd.size(); ++e) out.V.row(n + static_cast<int>(e)) = odd[e];
  out.F.resize(4 * nf, 3);
  for (int f = 0; f < nf; ++f) {
    const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
    const int ab = edge_vertex[3 * size_t(f)], bc = edge_vertex[3 * size_t(f) + 1],
              ca = edge_vertex[3 * size_t(f) + 2];
    out.F.row(4 * f) << a, ab, ca;
    out.F.row(4 * f + 1) << b, bc, ab;
    out.F.row(4 * f + 2) << c, ca, bc;
    out.F.row(4 * f + 3) << ab, bc, ca;
  }
  return out;
}

}  // namespace

TriangleMesh subdivide(const TriangleMesh& mesh, int levels, SubdivisionScheme scheme) {
  if (levels < 0) throw InputError("subdivide: the number of levels must be >= 0");
  TriangleMesh out = mesh;
  for (int l = 0; l < levels; ++l) out = subdivide_once(out, scheme);
  return out;
}

}  // namespace specdeform
