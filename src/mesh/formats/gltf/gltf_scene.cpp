#include "gltf_scene.h"

#include "gltf_decode.h"

#include <algorithm>
#include <cmath>
#include <tuple>

#include <Eigen/Geometry>

namespace specdeform::detail {

namespace {

// Numbers of `key` in `node` if it holds `size` of them; empty otherwise.
std::vector<double> numbers(const Json& node, const char* key, size_t size) {
  const Json& v = array_at(node, key);
  if (!v.is_array() || v.size() != size) return {};
  std::vector<double> out;
  for (const Json& x : v) {
    if (!x.is_number()) return {};
    out.push_back(x.get<double>());
  }
  return out;
}

}  // namespace

Eigen::Matrix4d node_matrix(const Json& node) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  if (const std::vector<double> matrix = numbers(node, "matrix", 16); !matrix.empty()) {
    for (int k = 0; k < 16; ++k) m(k % 4, k / 4) = matrix[k];  // column-major
    return m;
  }
  Eigen::Affine3d t = Eigen::Affine3d::Identity();
  if (const std::vector<double> v = numbers(node, "translation", 3); !v.empty()) {
    t.translate(Eigen::Vector3d(v.data()));
  }
  if (const std::vector<double> q = numbers(node, "rotation", 4); !q.empty()) {
    t.rotate(Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized());
  }
  if (const std::vector<double> s = numbers(node, "scale", 3); !s.empty()) {
    t.scale(Eigen::Vector3d(s.data()));
  }
  return t.matrix();
}

std::vector<GltfDrawing> scene_drawings(const GltfDocument& doc) {
  const Json& json = doc.json;
  const Json& nodes = array_at(json, "nodes");
  const Json& scenes = array_at(json, "scenes");
  const size_t meshes = array_at(json, "meshes").size();
  std::vector<int> roots;
  const int scene = json.value("scene", scenes.empty() ? -1 : 0);
  if (scene >= int(scenes.size())) doc.fail("the default scene does not exist");
  if (scene >= 0) {
    for (const Json& n : array_at(scenes[scene], "nodes"))
      roots.push_back(n.is_number_integer() ? n.get<int>() : -1);
  } else {
    std::vector<char> child(nodes.size(), 0);
    for (const Json& n : nodes)
      for (const Json& c : array_at(n, "children"))
        if (const int i = json_index(c); i >= 0 && size_t(i) < child.size()) child[i] = 1;
    for (size_t n = 0; n < child.size(); ++n)
      if (!child[n]) roots.push_back(int(n));
  }
  std::vector<GltfDrawing> drawings;
  std::vector<char> seen(nodes.size(), 0);
  std::vector<std::pair<int, Eigen::Matrix4d>> stack;
  for (auto r = roots.rbegin(); r != roots.rend(); ++r)
    stack.emplace_back(*r, Eigen::Matrix4d::Identity());
  while (!stack.empty()) {
    const auto [index, parent] = stack.back();
    stack.pop_back();
    if (index < 0 || size_t(index) >= nodes.size()) doc.fail("a scene names a missing node");
    if (seen[index]) {
      doc.fail("node " + std::to_string(index) +
               " is reached twice in the scene (glTF's nodes form trees)");
    }
    seen[index] = 1;
    const Json& node = nodes[index];
    const Eigen::Matrix4d matrix = parent * node_matrix(node);
    if (node.contains("mesh")) {
      const int mesh = json_index(node["mesh"]);
      if (mesh < 0 || size_t(mesh) >= meshes)
        doc.fail("node " + std::to_string(index) + " names a missing mesh");
      if (!matrix.allFinite() || std::abs(matrix.topLeftCorner<3, 3>().determinant()) < 1e-300) {
        doc.fail("node " + std::to_string(index) + "'s transform is not invertible");
      }
      const bool skinned = node.contains("skin");
      const std::vector<Eigen::Matrix4d> instances = instance_matrices(doc, index);
      if (instances.empty()) {
        drawings.push_back({mesh, index, -1, skinned ? Eigen::Matrix4d::Identity() : matrix});
      }
      for (size_t i = 0; i < instances.size(); ++i) {
        const Eigen::Matrix4d world = matrix * instances[i];
        if (!world.allFinite() || std::abs(world.topLeftCorner<3, 3>().determinant()) < 1e-300) {
          doc.fail("node " + std::to_string(index) + "'s instance " + std::to_string(i) +
                   " has a transform that is not invertible");
        }
        drawings.push_back({mesh, index, int(i), world});
      }
    }
    const Json& children = array_at(node, "children");
    for (auto c = children.rbegin(); c != children.rend(); ++c)
      stack.emplace_back(c->is_number_integer() ? c->get<int>() : -1, matrix);
  }
  std::stable_sort(
      drawings.begin(), drawings.end(), [](const GltfDrawing& a, const GltfDrawing& b) {
        return std::tie(a.mesh, a.node, a.instance) < std::tie(b.mesh, b.node, b.instance);
      });
  return drawings;
}

}  // namespace specdeform::detail
