// A kept glTF written again with new positions (gltf.h, rewrite_gltf).
//
// Each drawing of a primitive gets its POSITION, NORMAL and TANGENT elements in its mesh's own
// space (through the inverse of its world matrix), and its morph targets' deltas of the same
// three turned by each vertex's local rotation (MorphTargets::Turn: A^-1 R A d for positions and
// tangents, A^T R A^-T d for normals, A the drawing's linear map, R the rotation in world space).
// An accessor keeps serving every drawing whose
// elements come out the same: one whose values did not change keeps its bytes (and the text of
// its min and max); otherwise its first drawing's values are written in place when it is a
// plain float accessor. Drawings whose values come out different (a mesh drawn by two nodes that
// the deformation moves apart, an accessor shared by two meshes), and values an accessor cannot
// hold in place (quantised, sparse), get an accessor of their own in a new buffer view; the
// primitives that draw them are re-pointed, a mesh drawn by nodes that now need different
// accessors is copied for each of them and the nodes re-pointed, and everything else (indices,
// texture coordinates, materials, skins, targets that did not turn) stays shared. The min and
// max of every accessor written are those of its new values. Skins follow in gltf_rig.h.
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
#include "gltf_rig.h"
#include "mesh/file_layout.h"
#include "mesh/file_normals.h"
#include "mesh/float_cast.h"

namespace specdeform::detail {

namespace {

enum Kind { kPosition, kNormal, kTangent };
// An attribute of a primitive: its own (target -1) or morph target `target`'s delta.
struct Slot {
  int target = -1;
  Kind kind = kPosition;
  auto operator<=>(const Slot&) const = default;
};
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

  // Each drawing's elements, slot by slot (none where the slot is absent or not rewritten).
  void compute(const Vertices& positions, const Eigen::MatrixX3d& normals, MorphTargets targets) {
    const Eigen::MatrixX3d tangents =
        layout_.tangents.rows() > 0 && normals.rows() > 0
            ? updated_tangents(file_.attributes, file_.rest, positions,
                               layout_.tangents.leftCols<3>(), normals)
            : Eigen::MatrixX3d();
    std::vector<char> turned;
    std::vector<Eigen::Matrix3d> rotation;
    if (targets == MorphTargets::Turn && any_targets()) {
      rotation = vertex_rotations(file_.attributes, file_.rest, positions, turned);
    }
    values_.resize(layout_.units.size());
    for (size_t u = 0; u < layout_.units.size(); ++u) {
      const GltfUnit& unit = layout_.units[u];
      const Eigen::Matrix3d A = unit.world.topLeftCorner<3, 3>();
      const Eigen::Vector3d shift = unit.world.topRightCorner<3, 1>();
      const Eigen::PartialPivLU<Eigen::Matrix3d> inverse(A);
      const Eigen::Matrix3d A_inverse_T = inverse.inverse().transpose();
      const auto fill = [&](Slot slot, int accessor, const auto& moved, const auto& local) {
        if (accessor < 0) return;
        const Floats& rest = original(accessor, slot.kind);
        const int components = slot_components(slot);
        if (rest.size() != size_t(unit.count) * components) {
          doc_.fail("accessor " + std::to_string(accessor) + " (" + kAttribute[slot.kind] +
                    ") does not have its primitive's " + std::to_string(unit.count) + " elements");
        }
        Floats out = rest;
        bool any = false;
        for (int i = 0; i < unit.count; ++i) {
          const int v = unit.first_vertex + i;
          if (!moved(v)) continue;
          const Eigen::Vector3d x = local(v, &rest[size_t(i) * components]);
          for (int k = 0; k < 3; ++k) out[size_t(i) * components + k] = to_float(x[k], "a value");
          any = true;
        }
        // Directions that go from quantised (or compressed) storage into a new float accessor
        // are made unit where the storage rounded them (a quantised normal is not unit).
        if (any && slot.kind != kPosition && slot.target < 0 &&
            !float_slots(layout_.doc, accessor)) {
          for (size_t i = 0; i < out.size(); i += components) {
            const Eigen::Vector3f d = Eigen::Vector3f(&out[i]).normalized();
            if (d.allFinite()) std::copy(d.data(), d.data() + 3, &out[i]);
          }
        }
        values_[u][slot] = std::move(out);
      };
      fill(
          {-1, kPosition}, unit.position,
          [&](int v) { return positions.row(v) != file_.rest.row(v); },
          [&](int v, const float*) {
            return Eigen::Vector3d(inverse.solve(positions.row(v).transpose() - shift));
          });
      if (normals.rows() > 0) {
        fill(
            {-1, kNormal}, unit.normal,
            [&](int v) { return normals.row(v) != file_.attributes.normals.row(v); },
            [&](int v, const float*) {
              return Eigen::Vector3d((A.transpose() * normals.row(v).transpose()).normalized());
            });
      }
      if (tangents.rows() > 0) {
        fill(
            {-1, kTangent}, unit.tangent,
            [&](int v) { return tangents.row(v) != layout_.tangents.row(v).head<3>(); },
            [&](int v, const float*) {
              return Eigen::Vector3d(inverse.solve(tangents.row(v).transpose()).normalized());
            });
      }
      if (rotation.empty()) continue;
      const Json& list = array_at(primitive(unit), "targets");
      for (size_t t = 0; t < list.size(); ++t) {
        for (const Kind kind : {kPosition, kNormal, kTangent}) {
          fill(
              {int(t), kind}, target_accessor(list[t], kind), [&](int v) { return turned[v] != 0; },
              [&](int v, const float* rest) {
                const Eigen::Vector3d d(rest[0], rest[1], rest[2]);
                const Eigen::Matrix3d& R = rotation[v];
                if (kind == kNormal)
                  return Eigen::Vector3d(A.transpose() * (R * (A_inverse_T * d)));
                return Eigen::Vector3d(inverse.solve(R * (A * d)));
              });
        }
      }
    }
  }

