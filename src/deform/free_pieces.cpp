#include "deform/free_pieces.h"

#include <algorithm>
#include <limits>
#include <memory>

#include "linalg/nearest_rotation.h"
#include "mesh/triangle_tree.h"
#include "specdeform/exceptions.h"

namespace specdeform::detail {

namespace {

// Barycentric coordinates of p (on or near the triangle's plane) in the triangle (a, b, c).
Eigen::Vector3d barycentric(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  Eigen::Matrix<double, 3, 2> E;
  E << b - a, c - a;
  const Eigen::Vector2d uv = (E.transpose() * E).ldlt().solve(E.transpose() * (p - a));
  return {1.0 - uv.sum(), uv[0], uv[1]};
}

// The triangle's edge frame: its two edges and its normal, scaled like an edge.
Eigen::Matrix3d edge_frame(const Vertices& V, const Eigen::Vector3i& f) {
  const Eigen::Vector3d a = V.row(f[0]);
  const Eigen::Vector3d e1 = V.row(f[1]).transpose() - a, e2 = V.row(f[2]).transpose() - a;
  const Eigen::Vector3d n = e1.cross(e2);
  Eigen::Matrix3d frame;
  frame << e1, e2, n / std::sqrt(std::max(n.norm(), 1e-300));
  return frame;
}

// A sample's closest point on a surface: its face, barycentric coordinates, distance and
// weight 1 / (distance + softening)^2.
struct Closest {
  int face;
  Eigen::Vector3d barycentric;
  double distance, weight;
};

// Triangles of the driving surface (mesh face numbers beside them) and their tree, built once
// all are added.
class Surface {
 public:
  void add(const TreeTriangle& t, int face) {
    triangles.push_back(t);
    faces_.push_back(face);
  }
  void build() {
    if (tree_ || triangles.empty()) return;
    tree_ = std::make_unique<TriangleTree>(triangles.cbegin(), triangles.cend());
    tree_->accelerate_distance_queries();
  }
  Closest closest(const TriangleMesh& mesh, int v, double softening) const {
    const auto [q, it] = tree_->closest_point_and_primitive(tree_point(mesh.V, v));
    const int f = faces_[it - triangles.cbegin()];
    const Eigen::Vector3d p(q.x(), q.y(), q.z());
    const double distance = (p - mesh.V.row(v).transpose()).norm();
    const double d = distance + softening;
    return {f,
            barycentric(p, mesh.V.row(mesh.F(f, 0)), mesh.V.row(mesh.F(f, 1)),
                        mesh.V.row(mesh.F(f, 2))),
            distance, 1.0 / (d * d)};
  }

  std::vector<TreeTriangle> triangles;

 private:
  std::vector<int> faces_;
  std::unique_ptr<TriangleTree> tree_;
};

}  // namespace

FreePieces::FreePieces(const TriangleMesh& mesh, const Eigen::VectorXi& components,
                       const std::vector<char>& driving, const FreePiecePolicy& policy)
    : faces_(mesh.F) {
  std::vector<int> piece_of(driving.size(), -1);
  for (size_t c = 0; c < driving.size(); ++c) {
    if (!driving[c]) {
      piece_of[c] = static_cast<int>(pieces_.size());
      pieces_.emplace_back();
    }
  }
  if (pieces_.empty()) return;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    if (piece_of[components[v]] >= 0) pieces_[piece_of[components[v]]].vertices.push_back(v);
  }
  // The driving surface, all of it and piece by piece.
  const size_t count = driving.size();
  Surface all;
  std::vector<Surface> by_piece(count);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const int c = components[mesh.F(f, 0)];
    if (!driving[c]) continue;
    const TreeTriangle t(tree_point(mesh.V, mesh.F(f, 0)), tree_point(mesh.V, mesh.F(f, 1)),
                         tree_point(mesh.V, mesh.F(f, 2)));
    if (t.is_degenerate()) continue;
    all.add(t, f);
    by_piece[c].add(t, f);
  }
  if (all.triangles.empty()) {
    throw InputError("free pieces: the constrained pieces have no triangle to follow");
  }
  all.build();
  for (Piece& piece : pieces_) {
    Eigen::AlignedBox3d box;
    for (const int v : piece.vertices) box.extend(Eigen::Vector3d(mesh.V.row(v)));
    const double softening = policy.softening * std::max(box.diagonal().norm(), 1e-300);
    const size_t samples = std::min<size_t>(piece.vertices.size(), policy.samples);
    std::vector<int> sampled(samples);
    for (size_t s = 0; s < samples; ++s)
      sampled[s] = piece.vertices[s * piece.vertices.size() / samples];
    // The constrained piece it follows: the nearest one; among those within `softening` of
    // the nearest distance (several contacts), the one it touches over the most samples'
    // weight.
    std::vector<double> nearest(count, std::numeric_limits<double>::infinity()), weight(count, 0);
    for (const int v : sampled) {
      const Closest q = all.closest(mesh, v, softening);
      const int c = components[mesh.F(q.face, 0)];
      nearest[c] = std::min(nearest[c], q.distance);
      weight[c] += q.weight;
    }
    const double closest = *std::min_element(nearest.begin(), nearest.end());
    int followed = -1;
    for (size_t c = 0; c < count; ++c) {
      if (nearest[c] <= closest + softening && (followed < 0 || weight[c] > weight[followed]))
        followed = static_cast<int>(c);
    }
    Surface& surface = by_piece[followed];
    surface.build();
    for (const int v : sampled) {
      const Closest q = surface.closest(mesh, v, softening);
      piece.samples.push_back({q.face, q.barycentric, q.weight});
    }
  }
}

std::vector<Eigen::Affine3d> FreePieces::motions(const Vertices& rest,
                                                 const Vertices& deformed) const {
  std::vector<Eigen::Affine3d> out;
  out.reserve(pieces_.size());
  for (const Piece& piece : pieces_) {
    Eigen::Matrix3d rotations = Eigen::Matrix3d::Zero();
    for (const Sample& s : piece.samples) {
      const Eigen::Vector3i f = faces_.row(s.face);
      const Eigen::Matrix3d gradient = edge_frame(deformed, f) * edge_frame(rest, f).inverse();
      rotations += s.weight * nearest_rotation(gradient);
    }
    const Eigen::Matrix3d R = nearest_rotation(rotations);
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    double weights = 0.0;
    for (const Sample& s : piece.samples) {
      Eigen::Vector3d q = Eigen::Vector3d::Zero(), q_deformed = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) {
        q += s.barycentric[k] * rest.row(faces_(s.face, k)).transpose();
        q_deformed += s.barycentric[k] * deformed.row(faces_(s.face, k)).transpose();
      }
      t += s.weight * (q_deformed - R * q);
      weights += s.weight;
    }
    Eigen::Affine3d motion = Eigen::Affine3d::Identity();
    motion.linear() = R;
    motion.translation() = t / weights;
    out.push_back(motion);
  }
  return out;
}

void FreePieces::apply(const std::vector<Eigen::Affine3d>& motions, const Vertices& positions,
                       Vertices& out) const {
  for (size_t p = 0; p < pieces_.size(); ++p) {
    for (const int v : pieces_[p].vertices)
      out.row(v) = (motions[p] * positions.row(v).transpose()).transpose();
  }
}

}  // namespace specdeform::detail
