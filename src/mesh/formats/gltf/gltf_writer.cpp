// glTF written afresh through tinygltf's writer: one buffer, one primitive per material (gltf.h).
#include <tiny_gltf.h>

#include <map>
#include <sstream>

#include "gltf.h"
#include "mesh/float_cast.h"
#include "mesh/formats/converted.h"
#include "specdeform/exceptions.h"

namespace specdeform::detail {

std::string gltf_bytes(const FileAttributes& a, const Vertices& X, const Eigen::MatrixX3d& normals,
                       bool binary, const MeshFile* file) {
  const bool uv = !a.corner_uv.empty(), normal = !a.corner_normal.empty() && normals.rows() > 0;
  const bool colours = a.colours.rows() > 0;
  // Vertices split by (vertex, uv row, normal row), per material.
  std::map<int, std::vector<int>> triangles;  // material -> split vertex per corner
  std::map<std::array<int, 3>, int> split;
  std::vector<std::array<int, 3>> vertices;
  const auto vertex = [&](int c) {
    const std::array<int, 3> key{a.corners[c], uv ? a.corner_uv[c] : -1,
                                 normal ? a.corner_normal[c] : -1};
    const auto [it, added] = split.emplace(key, int(vertices.size()));
    if (added) vertices.push_back(key);
    return it->second;
  };
  for_each_triangle(a, [&](int p, int i, int j, int k) {
    std::vector<int>& t = triangles[a.polygon_material.empty() ? -1 : a.polygon_material[p]];
    for (const int c : {i, j, k}) t.push_back(vertex(c));
  });
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "specdeform";
  tinygltf::Buffer buffer;
  const auto view = [&](const void* data, size_t bytes, int target) {
    while (buffer.data.size() % 4) buffer.data.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = buffer.data.size();
    v.byteLength = bytes;
    v.target = target;
    const auto* b = static_cast<const unsigned char*>(data);
    buffer.data.insert(buffer.data.end(), b, b + bytes);
    model.bufferViews.push_back(v);
    return int(model.bufferViews.size()) - 1;
  };
  const auto accessor = [&](const std::vector<float>& values, int type, int components) {
    tinygltf::Accessor acc;
    acc.bufferView = view(values.data(), values.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER);
    acc.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    acc.count = values.size() / components;
    acc.type = type;
    model.accessors.push_back(acc);
    return int(model.accessors.size()) - 1;
  };
  const int nv = static_cast<int>(vertices.size());
  std::vector<float> position(3 * nv), texcoord, normal_values, colour;
  for (int v = 0; v < nv; ++v)
    for (int k = 0; k < 3; ++k) position[3 * v + k] = to_float(X(vertices[v][0], k), "a position");
  const int position_accessor = accessor(position, TINYGLTF_TYPE_VEC3, 3);
  Eigen::Array3f lo = Eigen::Array3f::Constant(INFINITY), hi = -lo;
  for (int v = 0; v < nv; ++v) {
    const Eigen::Array3f p(position[3 * v], position[3 * v + 1], position[3 * v + 2]);
    lo = lo.min(p);
    hi = hi.max(p);
  }
  model.accessors[position_accessor].minValues = {lo[0], lo[1], lo[2]};
  model.accessors[position_accessor].maxValues = {hi[0], hi[1], hi[2]};
  std::map<std::string, int> attributes{{"POSITION", position_accessor}};
  if (uv) {
    for (const auto& [vtx, t, n] : vertices) {
      texcoord.push_back(t < 0 ? 0.f : to_float(a.uv(t, 0), "a texture coordinate"));
      texcoord.push_back(t < 0 ? 0.f : to_float(1.0 - a.uv(t, 1), "a texture coordinate"));
    }
    attributes["TEXCOORD_0"] = accessor(texcoord, TINYGLTF_TYPE_VEC2, 2);
  }
  if (normal) {
    for (const auto& [vtx, t, n] : vertices)
      for (int k = 0; k < 3; ++k) {
        normal_values.push_back(n < 0 ? 0.f : to_float(normals(n, k), "a normal"));
      }
    attributes["NORMAL"] = accessor(normal_values, TINYGLTF_TYPE_VEC3, 3);
  }
  if (colours) {
    for (const auto& [vtx, t, n] : vertices)
      for (int k = 0; k < 4; ++k) colour.push_back(a.colours(vtx, k));
    attributes["COLOR_0"] = accessor(colour, TINYGLTF_TYPE_VEC4, 4);
  }
  for (size_t m = 0; m < a.materials.size(); ++m) {
    const Material& mat = a.materials[m];
    tinygltf::Material gm;
    gm.name = mat.name;
    gm.pbrMetallicRoughness.baseColorFactor = {mat.base_color[0], mat.base_color[1],
                                               mat.base_color[2], mat.base_color[3]};
    if (file != nullptr) {
      if (auto image = file->texture(static_cast<int>(m))) {
        tinygltf::Image gi;
        gi.mimeType = image->second;
        gi.bufferView = view(image->first.data(), image->first.size(), 0);
        model.bufferViews.back().target = 0;
        model.images.push_back(gi);
        tinygltf::Texture texture;
        texture.source = int(model.images.size()) - 1;
        model.textures.push_back(texture);
        gm.pbrMetallicRoughness.baseColorTexture.index = int(model.textures.size()) - 1;
      }
    }
    model.materials.push_back(gm);
  }
  tinygltf::Mesh mesh;
  for (const auto& [material, corners] : triangles) {
    tinygltf::Primitive p;
    p.attributes = attributes;
    p.material = material;
    p.mode = TINYGLTF_MODE_TRIANGLES;
    std::vector<uint32_t> indices(corners.begin(), corners.end());
    tinygltf::Accessor acc;
    acc.bufferView = view(indices.data(), indices.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    acc.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    acc.count = indices.size();
    acc.type = TINYGLTF_TYPE_SCALAR;
    model.accessors.push_back(acc);
    p.indices = int(model.accessors.size()) - 1;
    mesh.primitives.push_back(p);
  }
  model.meshes.push_back(mesh);
  tinygltf::Node node;
  node.mesh = 0;
  model.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes = {0};
  model.scenes.push_back(scene);
  model.defaultScene = 0;
  model.buffers.push_back(std::move(buffer));
  std::ostringstream stream;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, stream, false, binary)) {
    throw InputError("the glTF writer failed");
  }
  return stream.str();
}

}  // namespace specdeform::detail
