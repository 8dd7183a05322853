#include "operators/sliver_meshes.h"

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace specdeform::test {

TriangleMesh skewed_grid(int nx, int ny, double a, double b, int skew, double jitter) {
  TriangleMesh mesh;
  mesh.V.resize((nx + 1) * (ny + 1), 3);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> shift(-jitter, jitter);
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      const bool interior = i > 0 && i < nx && j > 0 && j < ny;
      const double x = (i + (interior ? shift(rng) : 0.0)) * a / nx;
      const double y = (j + (interior ? shift(rng) : 0.0)) * b / ny;
      mesh.V.row(j * (nx + 1) + i) << x, y, 0.0;
    }
  }
  std::vector<Eigen::RowVector3i> faces;
  for (int j = 0; j < ny; ++j) {
    // A zipper along the row: p on the lower line, q on the upper one. The upper line runs
    // `skew` vertices ahead, then both advance in turn.
    const auto lower = [&](int i) { return j * (nx + 1) + i; };
    const auto upper = [&](int i) { return (j + 1) * (nx + 1) + i; };
    int p = 0, q = 0;
    const auto advance_upper = [&] { faces.push_back({lower(p), upper(q + 1), upper(q)}), ++q; };
    const auto advance_lower = [&] { faces.push_back({lower(p), lower(p + 1), upper(q)}), ++p; };
    while (q < std::min(skew, nx)) advance_upper();
    while (q < nx) advance_lower(), advance_upper();
    while (p < nx) advance_lower();
  }
  mesh.F.resize(static_cast<int>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) mesh.F.row(f) = faces[f];
  return mesh;
}

TriangleMesh book(int pages, int n, int skew) {
  const TriangleMesh page = skewed_grid(n, n, 1.0, 1.0, skew);
  const int per_page = page.num_vertices(), spine = n + 1;
  // Page k keeps the spine's vertices (x = 0, grid column 0) and adds the others.
  TriangleMesh out;
  out.V.resize(spine + pages * (per_page - spine), 3);
  out.F.resize(pages * page.num_faces(), 3);
  for (int j = 0; j <= n; ++j) out.V.row(j) = page.V.row(j * (n + 1));
  for (int k = 0; k < pages; ++k) {
    const double angle = 2.0 * std::numbers::pi * k / pages;
    std::vector<int> index(per_page);
    for (int v = 0; v < per_page; ++v) {
      const int i = v % (n + 1), j = v / (n + 1);
      if (i == 0) {
        index[v] = j;
        continue;
      }
      index[v] = spine + k * (per_page - spine) + j * n + (i - 1);
      const double x = page.V(v, 0);
      out.V.row(index[v]) << x * std::cos(angle), page.V(v, 1), x * std::sin(angle);
    }
    for (int f = 0; f < page.num_faces(); ++f)
      for (int c = 0; c < 3; ++c) out.F(k * page.num_faces() + f, c) = index[page.F(f, c)];
  }
  return out;
}

}  // namespace specdeform::test