  // Which accessor serves each drawing's slot: the same, written in place, or a new one.
  void assign() {
    std::map<int, std::vector<std::pair<size_t, Slot>>> users;  // accessor -> (unit, slot)
    for (size_t u = 0; u < layout_.units.size(); ++u) {
      for (const auto& [slot, values] : values_[u])
        users[accessor_of(u, slot)].emplace_back(u, slot);
    }
    serving_.assign(layout_.units.size(), {});
    for (const auto& [accessor, used] : users) {
      const Kind kind = used.front().second.kind;
      const int components = slot_components(used.front().second);
      // Classes of equal values, in drawing order.
      std::vector<const Floats*> classes;
      std::vector<size_t> class_of;
      for (const auto& [u, slot] : used) {
        const Floats& values = values_[u].at(slot);
        size_t c = 0;
        while (c < classes.size() && !alike(*classes[c], values)) ++c;
        if (c == classes.size()) classes.push_back(&values);
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
          write_in_place(accessor, kind, components, *classes[c]);
          target[c] = accessor;
        } else {
          target[c] = new_accessor(accessor, kind, components, *classes[c]);
        }
      }
      for (size_t i = 0; i < used.size(); ++i) {
        const auto [u, slot] = used[i];
        serving_[u][slot] = target[class_of[i]];
        if (slot.target >= 0 && class_of[i] != unchanged) {
          turned_.insert({layout_.units[u].mesh, layout_.units[u].primitive, slot.target});
        }
      }
    }
  }

