// A kept glTF written again with new positions (gltf.h, rewrite_gltf).
//
// Each drawing of a primitive gets its POSITION, NORMAL and TANGENT elements in its mesh's own
// space (through the inverse of its world matrix). An accessor keeps serving every drawing whose
// elements come out the same: one whose values did not change keeps its bytes (and the text of
// its min and max); otherwise its first drawing's values are written in place when it is a
// plain float accessor. Drawings whose values come out different (a mesh drawn by two nodes that
// the deformation moves apart, an accessor shared by two meshes), and values an accessor cannot
// hold in place (quantised, sparse), get an accessor of their own in a new buffer view; the
// primitives that draw them are re-pointed, a mesh drawn by nodes that now need different
// accessors is copied for each of them and the nodes re-pointed, and everything else (indices,
// texture coordinates, materials, morph targets, skins) stays shared. The min and max of every
// accessor written are those of its new values.
//
// The container is `out_name`'s: a .glb's BIN chunk becomes `<out stem>.bin` in a .gltf; a
// .gltf's buffers and images move into a .glb's BIN chunk; nothing else changes. A changed
// buffer that lives in a file is written as `<out stem>.bin` (`<out stem>-1.bin`, ... for more),
// never under a name the input's files use when the output is in their folder.
#include <algorithm>
#include <array>
#include <cstring>
#include <map>
#include <set>

#include <Eigen/Dense>

#include "data_uri.h"
#include "gltf.h"
#include "gltf_decode.h"
#include "mesh/file_layout.h"
#include "mesh/file_normals.h"
#include "mesh/float_cast.h"

namespace specdeform::detail {

namespace {

enum Kind { kPosition, kNormal, kTangent };
constexpr const char* kAttribute[] = {"POSITION", "NORMAL", "TANGENT"};
constexpr int kComponents[] = {3, 3, 4};

using Floats = std::vector<float>;

Floats as_floats(const AccessorValues& v) {
  Floats out(v.values.size());
  for (size_t i = 0; i < out.size(); ++i) out[i] = float(v.values[i]);
  return out;
}

bool same_bits(const Floats& a, const Floats& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

// Values that two drawings computed through different transforms and that agree to float
// rounding (1e-6 of their largest magnitude): one accessor serves both.
bool alike(const Floats& a, const Floats& b) {
  if (a.size() != b.size()) return false;
  float scale = 0.0f, gap = 0.0f;
  for (size_t i = 0; i < a.size(); ++i) {
    scale = std::max(scale, std::abs(a[i]));
    gap = std::max(gap, std::abs(a[i] - b[i]));
  }
  return gap <= 1e-6f * scale;
}

Json min_max(const Floats& values, int components, bool max) {
  Json out = Json::array();
  for (int k = 0; k < components; ++k) {
    float m = max ? -INFINITY : INFINITY;
    for (size_t i = k; i < values.size(); i += components)
      m = max ? std::max(m, values[i]) : std::min(m, values[i]);
    out.push_back(double(m));
  }
  return out;
}

std::string image_mime(const std::string& name) {
  std::string ext = std::filesystem::path(name).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".png") return "image/png";
  if (ext == ".jpg" || ext == ".jpeg") return "image/jpeg";
  if (ext == ".webp") return "image/webp";
  if (ext == ".ktx2") return "image/ktx2";
  return "application/octet-stream";
}

class Rewriter {
 public:
  Rewriter(const MeshFile& file, const GltfLayout& layout, std::vector<std::string>& notes)
      : file_(file), layout_(layout), doc_(layout.doc), notes_(notes) {}

