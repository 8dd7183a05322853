#include "specdeform/deform/selection.h"

#include <string>

#include <Eigen/Geometry>

#include "specdeform/exceptions.h"
#include "specdeform/mesh/mesh_info.h"

namespace specdeform {

namespace {

// The farthest a target may lie from its vertex, in sizes of the constrained region.
constexpr double kLargestMove = 1e6;

}  // namespace

ConstrainedSet constrained_set(const Selection& selection, const TriangleMesh& mesh,
                               UnconstrainedPieces pieces, const std::vector<int>& file_index,
                               std::string_view name) {
  int count = 0;
  const Eigen::VectorXi components = vertex_components(mesh, &count);
  return constrained_set(selection, components, count, pieces, file_index, name);
}

ConstrainedSet constrained_set(const Selection& selection, const Eigen::VectorXi& label,
                               int components, UnconstrainedPieces pieces,
                               const std::vector<int>& file_index, std::string_view name) {
  const int n = static_cast<int>(label.size());
  const auto vertex = [&](int v) {
    return "vertex " + std::to_string(file_index.empty() ? v : file_index[v]);
  };
  ConstrainedSet set;
  set.num_groups = static_cast<int>(selection.handles.size());
  std::vector<int> owner(n, -2);
  const auto add = [&](int v, int group) {
    if (v < 0 || v >= n) {
      throw InputError(std::string(name) + ": vertex " + std::to_string(v) +
                       " is out of range (the mesh has " + std::to_string(n) + " vertices)");
    }
    if (owner[v] != -2) {
      if (owner[v] == group) return;  // listed twice in the same group
      const auto which = [](int g) {
        return g < 0 ? std::string("the fixed set") : "handle group " + std::to_string(g);
      };
      throw InputError(std::string(name) + ": " + vertex(v) + " is in " + which(owner[v]) +
                       " and in " + which(group) + " (a vertex belongs to one of them)");
    }
    owner[v] = group;
    set.vertices.push_back(v);
    set.group.push_back(group);
  };
  for (int g = 0; g < set.num_groups; ++g)
    for (const int v : selection.handles[g]) add(v, g);
  for (const int v : selection.fixed) add(v, -1);
  if (set.vertices.empty()) throw InputError(std::string(name) + ": no handle and no fixed vertex");
  std::vector<char> pinned(components, 0);
  for (const int v : set.vertices) pinned[label[v]] = 1;
  std::vector<int> size(components, 0), first(components, -1);
  for (int v = 0; v < n; ++v) {
    if (size[label[v]]++ == 0) first[label[v]] = v;
  }
  set.first_free = set.vertices.size();
  for (int c = 0; c < components; ++c) {
    if (pinned[c]) continue;
    if (pieces == UnconstrainedPieces::Error) {
      throw InputError(std::string(name) + ": connected component " + std::to_string(c + 1) +
                       " of " + std::to_string(components) + " (" + std::to_string(size[c]) +
                       " vertices, the first " + vertex(first[c]) +
                       ") has no handle or fixed vertex, so its position is undefined");
    }
    ++set.free_pieces;
  }
  if (set.free_pieces > 0) {
    for (int v = 0; v < n; ++v) {
      if (!pinned[label[v]]) {
        set.vertices.push_back(v);
        set.group.push_back(-1);
      }
    }
  }
  return set;
}

Eigen::VectorXd piece_area_fractions(const Eigen::VectorXd& vertex_area,
                                     const Eigen::VectorXi& components, int count) {
  Eigen::VectorXd piece_area = Eigen::VectorXd::Zero(count);
  for (Eigen::Index v = 0; v < vertex_area.size(); ++v) piece_area[components[v]] += vertex_area[v];
  Eigen::VectorXd out(vertex_area.size());
  for (Eigen::Index v = 0; v < vertex_area.size(); ++v)
    out[v] = vertex_area[v] / piece_area[components[v]];
  return out;
}

Eigen::MatrixX3d constraint_targets(const ConstrainedSet& set, const Eigen::MatrixX3d& positions,
                                    const std::vector<Eigen::Affine3d>& transforms) {
  if (static_cast<int>(transforms.size()) != set.num_groups) {
    throw InputError("deformation: " + std::to_string(transforms.size()) + " transforms for " +
                     std::to_string(set.num_groups) + " handle groups");
  }
  for (size_t g = 0; g < transforms.size(); ++g) {
    const Eigen::Matrix4d& T = transforms[g].matrix();
    if (!T.allFinite()) {
      throw InputError("deformation: the transform of handle group " + std::to_string(g) +
                       " is not finite");
    }
    const double det = T.topLeftCorner<3, 3>().determinant();
    if (!(std::abs(det) > 1e-12 * std::pow(T.topLeftCorner<3, 3>().norm(), 3))) {
      throw InputError("deformation: the transform of handle group " + std::to_string(g) +
                       " is singular");
    }
    if (det < 0.0) {
      throw InputError("deformation: the transform of handle group " + std::to_string(g) +
                       " mirrors the handle (negative determinant); a deformation cannot "
                       "reflect part of a surface");
    }
  }
  // Targets far beyond the constrained region's size (a translation of 1e300, say) would give
  // overflowing or meaningless results: refused. The mesh's size stands in for a region of one
  // vertex (a handle of one vertex, nothing fixed).
  Eigen::MatrixX3d targets(set.vertices.size(), 3);
  Eigen::AlignedBox3d box;
  double moved = 0.0;
  for (size_t i = 0; i < set.vertices.size(); ++i) {
    const Eigen::Vector3d p = positions.row(set.vertices[i]);
    targets.row(i) = set.group[i] < 0 ? p : Eigen::Vector3d(transforms[set.group[i]] * p);
    box.extend(p);
    moved = std::max(moved, (targets.row(i).transpose() - p).norm());
  }
  double size = set.vertices.empty() ? 0.0 : std::max(box.diagonal().norm(), 1e-300);
  if (!(moved <= kLargestMove * size) && positions.rows() > 0) {
    size = std::max(size, (positions.colwise().maxCoeff() - positions.colwise().minCoeff()).norm());
  }
  if (!(moved <= kLargestMove * size)) {
    throw InputError("deformation: a handle moves its vertices " + std::to_string(moved) +
                     ", more than " + std::to_string(static_cast<long>(kLargestMove)) +
                     " times the size of the constrained region");
  }
  return targets;
}

}  // namespace specdeform