  // Primitives pointed at their drawings' new accessors; meshes copied where the nodes (or
  // instances) that draw them need different ones.
  void repoint() {
    using Drawer = std::pair<int, int>;                              // node, instance
    std::map<Drawer, std::map<std::pair<int, Slot>, int>> replaced;  // (accessor, slot) -> new
    std::map<Drawer, int> mesh_of;
    for (size_t u = 0; u < layout_.units.size(); ++u) {
      const GltfUnit& unit = layout_.units[u];
      const Drawer drawer{unit.node, unit.instance};
      mesh_of[drawer] = unit.mesh;
      for (const auto& [slot, accessor] : serving_[u]) {
        const int was = accessor_of(u, slot);
        if (accessor != was) replaced[drawer][{was, slot}] = accessor;
      }
    }
    // Each drawer's mesh as it needs it.
    std::map<int, std::vector<std::pair<Drawer, Json>>> drawn;
    for (const auto& [drawer, mesh] : mesh_of) {
      Json own = doc_.json["meshes"][mesh];
      if (const auto r = replaced.find(drawer); r != replaced.end()) {
        const auto repoint = [&](Json& attributes, int target) {
          for (const Kind kind : {kPosition, kNormal, kTangent}) {
            if (!attributes.contains(kAttribute[kind])) continue;
            const auto it =
                r->second.find({json_index(attributes[kAttribute[kind]]), Slot{target, kind}});
            if (it != r->second.end()) attributes[kAttribute[kind]] = it->second;
          }
        };
        for (Json& prim : own["primitives"]) {
          repoint(prim["attributes"], -1);
          if (!prim.contains("targets")) continue;
          for (size_t t = 0; t < prim["targets"].size(); ++t) repoint(prim["targets"][t], int(t));
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
      notes_.push_back(std::to_string(created_) +
                       " POSITION, NORMAL or TANGENT accessors (or morph target deltas) added "
                       "where drawings that shared one "
                       "came out different or the original could not hold the new values; " +
                       std::to_string(copies) +
                       " meshes copied for the nodes that draw them, everything else still shared "
                       "(the output's vertex numbering follows its own meshes)");
    }
    if (!turned_.empty()) {
      std::set<std::pair<int, int>> all, turned;  // (mesh, target)
      for (const GltfUnit& unit : layout_.units)
        for (size_t t = 0; t < array_at(primitive(unit), "targets").size(); ++t)
          all.insert({unit.mesh, int(t)});
      for (const auto& [mesh, prim, t] : turned_) turned.insert({mesh, t});
      notes_.push_back(std::to_string(turned.size()) + " of " + std::to_string(all.size()) +
                       " morph targets turned with the surface (their deltas by each vertex's "
                       "local rotation; morph targets \"keep\" leaves them)");
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

  void follow_joints(const Vertices& positions) {
    for (std::string& note : detail::follow_joints(doc_, layout_, file_.rest, positions)) {
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
  bool any_targets() const {
    return std::any_of(layout_.units.begin(), layout_.units.end(), [&](const GltfUnit& unit) {
      return !array_at(primitive(unit), "targets").empty();
    });
  }

  const Json& primitive(const GltfUnit& unit) const {
    return doc_.json["meshes"][unit.mesh]["primitives"][unit.primitive];
  }

  static int target_accessor(const Json& target, Kind kind) {
    return target.is_object() && target.contains(kAttribute[kind])
               ? json_index(target[kAttribute[kind]])
               : -1;
  }

  // The accessor the file gives drawing `u`'s slot.
  int accessor_of(size_t u, Slot slot) const {
    const GltfUnit& unit = layout_.units[u];
    if (slot.target >= 0) {
      return target_accessor(array_at(primitive(unit), "targets")[slot.target], slot.kind);
    }
    return slot.kind == kPosition ? unit.position
           : slot.kind == kNormal ? unit.normal
                                  : unit.tangent;
  }

  // Elements' components: 3, and 4 for a primitive's own TANGENT (morph targets' are 3).
  static int slot_components(Slot slot) { return slot.target < 0 ? kComponents[slot.kind] : 3; }

  const Floats& original(int accessor, Kind kind) {
    auto it = original_.find(accessor);
    if (it == original_.end()) {
      it = original_
               .emplace(accessor, as_floats(read_accessor(layout_.doc, accessor, kAttribute[kind])))
               .first;
    }
    return it->second;
  }

  void write_in_place(int accessor, Kind kind, int components, const Floats& values) {
    write_floats(doc_, accessor, values, components);
    set_float_bounds(doc_.json["accessors"][accessor], values, components, kind == kPosition);
  }

  int new_accessor(int accessor, Kind kind, int components, const Floats& values) {
    const int a = add_float_accessor(doc_, accessor, values, components, 34962);
    set_float_bounds(doc_.json["accessors"][a], values, components, kind == kPosition);
    ++created_;
    return a;
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
  std::vector<std::map<Slot, Floats>> values_;  // per unit, per rewritten slot: its values
  std::vector<std::map<Slot, int>> serving_;    // per unit, per rewritten slot: the accessor
  std::map<int, Floats> original_;
  std::set<std::array<int, 3>> turned_;  // morph targets changed: (mesh, primitive, target)
  int created_ = 0;
};

}  // namespace

EncodedMesh rewrite_gltf(const MeshFile& file, const Vertices& positions,
                         const Eigen::MatrixX3d& normals, const std::filesystem::path& out_name,
                         const std::set<std::string>& taken, const WriteOptions& options) {
  const GltfLayout& layout = std::get<GltfLayout>(file.layout->format);
  EncodedMesh out;
  Rewriter rewriter(file, layout, out.notes);
  rewriter.compute(positions, normals, options.morph_targets);
  rewriter.assign();
  rewriter.repoint();
  if (options.joints == Joints::Follow) rewriter.follow_joints(positions);
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
