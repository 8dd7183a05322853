#include "specdeform/mesh/generate.h"

#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>
#include <vector>

#include "specdeform/exceptions.h"

namespace specdeform {

namespace {

constexpr double kPi = std::numbers::pi;

TriangleMesh from_lists(const std::vector<Eigen::Vector3d>& points,
                        const std::vector<std::array<int, 3>>& tris) {
  TriangleMesh m;
  m.V.resize(static_cast<int>(points.size()), 3);
  for (size_t i = 0; i < points.size(); ++i) m.V.row(i) = points[i];
  m.F.resize(static_cast<int>(tris.size()), 3);
  for (size_t f = 0; f < tris.size(); ++f) m.F.row(f) << tris[f][0], tris[f][1], tris[f][2];
  return m;
}

// Two counter-clockwise triangles for the quad a-b-c-d (in that order around it).
void add_quad(std::vector<std::array<int, 3>>& tris, int a, int b, int c, int d) {
  tris.push_back({a, b, c});
  tris.push_back({a, c, d});
}

}  // namespace

TriangleMesh make_bumpy_bar(const BumpyBarOptions& o) {
  if (o.length <= 0 || o.thickness <= 0 || o.cells_per_unit < 1) {
    throw InputError("bumpy bar: length, thickness and cells_per_unit must be positive");
  }
  const int nx = std::max(1, static_cast<int>(std::lround(o.length * o.cells_per_unit)));
  const int ny = std::max(1, static_cast<int>(std::lround(o.thickness * o.cells_per_unit)));
  const int bumps_along = static_cast<int>(std::lround(o.bumps_per_unit * o.length));
  const int bumps_across = static_cast<int>(std::lround(o.bumps_per_unit * o.thickness));
  std::map<std::array<int, 3>, int> index;
  std::vector<Eigen::Vector3d> points;
  const auto vertex = [&](int i, int j, int k) {
    const auto [it, inserted] = index.try_emplace({i, j, k}, static_cast<int>(points.size()));
    if (inserted) {
      const double x = o.length * i / nx;
      const double y = o.thickness * (double(j) / ny - 0.5);
      const double z = o.thickness * (double(k) / ny - 0.5);
      Eigen::Vector3d p(x, y, z);
      // Bumps on the long sides only, away from the bar's edges and the end caps.
      const bool side_y = (j == 0 || j == ny) && k > 0 && k < ny;
      const bool side_z = (k == 0 || k == ny) && j > 0 && j < ny;
      if ((side_y || side_z) && i > 0 && i < nx) {
        const double across = side_y ? double(k) / ny : double(j) / ny;
        const double s = std::sin(kPi * bumps_along * i / nx);
        const double t = std::sin(kPi * bumps_across * across);
        const double h = o.bump_height * s * s * t * t;
        if (side_y) p.y() += (j == 0 ? -h : h);
        if (side_z) p.z() += (k == 0 ? -h : h);
      }
      points.push_back(p);
    }
    return it->second;
  };
  std::vector<std::array<int, 3>> tris;
  for (int i = 0; i < nx; ++i) {
    for (int a = 0; a < ny; ++a) {
      // Long sides, outward normals -z, +z, -y, +y.
      add_quad(tris, vertex(i, a, 0), vertex(i, a + 1, 0), vertex(i + 1, a + 1, 0),
               vertex(i + 1, a, 0));
      add_quad(tris, vertex(i, a, ny), vertex(i + 1, a, ny), vertex(i + 1, a + 1, ny),
               vertex(i, a + 1, ny));
      add_quad(tris, vertex(i, 0, a), vertex(i + 1, 0, a), vertex(i + 1, 0, a + 1),
               vertex(i, 0, a + 1));
      add_quad(tris, vertex(i, ny, a), vertex(i, ny, a + 1), vertex(i + 1, ny, a + 1),
               vertex(i + 1, ny, a));
    }
  }
  for (int a = 0; a < ny; ++a) {
    for (int b = 0; b < ny; ++b) {
      // End caps, outward normals -x and +x.
      add_quad(tris, vertex(0, a, b), vertex(0, a, b + 1), vertex(0, a + 1, b + 1),
               vertex(0, a + 1, b));
      add_quad(tris, vertex(nx, a, b), vertex(nx, a + 1, b), vertex(nx, a + 1, b + 1),
               vertex(nx, a, b + 1));
    }
  }
  return from_lists(points, tris);
}

TriangleMesh make_bumpy_tube(const BumpyTubeOptions& o) {
  if (o.length <= 0 || o.radius <= 0 || o.segments < 3 || o.cells_per_unit < 1) {
    throw InputError(
        "bumpy tube: length, radius, cells_per_unit and segments (>= 3) must be "
        "positive");
  }
  const int rings = std::max(1, static_cast<int>(std::lround(o.length * o.cells_per_unit))) + 1;
  const int bumps_along = static_cast<int>(std::lround(o.bumps_per_unit * o.length));
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < rings; ++i) {
    const double x = o.length * i / (rings - 1);
    for (int a = 0; a < o.segments; ++a) {
      const double angle = 2 * kPi * a / o.segments;
      const double s = std::sin(kPi * bumps_along * i / (rings - 1));
      const double t = std::sin(0.5 * o.bumps_around * angle);
      const double r = o.radius + o.bump_height * s * s * t * t;
      points.emplace_back(x, r * std::cos(angle), r * std::sin(angle));
    }
  }
  const int first = static_cast<int>(points.size()), last = first + 1;
  points.emplace_back(0.0, 0.0, 0.0);
  points.emplace_back(o.length, 0.0, 0.0);
  std::vector<std::array<int, 3>> tris;
  const auto id = [&](int i, int a) { return i * o.segments + (a % o.segments); };
  for (int i = 0; i + 1 < rings; ++i)
    for (int a = 0; a < o.segments; ++a)
      add_quad(tris, id(i, a), id(i, a + 1), id(i + 1, a + 1), id(i + 1, a));
  for (int a = 0; a < o.segments; ++a) {
    tris.push_back({first, id(0, a + 1), id(0, a)});
    tris.push_back({last, id(rings - 1, a), id(rings - 1, a + 1)});
  }
  return from_lists(points, tris);
}

