// glTF read into a polygon soup and kept (gltf.h).
#include <cmath>
#include <map>
#include <set>
#include <tuple>

#include <Eigen/Dense>

#include "data_uri.h"
#include "gltf.h"
#include "gltf_decode.h"
#include "gltf_rig.h"
#include "gltf_scene.h"
#include "mesh/polygon_soup.h"
#include "specdeform/exceptions.h"

namespace specdeform::detail {

namespace {

constexpr int kTriangles = 4, kStrip = 5, kFan = 6;

// Per file vertex attributes, filled primitive by primitive.
struct VertexAttributes {
  std::vector<double> uv, normal, tangent;  // 2, 3, 4 per file vertex
  std::vector<float> colour;                // 4 per file vertex
  std::vector<char> with_uv, with_normal;
  bool has_uv = false, has_normal = false, has_colour = false;

  void resize(int n) {
    uv.resize(2 * size_t(n), 0.0);
    normal.resize(3 * size_t(n), 0.0);
    tangent.resize(4 * size_t(n), 0.0);
    colour.resize(4 * size_t(n), 1.0f);
    with_uv.resize(n, 0);
    with_normal.resize(n, 0);
  }
};

// The image a texture draws (its source, or an extension's: EXT_texture_webp, KHR_texture_basisu).
int texture_image(const Json& json, int texture) {
  const Json& textures = array_at(json, "textures");
  if (texture < 0 || size_t(texture) >= textures.size()) return -1;
  const Json& t = textures[texture];
  if (t.contains("source")) return t["source"].get<int>();
  for (const auto& [name, ext] : object_at(t, "extensions").items())
    if (ext.is_object() && ext.contains("source")) return ext["source"].get<int>();
  return -1;
}

TextureSampling::Wrap wrap(const Json& sampler, const char* key) {
  switch (sampler.value(key, 10497)) {
    case 33071:
      return TextureSampling::Wrap::Clamp;
    case 33648:
      return TextureSampling::Wrap::Mirror;
    default:
      return TextureSampling::Wrap::Repeat;
  }
}

// A texture reference's sampler and KHR_texture_transform.
TextureSampling texture_sampling(const Json& json, const Json& info) {
  TextureSampling out;
  const Json& samplers = array_at(json, "samplers");
  const Json& textures = array_at(json, "textures");
  const int texture = info.value("index", -1);
  const int s = texture >= 0 && size_t(texture) < textures.size()
                    ? textures[texture].value("sampler", -1)
                    : -1;
  if (s >= 0 && size_t(s) < samplers.size() && samplers[s].is_object()) {
    out.wrap_u = wrap(samplers[s], "wrapS");
    out.wrap_v = wrap(samplers[s], "wrapT");
    out.nearest = samplers[s].value("magFilter", 0) == 9728;
  }
  const Json& t = object_at(object_at(info, "extensions"), "KHR_texture_transform");
  const auto pair = [&](const char* key, float fallback, int k) {
    const Json& a = array_at(t, key);
    return a.size() == 2 && a[k].is_number() ? a[k].get<float>() : fallback;
  };
  const float r = t.value("rotation", 0.f), c = std::cos(r), sn = std::sin(r);
  const float sx = pair("scale", 1, 0), sy = pair("scale", 1, 1);
  out.transform << c * sx, sn * sy, pair("offset", 0, 0),  // offset * rotation * scale
      -sn * sx, c * sy, pair("offset", 0, 1);
  return out;
}

std::vector<Material> materials_of(const Json& json) {
  std::vector<Material> out;
  const Json& images = array_at(json, "images");
  for (const Json& gm : array_at(json, "materials")) {
    Material mat;
    mat.name = gm.value("name", "");
    const Json& pbr = object_at(gm, "pbrMetallicRoughness");
    const Json& factor = array_at(pbr, "baseColorFactor");
    if (factor.size() == 4) {
      for (int k = 0; k < 4; ++k) mat.base_color[k] = factor[k].get<float>();
    }
    const Json& base = object_at(pbr, "baseColorTexture");
    const int image = texture_image(json, base.value("index", -1));
    if (image >= 0 && size_t(image) < images.size()) {
      mat.gltf_image = image;
      const std::string uri = images[image].value("uri", "");
      mat.texture = uri.starts_with("data:") ? uri : decode_uri(uri);
      mat.sampling = texture_sampling(json, base);
    }
    mat.unlit = object_at(gm, "extensions").contains("KHR_materials_unlit");
    out.push_back(std::move(mat));
  }
  return out;
}

}  // namespace

std::vector<std::string> gltf_companions(const GltfDocument& doc) {
  std::vector<std::string> names;
  std::set<std::string> seen;
  for (const char* list : {"buffers", "images"}) {
    for (const Json& item : array_at(doc.json, list)) {
      const std::string uri = item.value("uri", "");
      if (uri.empty() || uri.starts_with("data:")) continue;
      if (const std::string name = decode_uri(uri); seen.insert(name).second) names.push_back(name);
    }
  }
  return names;
}

namespace {

PolygonSoup read_scene(std::string_view data, MeshFormat format, const std::string& name,
                       const FileResolver& companions, KeptRecord* keep) {
  GltfLayout layout;
  layout.doc = load_gltf_document(data, format, name, companions);
  GltfDocument& doc = layout.doc;
  decode_meshopt(doc);
  decode_draco(doc);
  const std::vector<GltfDrawing> drawings = scene_drawings(doc);
  const Json& json = doc.json;

  PolygonSoup soup;
  VertexAttributes va;
  FileAttributes* a = keep ? &keep->attributes : nullptr;
  std::map<int, AccessorValues> read;  // accessors drawn more than once are read once
  const auto values = [&](int accessor, int components,
                          const std::string& what) -> const AccessorValues& {
    auto it = read.find(accessor);
    if (it == read.end()) it = read.emplace(accessor, read_accessor(doc, accessor, what)).first;
    if (it->second.components != components) {
      doc.fail(what + " (accessor " + std::to_string(accessor) + ") has the wrong type");
    }
    return it->second;
  };
  for (const GltfDrawing& d : drawings) {
    const Eigen::Matrix3d linear = d.world.topLeftCorner<3, 3>();
    const Eigen::Matrix3d normal_matrix = linear.inverse().transpose();
    const bool mirrors = linear.determinant() < 0;
    const Json& mesh = json["meshes"][d.mesh];
    const Json& primitives = array_at(mesh, "primitives");
    for (size_t p = 0; p < primitives.size(); ++p) {
      const Json& prim = primitives[p];
      const int mode = prim.value("mode", kTriangles);
      if (mode != kTriangles && mode != kStrip && mode != kFan) continue;  // points, lines
      const std::string mesh_name = mesh.value("name", "");
      const std::string what = "mesh " + std::to_string(d.mesh) +
                               (mesh_name.empty() ? "" : " ('" + mesh_name + "')") + " primitive " +
                               std::to_string(p);
      const Json& attributes = object_at(prim, "attributes");
      const auto attribute = [&](const char* key) {
        return attributes.contains(key) && attributes[key].is_number_integer()
                   ? attributes[key].get<int>()
                   : -1;
      };
      GltfUnit unit{d.mesh,
                    int(p),
                    d.node,
                    d.instance,
                    soup.num_vertices(),
                    0,
                    d.world,
                    attribute("POSITION"),
                    attribute("NORMAL"),
                    attribute("TANGENT")};
      if (unit.position < 0) doc.fail(what + " has no POSITION");
      const AccessorValues& position = values(unit.position, 3, what + " POSITION");
      unit.count = position.count;
      const int first = unit.first_vertex;
      for (int i = 0; i < position.count; ++i) {
        const Eigen::Vector4d w =
            d.world * Eigen::Vector4d(position(i, 0), position(i, 1), position(i, 2), 1.0);
        soup.xyz.insert(soup.xyz.end(), {w.x(), w.y(), w.z()});
      }
      // Triangles.
      const int index_accessor = prim.value("indices", -1);
      const AccessorValues* index =
          index_accessor >= 0 ? &values(index_accessor, 1, what + " indices") : nullptr;
      if (index && index->component_type != 5121 && index->component_type != 5123 &&
          index->component_type != 5125) {
        doc.fail(what + " indices are not unsigned integers");
      }
      const int count = index ? index->count : position.count;
      const auto corner = [&](int k) {
        const double v = index ? index->values[k] : k;
        if (!(v < position.count)) {
          doc.fail(what + " index " + std::to_string(k) + " is beyond its " +
                   std::to_string(position.count) + " vertices");
        }
        return first + static_cast<int>(v);
      };
      const int material = prim.value("material", -1);
      const auto triangle = [&](int i, int j, int k) {
        for (const int c : {i, j, k}) soup.add_polygon_corner(c);
        if (mirrors) std::swap(soup.indices.end()[-1], soup.indices.end()[-2]);
        soup.end_polygon();
        if (keep) a->polygon_material.push_back(material);
      };
      if (mode == kTriangles) {
        for (int k = 0; k + 2 < count; k += 3) triangle(corner(k), corner(k + 1), corner(k + 2));
      } else if (mode == kStrip) {
        for (int k = 0; k + 2 < count; ++k) {
          if (k % 2 == 0)
            triangle(corner(k), corner(k + 1), corner(k + 2));
          else
            triangle(corner(k + 1), corner(k), corner(k + 2));
        }
      } else {
        for (int k = 1; k + 1 < count; ++k) triangle(corner(0), corner(k), corner(k + 1));
      }
      layout.units.push_back(unit);
      if (!keep) continue;
      // The attributes the viewer draws and the writer rewrites.
      const int n = position.count;
      va.resize(soup.num_vertices());
      const auto same_count = [&](const AccessorValues& v, const char* key) {
        if (v.count != n) doc.fail(what + " " + key + " has another count than POSITION");
      };
      if (const int t = attribute("TEXCOORD_0"); t >= 0) {
        const AccessorValues& uv = values(t, 2, what + " TEXCOORD_0");
        same_count(uv, "TEXCOORD_0");
        for (int i = 0; i < n; ++i)
          for (int k = 0; k < 2; ++k) va.uv[2 * (first + i) + k] = uv(i, k);
        std::fill(va.with_uv.begin() + first, va.with_uv.end(), 1);
        va.has_uv = true;
      }
      if (unit.normal >= 0) {
        const AccessorValues& normal = values(unit.normal, 3, what + " NORMAL");
        same_count(normal, "NORMAL");
        for (int i = 0; i < n; ++i) {
          const Eigen::Vector3d w =
              normal_matrix * Eigen::Vector3d(normal(i, 0), normal(i, 1), normal(i, 2));
          const double norm = w.norm();
          for (int k = 0; k < 3; ++k) va.normal[3 * (first + i) + k] = norm > 0 ? w[k] / norm : 0;
        }
        std::fill(va.with_normal.begin() + first, va.with_normal.end(), 1);
        va.has_normal = true;
        if (unit.tangent >= 0) {
          const AccessorValues& tangent = values(unit.tangent, 4, what + " TANGENT");
          same_count(tangent, "TANGENT");
          for (int i = 0; i < n; ++i) {
            const Eigen::Vector3d w =
                linear * Eigen::Vector3d(tangent(i, 0), tangent(i, 1), tangent(i, 2));
            for (int k = 0; k < 3; ++k) va.tangent[4 * (first + i) + k] = w[k];
            va.tangent[4 * (first + i) + 3] = tangent(i, 3);
          }
        }
      }
      if (const int c = attribute("COLOR_0"); c >= 0) {
        const std::string type = json["accessors"][c].value("type", "");
        const int components = type == "VEC3" ? 3 : 4;
        const AccessorValues& colour = values(c, components, what + " COLOR_0");
        same_count(colour, "COLOR_0");
        for (int i = 0; i < n; ++i)
          for (int k = 0; k < components; ++k) va.colour[4 * (first + i) + k] = float(colour(i, k));
        va.has_colour = true;
      }
    }
  }
  if (soup.num_polygons() == 0) {
    doc.fail(drawings.empty() ? "the scene draws no mesh" : "no triangle primitives in the scene");
  }
  soup.weld = weld_coincident(soup.xyz);
  if (!keep) return soup;

  // Rows of uv and normals are file vertices; corners of primitives without them use none.
  const int n = soup.num_vertices();
  va.resize(n);
  const auto corner_rows = [&](const std::vector<char>& with) {
    std::vector<int> rows = soup.indices;
    for (int& c : rows)
      if (!with[c]) c = -1;
    return rows;
  };
  if (va.has_uv) {
    a->uv = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>(
        va.uv.data(), n, 2);
    a->corner_uv = corner_rows(va.with_uv);
  }
  if (va.has_normal) {
    a->normals = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(
        va.normal.data(), n, 3);
    a->corner_normal = corner_rows(va.with_normal);
    layout.tangents = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>>(
        va.tangent.data(), n, 4);
  }
  if (va.has_colour) {
    a->colours = Eigen::Map<const Eigen::Matrix<float, Eigen::Dynamic, 4, Eigen::RowMajor>>(
        va.colour.data(), n, 4);
  }
  a->materials = materials_of(json);
  if (a->materials.empty()) {
    a->polygon_material.clear();
  } else {
    for (int& m : a->polygon_material)
      if (m >= int(a->materials.size())) m = -1;
  }
  keep->layout.format = std::move(layout);
  return soup;
}

}  // namespace

PolygonSoup parse_gltf(std::string_view data, MeshFormat format, const std::string& name,
                       const FileResolver& companions, KeptRecord* keep) {
  try {
    return read_scene(data, format, name, companions, keep);
  } catch (const nlohmann::json::exception& e) {  // a member of the wrong type
    throw InputError(name + ": malformed glTF (" + e.what() + ")");
  }
}

void summarize_gltf_document(const GltfDocument& doc, FileSummary& s) {
  const Json& json = doc.json;
  s.nodes = int(array_at(json, "nodes").size());
  s.meshes = int(array_at(json, "meshes").size());
  s.primitives = 0;
  for (const Json& mesh : array_at(json, "meshes"))
    s.primitives += int(array_at(mesh, "primitives").size());
  s.skins = int(array_at(json, "skins").size());
  s.animations = int(array_at(json, "animations").size());
  s.images = int(array_at(json, "images").size());
  if (s.materials.empty()) {
    for (const Json& m : array_at(json, "materials")) s.materials.push_back(m.value("name", ""));
  }
  for (const Json& e : array_at(doc.original, "extensionsUsed"))
    if (e.is_string()) s.extensions.push_back(e.get<std::string>());
  s.round_trip = "everything; POSITION, NORMAL and TANGENT rewritten (with their min and max)";
  for (const char* compressed : {"KHR_draco_mesh_compression", "EXT_meshopt_compression"}) {
    if (doc.uses(compressed)) {
      s.changes.push_back(std::string("primitives compressed by ") + compressed +
                          " are written uncompressed where their positions change");
    }
  }
  for (std::string& change : rig_changes(doc)) s.changes.push_back(std::move(change));
}

void summarize_gltf(const GltfLayout& layout, FileSummary& s) {
  summarize_gltf_document(layout.doc, s);
  const Json& json = layout.doc.json;
  std::set<int> meshes;
  std::set<std::tuple<int, int, int>> drawings;
  std::set<std::pair<int, int>> primitives;
  for (const GltfUnit& u : layout.units) {
    meshes.insert(u.mesh);
    drawings.insert({u.mesh, u.node, u.instance});
    if (!primitives.insert({u.mesh, u.primitive}).second) continue;
    const Json& prim = json["meshes"][u.mesh]["primitives"][u.primitive];
    s.morph_targets += int(array_at(prim, "targets").size());
    int sets = 0;
    while (prim["attributes"].contains("TEXCOORD_" + std::to_string(sets))) ++sets;
    s.uv_sets = std::max(s.uv_sets, sets);
  }
  s.meshes = int(meshes.size());
  s.drawings = int(drawings.size());
  s.primitives = int(layout.units.size());
}

FileSummary gltf_document_summary(std::string_view data, MeshFormat format, const std::string& name,
                                  const FileResolver& companions) {
  FileSummary s;
  s.format = format_name(format);
  try {
    summarize_gltf_document(load_gltf_document(data, format, name, companions), s);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(name + ": malformed glTF (" + e.what() + ")");
  }
  return s;
}

std::optional<std::pair<std::string, std::string>> gltf_image(const GltfDocument& doc, int image) {
  const Json& images = array_at(doc.json, "images");
  if (image < 0 || size_t(image) >= images.size()) return std::nullopt;
  const Json& i = images[image];
  if (i.contains("bufferView")) {
    try {
      const std::string_view bytes = doc.view_bytes(i["bufferView"].get<int>(), "image");
      return std::pair{std::string(bytes), i.value("mimeType", "")};
    } catch (const InputError&) {
      return std::nullopt;
    }
  }
  if (std::optional<DataUri> data = decode_data_uri(i.value("uri", ""))) {
    return std::pair{std::move(data->bytes), i.value("mimeType", data->mime_type)};
  }
  return std::nullopt;
}

}  // namespace specdeform::detail