  // Each drawing's new elements, kind by kind (empty where the kind is absent or not rewritten).
  void compute(const Vertices& positions, const Eigen::MatrixX3d& normals) {
    const Eigen::MatrixX3d tangents =
        layout_.tangents.rows() > 0 && normals.rows() > 0
            ? updated_tangents(file_.attributes, file_.rest, positions,
                               layout_.tangents.leftCols<3>(), normals)
            : Eigen::MatrixX3d();
    values_.resize(layout_.units.size());
    for (size_t u = 0; u < layout_.units.size(); ++u) {
      const GltfUnit& unit = layout_.units[u];
      const Eigen::Matrix3d A = unit.world.topLeftCorner<3, 3>();
      const Eigen::Vector3d shift = unit.world.topRightCorner<3, 1>();
      const Eigen::PartialPivLU<Eigen::Matrix3d> inverse(A);
      const auto fill = [&](Kind kind, int accessor, const auto& moved, const auto& local) {
        if (accessor < 0) return;
        const Floats& rest = original(accessor, kind);
        Floats& out = values_[u][kind];
        out = rest;
        bool any = false;
        for (int i = 0; i < unit.count; ++i) {
          const int v = unit.first_vertex + i;
          if (!moved(v)) continue;
          const Eigen::Vector3d x = local(v);
          for (int k = 0; k < 3; ++k) {
            out[size_t(i) * kComponents[kind] + k] = to_float(x[k], "a value");
          }
          any = true;
        }
        // Directions that go from quantised (or compressed) storage into a new float accessor
        // are made unit where the storage rounded them (a quantised normal is not unit).
        if (!any || kind == kPosition || float_slots(layout_.doc, accessor)) return;
        for (size_t i = 0; i < out.size(); i += kComponents[kind]) {
          const Eigen::Vector3f d = Eigen::Vector3f(&out[i]).normalized();
          if (d.allFinite()) std::copy(d.data(), d.data() + 3, &out[i]);
        }
      };
      fill(
          kPosition, unit.position, [&](int v) { return positions.row(v) != file_.rest.row(v); },
          [&](int v) {
            return Eigen::Vector3d(inverse.solve(positions.row(v).transpose() - shift));
          });
      if (normals.rows() == 0) continue;
      fill(
          kNormal, unit.normal,
          [&](int v) { return normals.row(v) != file_.attributes.normals.row(v); },
          [&](int v) {
            return Eigen::Vector3d((A.transpose() * normals.row(v).transpose()).normalized());
          });
      if (tangents.rows() == 0) continue;
      fill(
          kTangent, unit.tangent,
          [&](int v) { return tangents.row(v) != layout_.tangents.row(v).head<3>(); },
          [&](int v) {
            return Eigen::Vector3d(inverse.solve(tangents.row(v).transpose()).normalized());
          });
    }
  }

  // Which accessor serves each drawing's kind: the same, written in place, or a new one.
  void assign() {
    std::map<std::pair<int, Kind>, std::vector<size_t>> users;
    for (size_t u = 0; u < layout_.units.size(); ++u) {
      const GltfUnit& unit = layout_.units[u];
      for (const Kind kind : {kPosition, kNormal, kTangent}) {
        const int a = kind == kPosition ? unit.position
                      : kind == kNormal ? unit.normal
                                        : unit.tangent;
        if (a >= 0 && !values_[u][kind].empty()) users[{a, kind}].push_back(u);
      }
    }
    serving_.assign(layout_.units.size(), {-1, -1, -1});
    for (const auto& [key, units] : users) {
      const auto [accessor, kind] = key;
      // Classes of equal values, in drawing order.
      std::vector<const Floats*> classes;
      std::vector<size_t> class_of;
      for (const size_t u : units) {
        size_t c = 0;
        while (c < classes.size() && !alike(*classes[c], values_[u][kind])) ++c;
        if (c == classes.size()) classes.push_back(&values_[u][kind]);
        class_of.push_back(c);
      }
      const Floats& rest = original(accessor, kind);
      size_t unchanged = classes.size();
      for (size_t c = 0; c < classes.size(); ++c)
        if (same_bits(*classes[c], rest)) unchanged = c;
      std::vector<int> target(classes.size(), -1);
      for (size_t c = 0; c < classes.size(); ++c) {
        if (c == unchanged) {
          target[c] = accessor;
        } else if (unchanged == classes.size() && c == 0 && float_slots(doc_, accessor)) {
          write_in_place(accessor, kind, *classes[c]);
          target[c] = accessor;
        } else {
          target[c] = new_accessor(accessor, kind, *classes[c]);
        }
      }
      for (size_t i = 0; i < units.size(); ++i) serving_[units[i]][kind] = target[class_of[i]];
    }
  }