TriangleMesh make_bumpy_plane(const BumpyPlaneOptions& o) {
  if (o.size <= 0 || o.resolution < 1) {
    throw InputError("bumpy plane: size and resolution must be positive");
  }
  const int r = o.resolution;
  std::vector<Eigen::Vector3d> points;
  for (int j = 0; j <= r; ++j) {
    for (int i = 0; i <= r; ++i) {
      const double x = o.size * i / r, y = o.size * j / r;
      const double s = std::sin(kPi * o.bumps * i / r), t = std::sin(kPi * o.bumps * j / r);
      points.emplace_back(x, y, o.bump_height * s * s * t * t);
    }
  }
  std::vector<std::array<int, 3>> tris;
  const auto id = [r](int i, int j) { return j * (r + 1) + i; };
  for (int j = 0; j < r; ++j)
    for (int i = 0; i < r; ++i)
      add_quad(tris, id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
  return from_lists(points, tris);
}

TriangleMesh make_icosphere(int subdivisions, double radius) {
  if (subdivisions < 0 || subdivisions > 9) {
    throw InputError("icosphere: subdivisions must be in [0, 9]");
  }
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> points = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                         {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                         {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : points) p.normalize();
  std::vector<std::array<int, 3>> tris = {
      {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> midpoint;
    const auto mid = [&](int a, int b) {
      const auto [it, inserted] =
          midpoint.try_emplace({std::min(a, b), std::max(a, b)}, static_cast<int>(points.size()));
      if (inserted) points.push_back((points[a] + points[b]).normalized());
      return it->second;
    };
    std::vector<std::array<int, 3>> finer;
    finer.reserve(4 * tris.size());
    for (const auto& [a, b, c] : tris) {
      const int ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      finer.push_back({a, ab, ca});
      finer.push_back({b, bc, ab});
      finer.push_back({c, ca, bc});
      finer.push_back({ab, bc, ca});
    }
    tris = std::move(finer);
  }
  for (auto& p : points) p *= radius;
  return from_lists(points, tris);
}

TriangleMesh make_torus(double major_radius, double minor_radius, int major_segments,
                        int minor_segments) {
  if (major_segments < 3 || minor_segments < 3 || minor_radius <= 0 ||
      major_radius <= minor_radius) {
    throw InputError("torus: needs R > r > 0 and at least 3 segments each way");
  }
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < major_segments; ++i) {
    const double u = 2 * kPi * i / major_segments;
    for (int j = 0; j < minor_segments; ++j) {
      const double v = 2 * kPi * j / minor_segments;
      const double rr = major_radius + minor_radius * std::cos(v);
      points.emplace_back(rr * std::cos(u), rr * std::sin(u), minor_radius * std::sin(v));
    }
  }
  std::vector<std::array<int, 3>> tris;
  const auto id = [&](int i, int j) {
    return (i % major_segments) * minor_segments + (j % minor_segments);
  };
  for (int i = 0; i < major_segments; ++i)
    for (int j = 0; j < minor_segments; ++j)
      add_quad(tris, id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
  return from_lists(points, tris);
}

}  // namespace specdeform
