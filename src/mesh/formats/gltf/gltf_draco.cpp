// KHR_draco_mesh_compression decoded through Debian's Draco (gltf_decode.h).
#include <draco/compression/decode.h>

#include <cstring>

#include "gltf_decode.h"

namespace specdeform::detail {

namespace {

constexpr const char* kDraco = "KHR_draco_mesh_compression";

// Each point's `attribute` values converted to the accessor's component type, packed.
template <typename T>
std::string converted(const draco::PointAttribute& attribute, const draco::Mesh& mesh,
                      int components) {
  std::string out(size_t(mesh.num_points()) * components * sizeof(T), '\0');
  std::vector<T> value(components);
  for (draco::PointIndex p(0); p < mesh.num_points(); ++p) {
    attribute.ConvertValue<T>(attribute.mapped_index(p), int8_t(components), value.data());
    std::memcpy(out.data() + size_t(p.value()) * components * sizeof(T), value.data(),
                components * sizeof(T));
  }
  return out;
}

std::string attribute_bytes(const draco::PointAttribute& attribute, const draco::Mesh& mesh,
                            int component_type, int components) {
  switch (component_type) {
    case 5120:
      return converted<int8_t>(attribute, mesh, components);
    case 5121:
      return converted<uint8_t>(attribute, mesh, components);
    case 5122:
      return converted<int16_t>(attribute, mesh, components);
    case 5123:
      return converted<uint16_t>(attribute, mesh, components);
    case 5125:
      return converted<uint32_t>(attribute, mesh, components);
    default:
      return converted<float>(attribute, mesh, components);
  }
}

template <typename T>
std::string face_indices(const draco::Mesh& mesh) {
  std::string out(size_t(mesh.num_faces()) * 3 * sizeof(T), '\0');
  for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const T v = static_cast<T>(mesh.face(f)[k].value());
      std::memcpy(out.data() + (size_t(f.value()) * 3 + k) * sizeof(T), &v, sizeof(T));
    }
  }
  return out;
}

}  // namespace

void decode_draco(GltfDocument& doc) {
  const Json& meshes = array_at(doc.json, "meshes");
  for (size_t m = 0; m < meshes.size(); ++m) {
    const Json& primitives = array_at(meshes[m], "primitives");
    for (size_t p = 0; p < primitives.size(); ++p) {
      const Json& prim = primitives[p];
      const Json& ext = object_at(object_at(prim, "extensions"), kDraco);
      if (ext.empty()) continue;
      const std::string which =
          "mesh " + std::to_string(m) + " primitive " + std::to_string(p) + " (" + kDraco + ")";
      const std::string_view compressed = doc.view_bytes(ext.value("bufferView", -1), which);
      draco::DecoderBuffer input;
      input.Init(compressed.data(), compressed.size());
      draco::Decoder decoder;
      auto result = decoder.DecodeMeshFromBuffer(&input);
      if (!result.ok()) {
        doc.fail(which + " could not be decoded: " + result.status().error_msg_string());
      }
      const std::unique_ptr<draco::Mesh> mesh = std::move(result).value();
      const Json& attributes = object_at(prim, "attributes");
      for (const auto& [name, id] : object_at(ext, "attributes").items()) {
        if (!attributes.contains(name)) continue;
        const draco::PointAttribute* attribute =
            id.is_number_unsigned() ? mesh->GetAttributeByUniqueId(id.get<uint32_t>()) : nullptr;
        if (attribute == nullptr)
          doc.fail(which + " has no attribute " + id.dump() + " for " + name);
        const int accessor = attributes[name].get<int>();
        const Json& a = doc.json["accessors"].at(accessor);
        const int components = type_components(a.value("type", ""));
        if (components == 0) doc.fail(which + " " + name + " has an unknown type");
        doc.decoded_accessors[accessor] =
            attribute_bytes(*attribute, *mesh, a.value("componentType", 5126), components);
      }
      if (!prim.contains("indices")) doc.fail(which + " has no indices accessor");
      const int indices = prim["indices"].get<int>();
      const int type = doc.json["accessors"].at(indices).value("componentType", 5125);
      doc.decoded_accessors[indices] = type == 5121   ? face_indices<uint8_t>(*mesh)
                                       : type == 5123 ? face_indices<uint16_t>(*mesh)
                                                      : face_indices<uint32_t>(*mesh);
    }
  }
}

std::vector<std::string> uncompress_changed_draco(GltfDocument& doc, const Json& original) {
  int uncompressed = 0;
  bool kept = false;
  const Json& meshes = array_at(doc.json, "meshes");
  for (size_t m = 0; m < meshes.size(); ++m) {
    for (size_t p = 0; p < array_at(meshes[m], "primitives").size(); ++p) {
      const Json& prim = doc.json["meshes"][m]["primitives"][p];
      if (object_at(object_at(prim, "extensions"), kDraco).empty()) continue;
      const Json& before =
          m < array_at(original, "meshes").size() ? original["meshes"][m]["primitives"][p] : Json();
      if (prim == before) {
        kept = true;
        continue;
      }
      // Re-pointed (a new mesh copy counts as such): every accessor still compressed gets its
      // decoded bytes in a buffer view of its own.
      std::vector<int> accessors;
      for (const auto& [name, a] : object_at(prim, "attributes").items())
        accessors.push_back(a.get<int>());
      if (prim.contains("indices")) accessors.push_back(prim["indices"].get<int>());
      for (const int a : accessors) {
        const auto decoded = doc.decoded_accessors.find(a);
        if (decoded == doc.decoded_accessors.end() ||
            doc.json["accessors"][a].contains("bufferView")) {
          continue;
        }
        const Json& accessor = doc.json["accessors"][a];
        const size_t element = size_t(component_size(accessor.value("componentType", 5126))) *
                               type_components(accessor.value("type", ""));
        const bool index = prim.contains("indices") && prim["indices"] == a;
        const int view = doc.append_view(doc.data_buffer(), decoded->second, index ? 34963 : 34962);
        Json& same = doc.json["accessors"][a];
        same["bufferView"] = view;
        same["count"] = decoded->second.size() / element;
        doc.decoded_accessors.erase(decoded);
        if (same.contains("min") || same.contains("max")) {
          auto [lo, hi] = accessor_bounds(doc, a);  // Draco's quantisation moved them
          same["min"] = std::move(lo);
          same["max"] = std::move(hi);
        }
      }
      Json& extensions = doc.json["meshes"][m]["primitives"][p]["extensions"];
      extensions.erase(kDraco);
      if (extensions.empty()) doc.json["meshes"][m]["primitives"][p].erase("extensions");
      ++uncompressed;
    }
  }
  if (uncompressed == 0) return {};
  if (!kept) doc.drop_extension(kDraco);
  return {std::to_string(uncompressed) + " primitives compressed by " + kDraco +
          " written uncompressed (their positions changed)"};
}

}  // namespace specdeform::detail