  // Primitives pointed at their drawings' new accessors; meshes copied where the nodes (or
  // instances) that draw them need different ones.
  void repoint() {
    using Drawer = std::pair<int, int>;                             // node, instance
    std::map<Drawer, std::map<std::pair<int, int>, int>> replaced;  // (accessor, kind) -> new
    std::map<Drawer, int> mesh_of;
    for (size_t u = 0; u < layout_.units.size(); ++u) {
      const GltfUnit& unit = layout_.units[u];
      const Drawer drawer{unit.node, unit.instance};
      mesh_of[drawer] = unit.mesh;
      const int original[3] = {unit.position, unit.normal, unit.tangent};
      for (const Kind kind : {kPosition, kNormal, kTangent}) {
        if (serving_[u][kind] >= 0 && serving_[u][kind] != original[kind]) {
          replaced[drawer][{original[kind], kind}] = serving_[u][kind];
        }
      }
    }
    // Each drawer's mesh as it needs it.
    std::map<int, std::vector<std::pair<Drawer, Json>>> drawn;
    for (const auto& [drawer, mesh] : mesh_of) {
      Json own = doc_.json["meshes"][mesh];
      if (const auto r = replaced.find(drawer); r != replaced.end()) {
        for (Json& prim : own["primitives"]) {
          Json& attributes = prim["attributes"];
          for (const Kind kind : {kPosition, kNormal, kTangent}) {
            if (!attributes.contains(kAttribute[kind])) continue;
            const auto it = r->second.find({attributes[kAttribute[kind]].get<int>(), kind});
            if (it != r->second.end()) attributes[kAttribute[kind]] = it->second;
          }
        }
      }
      drawn[mesh].emplace_back(drawer, std::move(own));
    }
    // The mesh itself goes to the drawers that keep it as it is, else to the first; each other
    // version is a new mesh.
    std::map<Drawer, int> mesh_index;
    int copies = 0;
    for (auto& [mesh, drawers] : drawn) {
      const Json original = doc_.json["meshes"][mesh];
      const Json* kept = &drawers.front().second;
      for (const auto& [drawer, own] : drawers)
        if (own == original) kept = &own;
      std::vector<std::pair<const Json*, int>> made{{kept, mesh}};
      for (const auto& [drawer, needed] : drawers) {
        const Json& own = needed;  // a binding a lambda can take
        auto it =
            std::find_if(made.begin(), made.end(), [&](const auto& m) { return *m.first == own; });
        if (it == made.end()) {
          doc_.json["meshes"].push_back(own);
          made.emplace_back(&own, int(doc_.json["meshes"].size()) - 1);
          it = made.end() - 1;
          ++copies;
        }
        mesh_index[drawer] = it->second;
      }
      if (*kept != original) doc_.json["meshes"][mesh] = *kept;
    }
    std::map<int, std::vector<int>> instanced;  // node -> each instance's mesh
    for (const auto& [drawer, index] : mesh_index) {
      if (drawer.second >= 0) {
        instanced[drawer.first].push_back(index);
      } else if (index != mesh_of[drawer]) {
        doc_.json["nodes"][drawer.first]["mesh"] = index;
      }
    }
    int expanded = 0;
    for (const auto& [node, meshes] : instanced) expanded += draw_instances(doc_, node, meshes);
    if (created_ > 0) {
      notes_.push_back(
          std::to_string(created_) +
          " POSITION, NORMAL or TANGENT accessors added where drawings that shared one "
          "came out different or the original could not hold the new values; " +
          std::to_string(copies) +
          " meshes copied for the nodes that draw them, everything else still shared "
          "(the output's vertex numbering follows its own meshes)");
    }
    if (expanded > 0) {
      notes_.push_back(std::to_string(expanded) +
                       " nodes drawn by EXT_mesh_gpu_instancing written as one child node per "
                       "instance (their instances came out different)");
    }
    for (std::string& note : uncompress_changed_draco(doc_, layout_.doc.json)) {
      notes_.push_back(std::move(note));
    }
  }

