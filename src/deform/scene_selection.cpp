// Selections built from geometry (radius, height), transforms checked and matched to handle
// groups, and selections moved from the file's numbering to the loaded mesh's (scene.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "scene_internal.h"
#include "specdeform/deform/influence.h"
#include "specdeform/deform/scene.h"
#include "specdeform/exceptions.h"

namespace specdeform {

namespace detail {

std::vector<int> vertices_within(const Vertices& V, const std::vector<int>& among,
                                 const Eigen::Vector3d& center, double radius) {
  std::vector<int> out;
  for (const int i : among) {
    if ((V.row(i).transpose() - center).norm() <= radius) out.push_back(i);
  }
  return out;
}

std::vector<int> lowest_vertices(const Vertices& V, const std::vector<int>& among, double fraction,
                                 int axis, const std::vector<std::vector<int>>& excluded) {
  std::vector<char> skip(V.rows(), 0);
  for (const auto& group : excluded) {
    for (const int v : group) skip[v] = 1;
  }
  std::vector<int> order = among;
  const auto count = static_cast<std::ptrdiff_t>(fraction * static_cast<double>(order.size()));
  std::nth_element(order.begin(), order.begin() + count, order.end(),
                   [&](int a, int b) { return V(a, axis) < V(b, axis); });
  std::vector<int> out;
  for (std::ptrdiff_t k = 0; k < count; ++k) {
    if (!skip[order[k]]) out.push_back(order[k]);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace detail

Eigen::Affine3d checked_transform(const Eigen::Matrix4d& m, const std::string& where) {
  if (!m.allFinite()) throw InputError(where + ": the transform is not finite");
  if (m.row(3) != Eigen::RowVector4d(0, 0, 0, 1)) {
    throw InputError(where + ": the transform's last row must be 0 0 0 1");
  }
  // Entries beyond 1e100 (a scale of 1e300) would overflow the determinant and every squared
  // length after it: said as such, not as "not invertible".
  const Eigen::Matrix3d linear = m.topLeftCorner<3, 3>();
  const double largest = linear.cwiseAbs().maxCoeff();
  if (largest > 1e100) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", largest);
    throw InputError(where + ": the transform's linear part reaches " + text +
                     ", out of range (at most 1e100)");
  }
  const Eigen::Matrix3d unit = linear / (largest > 0 ? largest : 1.0);
  if (!(std::abs(unit.determinant()) > 1e-12 * std::pow(unit.norm(), 3))) {
    throw InputError(where + ": the transform is not invertible");
  }
  return Eigen::Affine3d(m);
}

std::vector<Eigen::Affine3d> match_transforms(const Selection& selection,
                                              std::vector<Eigen::Affine3d> transforms) {
  size_t handle_vertices = 0;
  for (const auto& g : selection.handles) handle_vertices += g.size();
  if (handle_vertices == 0) throw InputError("scene: no handle vertex");
  if (transforms.size() > selection.handles.size()) {
    throw InputError("scene: " + std::to_string(transforms.size()) + " transforms for " +
                     std::to_string(selection.handles.size()) + " handle groups");
  }
  transforms.resize(selection.handles.size(), Eigen::Affine3d::Identity());
  return transforms;
}

Selection radius_selection(const TriangleMesh& mesh, int center, double radius,
                           double fixed_fraction, int up) {
  const int n = mesh.num_vertices();
  if (center < 0 || center >= n || up < 0 || up > 2 ||
      !(fixed_fraction >= 0 && fixed_fraction < 1)) {
    throw InputError("radius selection: bad centre vertex, axis or fraction");
  }
  std::vector<int> all(n);
  std::iota(all.begin(), all.end(), 0);
  Selection s;
  s.handles = {detail::vertices_within(mesh.V, all, mesh.V.row(center).transpose(),
                                       radius * bounding_box_diagonal(mesh.V))};
  s.fixed = detail::lowest_vertices(mesh.V, all, fixed_fraction, up, s.handles);
  return s;
}

Scene benchmark_scene(const TriangleMesh& mesh) {
  const Eigen::Vector3d extent = mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff();
  int axes[3] = {0, 1, 2};
  std::sort(axes, axes + 3, [&](int a, int b) { return extent[a] > extent[b]; });
  Eigen::Index top;
  mesh.V.col(axes[0]).maxCoeff(&top);
  Scene s;
  s.selection = radius_selection(mesh, static_cast<int>(top), 0.05, 0.10, axes[0]);
  Eigen::Vector3d move = Eigen::Vector3d::Zero();
  move[axes[1]] = 0.1 * extent.norm();
  s.transforms = {Eigen::Affine3d(Eigen::Translation3d(move))};
  return s;
}

Selection scene_selection(const Scene& scene, const LoadedMesh& mesh,
                          std::vector<std::string>* notes, std::string_view name) {
  Selection out = to_mesh_numbering(scene.selection, mesh.info, notes, name);
  if (!scene.influence) return out;
  return limit_influence(mesh.mesh, out, *scene.influence * bounding_box_diagonal(mesh.mesh.V));
}

Selection to_mesh_numbering(const Selection& selection, const MeshReadInfo& info,
                            std::vector<std::string>* notes, std::string_view name) {
  const std::vector<int>& index = info.file_to_vertex;
  // Copies of one welded vertex (glTF's seams) in a list count once.
  std::vector<char> taken(info.vertex_to_file.size(), 0);
  const auto map = [&](const std::vector<int>& in, const std::string& what) {
    std::vector<int> out;
    size_t dropped = 0;
    for (const int v : in) {
      if (v < 0 || v >= static_cast<int>(index.size())) {
        throw InputError(std::string(name) + ": " + what + ": vertex " + std::to_string(v) +
                         " is out of range (the file has " + std::to_string(index.size()) +
                         " vertices)");
      }
      if (index[v] < 0) {
        ++dropped;
      } else if (!taken[index[v]]) {
        taken[index[v]] = 1;
        out.push_back(index[v]);
      }
    }
    for (const int v : out) taken[v] = 0;
    if (dropped == 0) return out;
    if (out.empty()) {
      throw InputError(std::string(name) + ": " + what + ": all " + std::to_string(in.size()) +
                       " of its vertices (file vertex " + std::to_string(in.front()) +
                       " first) are used by no face, so the mesh reader dropped them");
    }
    if (notes != nullptr) {
      notes->push_back(what + ": " + std::to_string(dropped) + " of its " +
                       std::to_string(in.size()) +
                       " vertices are used by no face and were left out");
    }
    return out;
  };
  Selection out;
  for (size_t g = 0; g < selection.handles.size(); ++g) {
    out.handles.push_back(map(selection.handles[g], "handle group " + std::to_string(g)));
  }
  out.fixed = map(selection.fixed, "the fixed set");
  return out;
}

}  // namespace specdeform
