// EXT_mesh_gpu_instancing read as drawings and written back (gltf_decode.h).
#include <optional>

#include <Eigen/Geometry>

#include "gltf_decode.h"

namespace specdeform::detail {

namespace {

constexpr const char* kInstancing = "EXT_mesh_gpu_instancing";
constexpr const char* kKeys[3] = {"TRANSLATION", "ROTATION", "SCALE"};

// Each instance's translation, rotation (x y z w) and scale where the extension gives them.
struct Instances {
  std::optional<AccessorValues> trs[3];
  int count = 0;
};

Instances instances_of(const GltfDocument& doc, int node) {
  Instances out;
  const Json& ext =
      object_at(object_at(array_at(doc.json, "nodes")[node], "extensions"), kInstancing);
  const std::string which = "node " + std::to_string(node) + " (" + kInstancing + ")";
  const Json& attributes = object_at(ext, "attributes");
  int count = -1;
  for (int k = 0; k < 3; ++k) {
    if (!attributes.contains(kKeys[k])) continue;
    out.trs[k] = read_accessor(doc, attributes[kKeys[k]].get<int>(), which + " " + kKeys[k]);
    if (out.trs[k]->components != (k == 1 ? 4 : 3)) {
      doc.fail(which + " " + kKeys[k] + " has the wrong type");
    }
    if (count >= 0 && out.trs[k]->count != count) {
      doc.fail(which + "'s attributes count different instances");
    }
    count = out.trs[k]->count;
  }
  if (count < 0) doc.fail(which + " has no TRANSLATION, ROTATION or SCALE");
  out.count = count;
  return out;
}

}  // namespace

std::vector<Eigen::Matrix4d> instance_matrices(const GltfDocument& doc, int node) {
  const Json& n = array_at(doc.json, "nodes")[node];
  if (object_at(object_at(n, "extensions"), kInstancing).empty()) return {};
  const Instances instances = instances_of(doc, node);
  std::vector<Eigen::Matrix4d> out;
  for (int i = 0; i < instances.count; ++i) {
    Eigen::Affine3d t = Eigen::Affine3d::Identity();
    if (const auto& v = instances.trs[0])
      t.translate(Eigen::Vector3d((*v)(i, 0), (*v)(i, 1), (*v)(i, 2)));
    if (const auto& q = instances.trs[1]) {
      t.rotate(Eigen::Quaterniond((*q)(i, 3), (*q)(i, 0), (*q)(i, 1), (*q)(i, 2)).normalized());
    }
    if (const auto& s = instances.trs[2])
      t.scale(Eigen::Vector3d((*s)(i, 0), (*s)(i, 1), (*s)(i, 2)));
    out.push_back(t.matrix());
  }
  return out;
}

bool draw_instances(GltfDocument& doc, int node, const std::vector<int>& meshes) {
  if (std::all_of(meshes.begin(), meshes.end(), [&](int m) { return m == meshes.front(); })) {
    doc.json["nodes"][node]["mesh"] = meshes.front();
    return false;
  }
  const Instances instances = instances_of(doc, node);
  const Json parent = doc.json["nodes"][node];
  Json children = array_at(parent, "children");
  const std::string name = parent.value("name", "node " + std::to_string(node));
  for (int i = 0; i < instances.count; ++i) {
    Json child = {{"name", name + " instance " + std::to_string(i)}, {"mesh", meshes[i]}};
    for (int k = 0; k < 3; ++k) {
      if (!instances.trs[k]) continue;
      Json v = Json::array();
      for (int c = 0; c < instances.trs[k]->components; ++c) {
        v.push_back(double(float((*instances.trs[k])(i, c))));
      }
      child[k == 0 ? "translation" : k == 1 ? "rotation" : "scale"] = std::move(v);
    }
    children.push_back(doc.json["nodes"].size());
    doc.json["nodes"].push_back(std::move(child));
  }
  Json& expanded = doc.json["nodes"][node];
  expanded["children"] = std::move(children);
  expanded.erase("mesh");
  expanded["extensions"].erase(kInstancing);
  if (expanded["extensions"].empty()) expanded.erase("extensions");
  const Json& nodes = doc.json["nodes"];
  if (std::none_of(nodes.begin(), nodes.end(), [](const Json& n) {
        return !object_at(object_at(n, "extensions"), kInstancing).empty();
      })) {
    doc.drop_extension(kInstancing);
  }
  return true;
}

}  // namespace specdeform::detail