  // The document in `container`, its changed files named after `stem`, never as one of `taken`.
  GltfDocument finish(GltfContainer container, const std::string& stem,
                      const std::set<std::string>& taken) {
    if (container == GltfContainer::Glb && doc_.container == GltfContainer::Gltf) into_glb();
    if (container == GltfContainer::Gltf && doc_.container == GltfContainer::Glb) {
      doc_.container = GltfContainer::Gltf;
      if (!doc_.buffers.empty() && doc_.buffers[0].source == GltfBufferSource::GlbChunk) {
        doc_.buffers[0].source = GltfBufferSource::External;
        doc_.buffers[0].changed = true;
      }
    }
    int written = 0;
    for (size_t b = 0; b < doc_.buffers.size(); ++b) {
      GltfBuffer& buffer = doc_.buffers[b];
      if (!buffer.changed || buffer.source != GltfBufferSource::External) continue;
      std::string name;
      do {
        name = stem;
        if (written > 0) name.append("-").append(std::to_string(written));
        name += ".bin";
        ++written;
      } while (taken.count(name));
      const std::string uri = encode_uri(name);
      if (doc_.json["buffers"][b].value("uri", "") != uri) {
        if (!buffer.uri.empty()) {
          notes_.push_back("buffer " + std::to_string(b) + " ('" + decode_uri(buffer.uri) +
                           "') written as " + name);
        }
        doc_.json["buffers"][b]["uri"] = uri;
      }
    }
    return std::move(doc_);
  }

 private:
  const Floats& original(int accessor, Kind kind) {
    auto it = original_.find(accessor);
    if (it == original_.end()) {
      it = original_
               .emplace(accessor, as_floats(read_accessor(layout_.doc, accessor, kAttribute[kind])))
               .first;
    }
    return it->second;
  }

  void set_bounds(Json& accessor, Kind kind, const Floats& values) {
    if (kind != kPosition && !accessor.contains("min") && !accessor.contains("max")) return;
    accessor["min"] = min_max(values, kComponents[kind], false);
    accessor["max"] = min_max(values, kComponents[kind], true);
  }

  void write_in_place(int accessor, Kind kind, const Floats& values) {
    const FloatSlots slots = *float_slots(doc_, accessor);
    GltfBuffer& buffer = doc_.buffers[slots.buffer];
    const int components = kComponents[kind];
    for (size_t i = 0; i < values.size() / components; ++i) {
      char* at = buffer.bytes.data() + slots.offset + i * slots.stride;
      if (std::memcmp(at, values.data() + i * components, components * sizeof(float)) != 0) {
        std::memcpy(at, values.data() + i * components, components * sizeof(float));
        buffer.changed = true;
      }
    }
    set_bounds(doc_.json["accessors"][accessor], kind, values);
  }

  int new_accessor(int accessor, Kind kind, const Floats& values) {
    Json a = doc_.json["accessors"][accessor];
    int buffer = -1;
    if (a.contains("bufferView")) {
      buffer = doc_.json["bufferViews"][a["bufferView"].get<int>()].value("buffer", -1);
    }
    const std::string_view bytes(reinterpret_cast<const char*>(values.data()),
                                 values.size() * sizeof(float));
    a["bufferView"] = doc_.append_view(doc_.data_buffer(buffer), bytes, 34962);
    a.erase("byteOffset");
    a.erase("sparse");
    a.erase("normalized");
    a["componentType"] = 5126;
    a["count"] = values.size() / kComponents[kind];
    set_bounds(a, kind, values);
    doc_.json["accessors"].push_back(std::move(a));
    ++created_;
    return int(doc_.json["accessors"].size()) - 1;
  }

