#include "file_normals.h"

#include <array>
#include <cmath>
#include <map>
#include <vector>

#include <Eigen/Dense>

#include "linalg/nearest_rotation.h"

namespace specdeform::detail {

namespace {

using Vec = Eigen::Vector3d;

// A polygon corner's triangle: its vertex, the next and the previous corner's.
struct Corner {
  int v, next, prev;
};

template <typename Visit>
void for_each_corner(const FileAttributes& a, const Visit& visit) {
  for (int p = 0; p < a.num_polygons(); ++p) {
    const int begin = a.offsets[p], k = a.offsets[p + 1] - begin;
    for (int c = 0; c < k; ++c) {
      visit(p, begin + c,
            Corner{a.corners[begin + c], a.corners[begin + (c + 1) % k],
                   a.corners[begin + (c + k - 1) % k]});
    }
  }
}

// The corner's frame [e1 e2 n] (n the unit normal of e1 x e2); false where degenerate.
bool frame(const Vertices& X, const Corner& c, Eigen::Matrix3d& out) {
  const Vec e1 = X.row(c.next) - X.row(c.v), e2 = X.row(c.prev) - X.row(c.v);
  const Vec n = e1.cross(e2);
  const double scale = e1.squaredNorm() * e2.squaredNorm();
  if (!(n.squaredNorm() > 1e-24 * scale)) return false;
  out << e1, e2, n.normalized();
  return true;
}

double angle(const Eigen::Matrix3d& frame) {
  return std::atan2(frame.col(0).cross(frame.col(1)).norm(), frame.col(0).dot(frame.col(1)));
}

// Polygons with a corner away from its rest position.
std::vector<char> moved_polygons(const FileAttributes& a, const Vertices& rest,
                                 const Vertices& deformed) {
  std::vector<char> moved(a.num_polygons(), 0);
  for_each_corner(a, [&](int p, int, const Corner& c) {
    if (rest.row(c.v) != deformed.row(c.v)) moved[p] = 1;
  });
  return moved;
}

// Per row: the sum of each corner's `contribution` (a vector) times its weight, over the corners
// of moved polygons that use the row; `used` says which rows have such a corner.
template <typename Contribution>
Eigen::MatrixX3d sum_over_corners(const FileAttributes& a, const std::vector<int>& rows,
                                  Eigen::Index count, const std::vector<char>& moved,
                                  std::vector<char>& used, const Contribution& contribution) {
  Eigen::MatrixX3d sum = Eigen::MatrixX3d::Zero(count, 3);
  used.assign(count, 0);
  for_each_corner(a, [&](int p, int corner, const Corner& c) {
    const int row = rows[corner];
    if (row < 0 || !moved[p]) return;
    used[row] = 1;
    sum.row(row) += contribution(c, row).transpose();
  });
  return sum;
}

Eigen::MatrixX3d recomputed(const FileAttributes& a, const Vertices& deformed,
                            const std::vector<char>& moved, std::vector<char>& used) {
  return sum_over_corners(a, a.corner_normal, a.normals.rows(), moved, used,
                          [&](const Corner& c, int) -> Vec {
                            Eigen::Matrix3d d;
                            if (!frame(deformed, c, d)) return Vec::Zero();
                            return angle(d) * d.col(2);
                          });
}

}  // namespace

std::vector<Eigen::Matrix3d> vertex_rotations(const FileAttributes& a, const Vertices& rest,
                                              const Vertices& deformed, std::vector<char>& turned) {
  // File vertices at the same rest position (split along seams and hard edges) share a ring.
  std::map<std::array<double, 3>, int> welded;
  std::vector<int> ring(rest.rows());
  for (Eigen::Index v = 0; v < rest.rows(); ++v) {
    ring[v] = welded.emplace(std::array{rest(v, 0), rest(v, 1), rest(v, 2)}, int(welded.size()))
                  .first->second;
  }
  std::vector<Eigen::Matrix3d> cov(welded.size(), Eigen::Matrix3d::Zero());
  std::vector<char> moved(welded.size(), 0);
  for_each_corner(a, [&](int, int, const Corner& c) {
    const Vec e = rest.row(c.next) - rest.row(c.v), d = deformed.row(c.next) - deformed.row(c.v);
    const bool edge_moved =
        rest.row(c.next) != deformed.row(c.next) || rest.row(c.v) != deformed.row(c.v);
    for (const int v : {ring[c.v], ring[c.next]}) {
      cov[v] += d * e.transpose();
      moved[v] |= edge_moved;
    }
  });
  std::vector<Eigen::Matrix3d> out(rest.rows(), Eigen::Matrix3d::Identity());
  turned.assign(rest.rows(), 0);
  for (Eigen::Index v = 0; v < rest.rows(); ++v) {
    const int r = ring[v];
    if (!moved[r] || cov[r].isZero()) continue;
    out[v] = nearest_rotation(cov[r]);
    turned[v] = 1;
  }
  return out;
}

SharedNormals shared_normals(const FileAttributes& a, const Vertices& rest,
                             const Vertices& deformed, const Eigen::MatrixX3d& normals) {
  // The rows used at more than one position.
  std::vector<int> position(a.normals.rows(), -1);
  std::vector<char> shared(a.normals.rows(), 0);
  for (size_t c = 0; c < a.corners.size(); ++c) {
    const int row = a.corner_normal[c];
    if (row < 0) continue;
    const Eigen::RowVector3d p = rest.row(a.corners[c]);
    if (position[row] < 0) {
      position[row] = a.corners[c];
    } else if (rest.row(position[row]) != p) {
      shared[row] = 1;
    }
  }
  std::vector<double> spread(a.normals.rows(), 0.0);
  for_each_corner(a, [&](int, int corner, const Corner& c) {
    const int row = a.corner_normal[corner];
    if (row < 0 || !shared[row]) return;
    Eigen::Matrix3d r, d;
    if (!frame(rest, c, r) || !frame(deformed, c, d)) return;
    const Vec own =
        d.transpose().partialPivLu().solve(r.transpose() * a.normals.row(row).transpose());
    const Vec written = normals.row(row).transpose();
    spread[row] = std::max(spread[row], std::atan2(own.cross(written).norm(), own.dot(written)));
  });
  SharedNormals out;
  for (const double s : spread) {
    const double degrees = s * 180.0 / M_PI;
    if (degrees > SharedNormals::kTurnedApart) ++out.turned_apart;
    out.largest_degrees = std::max(out.largest_degrees, degrees);
  }
  return out;
}

Eigen::MatrixX3d updated_normals(const FileAttributes& a, const Vertices& rest,
                                 const Vertices& deformed, NormalUpdate mode) {
  const std::vector<char> moved = moved_polygons(a, rest, deformed);
  std::vector<char> used, used_recomputed;
  Eigen::MatrixX3d sum;
  if (mode == NormalUpdate::Follow) {
    sum = sum_over_corners(
        a, a.corner_normal, a.normals.rows(), moved, used, [&](const Corner& c, int row) -> Vec {
          Eigen::Matrix3d r, d;
          if (!frame(rest, c, r) || !frame(deformed, c, d)) return Vec::Zero();
          // J^-T n = D^-T R^T n
          const Vec n =
              d.transpose().partialPivLu().solve(r.transpose() * a.normals.row(row).transpose());
          return angle(d) * n.normalized();
        });
  } else if (mode == NormalUpdate::Rotate) {
    std::vector<char> turned;
    const std::vector<Eigen::Matrix3d> rotation = vertex_rotations(a, rest, deformed, turned);
    sum = sum_over_corners(a, a.corner_normal, a.normals.rows(), moved, used,
                           [&](const Corner& c, int row) -> Vec {
                             return rotation[c.v] * a.normals.row(row).transpose();
                           });
  } else {
    sum = recomputed(a, deformed, moved, used);
  }
  Eigen::MatrixX3d fallback;
  Eigen::MatrixX3d out = a.normals;
  for (Eigen::Index row = 0; row < out.rows(); ++row) {
    if (!used[row]) continue;
    double norm = sum.row(row).norm();
    if (!(norm > 1e-12) && mode != NormalUpdate::Recompute) {
      if (fallback.size() == 0) fallback = recomputed(a, deformed, moved, used_recomputed);
      sum.row(row) = fallback.row(row);
      norm = sum.row(row).norm();
    }
    if (norm > 1e-12) out.row(row) = sum.row(row) / norm;
  }
  return out;
}

Eigen::MatrixX3d updated_tangents(const FileAttributes& a, const Vertices& rest,
                                  const Vertices& deformed, const Eigen::MatrixX3d& tangents,
                                  const Eigen::MatrixX3d& normals) {
  const std::vector<char> moved = moved_polygons(a, rest, deformed);
  std::vector<char> used;
  const Eigen::MatrixX3d sum = sum_over_corners(
      a, a.corner_normal, tangents.rows(), moved, used, [&](const Corner& c, int row) -> Vec {
        Eigen::Matrix3d r, d;
        if (!frame(rest, c, r) || !frame(deformed, c, d)) return Vec::Zero();
        // J t = D R^-1 t
        const Vec t = d * r.partialPivLu().solve(tangents.row(row).transpose());
        return angle(d) * t.normalized();
      });
  Eigen::MatrixX3d out = tangents;
  for (Eigen::Index row = 0; row < out.rows(); ++row) {
    if (!used[row]) continue;
    const Vec n = normals.row(row).transpose();
    const Vec t = sum.row(row).transpose() - n.dot(sum.row(row)) * n;
    if (t.norm() > 1e-12) out.row(row) = t.normalized().transpose();
  }
  return out;
}

}  // namespace specdeform::detail
