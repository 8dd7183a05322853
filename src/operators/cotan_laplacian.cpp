#include "specdeform/operators/cotan_laplacian.h"

#include <algorithm>
#include <atomic>
#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "linalg/huge_pages.h"
#include "linalg/parallel.h"
#include "mesh/vertex_rings.h"

namespace specdeform {

namespace {

// Half the cotangent of each corner's angle (face f, corner k at 3 f + k), 0 for a degenerate
// face; *all_sound: whether no face is degenerate. Written once, on huge pages (33 MB at 692k
// vertices: zeroed first, its page faults were a tenth of the multilevel basis's).
std::unique_ptr<double[]> half_cotangents(const TriangleMesh& mesh, bool* all_sound) {
  const size_t size = 3 * size_t(mesh.num_faces());
  std::unique_ptr<double[]> out(new double[size]);
  detail::advise_huge_pages(out.get(), sizeof(double) * size);
  std::atomic<bool> degenerate = false;
  detail::split_in_two(mesh.num_faces(), [&](Eigen::Index begin, Eigen::Index end) {
    for (Eigen::Index f = begin; f < end; ++f) {
      const Eigen::Vector3d p[3] = {mesh.V.row(mesh.F(f, 0)), mesh.V.row(mesh.F(f, 1)),
                                    mesh.V.row(mesh.F(f, 2))};
      if (is_degenerate_triangle(p[0], p[1], p[2])) {
        for (int k = 0; k < 3; ++k) out[3 * f + k] = 0.0;
        degenerate = true;
        continue;
      }
      const double double_area = (p[1] - p[0]).cross(p[2] - p[0]).norm();
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d u = p[(k + 1) % 3] - p[k], v = p[(k + 2) % 3] - p[k];
        out[3 * f + k] = 0.5 * u.dot(v) / double_area;
      }
    }
  });
  *all_sound = !degenerate;
  return out;
}

}  // namespace

// Assembled by counting: the pattern from the vertex rings of the sound faces (each column: its
// ring and the diagonal, sorted), then each corner's weight added into the columns of its edge's
// two ends, the columns split between two threads, each walking all faces in order (the sums of
// the triplet assembly, to the bit, whatever the vertex numbering).
Eigen::SparseMatrix<double> cotan_stiffness(const TriangleMesh& mesh) {
  const int n = mesh.num_vertices();
  bool sound = true;
  const std::unique_ptr<const double[]> half_cot = half_cotangents(mesh, &sound);
  TriangleMesh kept;
  if (!sound) {  // rings of the sound faces only: a degenerate face adds no entry
    kept.V = mesh.V;
    kept.F.resize(mesh.num_faces(), 3);
    int count = 0;
    for (int f = 0; f < mesh.num_faces(); ++f)
      if (!is_degenerate_triangle(mesh.V.row(mesh.F(f, 0)), mesh.V.row(mesh.F(f, 1)),
                                  mesh.V.row(mesh.F(f, 2))))
        kept.F.row(count++) = mesh.F.row(f);
    kept.F.conservativeResize(count, 3);
  }
  const detail::VertexRings rings = detail::vertex_rings(sound ? mesh : kept);
  Eigen::SparseMatrix<double> K(n, n);
  K.resizeNonZeros(static_cast<Eigen::Index>(rings.neighbour.size()) + n);
  detail::advise_huge_pages(K);
  int* outer = K.outerIndexPtr();
  int* inner = K.innerIndexPtr();
  double* value = K.valuePtr();
  outer[0] = 0;
  for (int j = 0; j < n; ++j) {
    int at = outer[j];
    const int size = rings.size(j);
    const int* ring = rings.neighbour.data() + rings.start[j];
    const int below = static_cast<int>(std::lower_bound(ring, ring + size, j) - ring);
    at = std::copy(ring, ring + below, inner + at) - inner;
    if (size > 0) inner[at++] = j;
    at = std::copy(ring + below, ring + size, inner + at) - inner;
    outer[j + 1] = at;
  }
  K.resizeNonZeros(outer[n]);  // vertices of no sound face have no diagonal either (shrinks)
  inner = K.innerIndexPtr();
  value = K.valuePtr();
  std::fill(value, value + outer[n], 0.0);
  const auto entry = [&](int row, int col) -> double& {
    return value[std::lower_bound(inner + outer[col], inner + outer[col + 1], row) - inner];
  };
  detail::split_in_two(n, [&](Eigen::Index begin, Eigen::Index end) {
    for (int f = 0; f < mesh.num_faces(); ++f) {
      for (int k = 0; k < 3; ++k) {
        // The angle at corner k is opposite to the edge (k+1, k+2).
        const int i = mesh.F(f, (k + 1) % 3), j = mesh.F(f, (k + 2) % 3);
        const double w = half_cot[3 * f + k];
        if (w == 0.0) continue;
        if (j >= begin && j < end) {
          entry(i, j) -= w;
          entry(j, j) += w;
        }
        if (i >= begin && i < end) {
          entry(j, i) -= w;
          entry(i, i) += w;
        }
      }
    }
  });
  return K;
}

Eigen::Matrix3d hat_gradients(const TriangleMesh& mesh, int f) {
  return hat_gradients(mesh.V.row(mesh.F(f, 0)), mesh.V.row(mesh.F(f, 1)),
                       mesh.V.row(mesh.F(f, 2)));
}

Eigen::Matrix3d hat_gradients(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                              const Eigen::Vector3d& c) {
  const Eigen::Vector3d p[3] = {a, b, c};
  if (is_degenerate_triangle(p[0], p[1], p[2])) return Eigen::Matrix3d::Zero();
  const Eigen::Vector3d normal = (p[1] - p[0]).cross(p[2] - p[0]);
  Eigen::Matrix3d g;
  for (int k = 0; k < 3; ++k) {
    // grad phi_k = (n x e_k) / |n|^2, e_k the edge opposite to corner k, counter-clockwise.
    g.row(k) =
        normal.cross(Eigen::Vector3d(p[(k + 2) % 3] - p[(k + 1) % 3])) / normal.squaredNorm();
  }
  return g;
}

Eigen::SparseMatrix<double> gradient_operator(const TriangleMesh& mesh) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(9 * size_t(mesh.num_faces()));
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Matrix3d g = hat_gradients(mesh, f);
    if (g.isZero(0.0)) continue;  // degenerate: no entries
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) triplets.emplace_back(3 * f + d, mesh.F(f, k), g(k, d));
  }
  Eigen::SparseMatrix<double> G(3 * mesh.num_faces(), mesh.num_vertices());
  G.setFromTriplets(triplets.begin(), triplets.end());
  G.makeCompressed();
  return G;
}

}  // namespace specdeform