  // A .gltf's buffers and images moved into one BIN chunk (buffers without bytes, meshopt's
  // fallbacks, stay buffers of their own).
  void into_glb() {
    GltfBuffer bin;
    bin.source = GltfBufferSource::GlbChunk;
    bin.changed = true;
    std::vector<GltfBuffer> buffers;
    Json json_buffers = Json::array({Json::object()});
    std::vector<std::pair<int, size_t>> moved;  // buffer -> (new index, base offset)
    for (size_t b = 0; b < doc_.buffers.size(); ++b) {
      if (doc_.buffers[b].source == GltfBufferSource::None) {
        moved.emplace_back(int(json_buffers.size()), 0);
        json_buffers.push_back(doc_.json["buffers"][b]);
        buffers.push_back(std::move(doc_.buffers[b]));
        continue;
      }
      bin.bytes.resize((bin.bytes.size() + 3) / 4 * 4, '\0');
      moved.emplace_back(0, bin.bytes.size());
      bin.bytes += doc_.buffers[b].bytes;
    }
    const auto move = [&](Json& at) {
      const Json& buffer = at.contains("buffer") ? at["buffer"] : Json();
      if (!buffer.is_number_integer() || buffer.get<long long>() < 0 ||
          buffer.get<size_t>() >= moved.size()) {
        doc_.fail("a buffer view names buffer " + buffer.dump() + " of " +
                  std::to_string(moved.size()));
      }
      const auto [index, base] = moved[buffer.get<size_t>()];
      at["buffer"] = index;
      if (base > 0) at["byteOffset"] = at.value("byteOffset", size_t(0)) + base;
    };
    if (doc_.json.contains("bufferViews")) {
      for (Json& view : doc_.json["bufferViews"]) {
        move(view);
        if (view.contains("extensions") && view["extensions"].contains("EXT_meshopt_compression")) {
          move(view["extensions"]["EXT_meshopt_compression"]);
        }
      }
    }
    json_buffers[0]["byteLength"] = bin.bytes.size();
    buffers.insert(buffers.begin(), std::move(bin));
    doc_.buffers = std::move(buffers);
    doc_.json["buffers"] = std::move(json_buffers);
    doc_.container = GltfContainer::Glb;
    int embedded = 0;
    if (!doc_.json.contains("images")) return;
    for (size_t i = 0; i < doc_.json["images"].size(); ++i) {
      const std::string uri = doc_.json["images"][i].value("uri", "");
      if (uri.empty()) continue;
      std::optional<DataUri> data = decode_data_uri(uri);
      if (!data) {
        std::optional<std::string> bytes;
        try {
          bytes = file_.companions ? file_.companions(decode_uri(uri)) : std::nullopt;
        } catch (const InputError&) {
        }
        if (!bytes) {
          notes_.push_back("image " + std::to_string(i) + " ('" + decode_uri(uri) +
                           "') was not found: left as a file beside the .glb");
          continue;
        }
        data = DataUri{image_mime(decode_uri(uri)), std::move(*bytes)};
      }
      const int view = doc_.append_view(0, data->bytes, 0);
      Json& image = doc_.json["images"][i];
      image.erase("uri");
      image["bufferView"] = view;
      if (!image.contains("mimeType")) image["mimeType"] = data->mime_type;
      ++embedded;
    }
    if (embedded > 0) notes_.push_back(std::to_string(embedded) + " images embedded in the .glb");
  }

  const MeshFile& file_;
  const GltfLayout& layout_;
  GltfDocument doc_;
  std::vector<std::string>& notes_;
  std::vector<std::array<Floats, 3>> values_;  // per unit, per kind
  std::vector<std::array<int, 3>> serving_;    // per unit, per kind: the accessor
  std::map<int, Floats> original_;
  int created_ = 0;
};

}  // namespace

EncodedMesh rewrite_gltf(const MeshFile& file, const Vertices& positions,
                         const Eigen::MatrixX3d& normals, const std::filesystem::path& out_name,
                         const std::set<std::string>& taken) {
  const GltfLayout& layout = std::get<GltfLayout>(file.layout->format);
  EncodedMesh out;
  Rewriter rewriter(file, layout, out.notes);
  rewriter.compute(positions, normals);
  rewriter.assign();
  rewriter.repoint();
  const GltfContainer container =
      mesh_format_from_path(out_name) == MeshFormat::Glb ? GltfContainer::Glb : GltfContainer::Gltf;
  const GltfDocument doc = rewriter.finish(container, out_name.stem().string(), taken);
  EncodedDocument encoded = encode_gltf_document(doc);
  out.files.push_back({out_name.filename().string(), std::move(encoded.main)});
  for (OutputFile& f : encoded.buffers) out.files.push_back(std::move(f));
  for (const std::string& name : gltf_companions(doc)) {
    if (std::none_of(out.files.begin(), out.files.end(),
                     [&](const OutputFile& f) { return f.name == name; })) {
      out.companions.push_back(name);
    }
  }
  return out;
}

}  // namespace specdeform::detail
