#include <array>
#include <cmath>
#include <cstring>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "gltf.h"
#include "mesh/file_layout.h"
#include "mesh/file_normals.h"
#include "mesh/float_cast.h"
#include "specdeform/exceptions.h"

namespace specdeform::detail {

namespace {

using Json = nlohmann::ordered_json;

std::string base64(std::string_view bytes) {
  static constexpr char kDigits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t n = uint32_t(uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) n |= uint32_t(uint8_t(bytes[i + 1])) << 8;
    if (i + 2 < bytes.size()) n |= uint8_t(bytes[i + 2]);
    out += kDigits[n >> 18];
    out += kDigits[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? kDigits[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[n & 63] : '=';
  }
  return out;
}

// Writes float values into a buffer where they differ from what is there (so that an unchanged
// value keeps its bytes).
struct FloatWriter {
  std::string& bytes;
  bool changed = false;

  void put(size_t at, float v) {
    float old;
    std::memcpy(&old, bytes.data() + at, 4);
    if (old == v || (std::isnan(old) && std::isnan(v))) return;
    std::memcpy(bytes.data() + at, &v, 4);
    changed = true;
  }
};

void append_u32(std::string& s, uint32_t v) {
  char b[4];
  std::memcpy(b, &v, 4);
  s.append(b, 4);
}

}  // namespace

EncodedMesh rewrite_gltf(const MeshFile& file, const Vertices& positions,
                         const Eigen::MatrixX3d& normals, const std::filesystem::path& out_name,
                         bool same_folder) {
  const GltfLayout& layout = std::get<GltfLayout>(file.layout->format);
  std::vector<std::string> buffers;
  for (const GltfBuffer& b : layout.buffers) buffers.push_back(b.bytes);
  std::vector<char> changed(buffers.size(), 0);
  // tinygltf read it; NUL padding (some writers pad a .glb's JSON chunk so) is not JSON.
  Json json =
      Json::parse(std::string_view(layout.json)
                      .substr(0, layout.json.find_last_not_of(std::string_view("\0 ", 2)) + 1),
                  nullptr, false);
  if (json.is_discarded()) throw InputError(file.name + ": its JSON cannot be rewritten");
  const Json original = json;
  const Eigen::MatrixX3d tangents = layout.tangents.rows() > 0 && normals.rows() > 0
                                        ? updated_tangents(file.attributes, file.rest, positions,
                                                           layout.tangents.leftCols<3>(), normals)
                                        : Eigen::MatrixX3d();
  for (const GltfPrimitive& p : layout.primitives) {
    const Eigen::Matrix3d A = p.world.topLeftCorner<3, 3>();
    const Eigen::Vector3d shift = p.world.topRightCorner<3, 1>();
    const Eigen::PartialPivLU<Eigen::Matrix3d> inverse(A);
    FloatWriter out{buffers[p.position.buffer]};
    Eigen::Array3f lo = Eigen::Array3f::Constant(INFINITY), hi = -lo;
    // Only what changed is written: an unchanged value keeps its bytes (no round trip through
    // the node's transform).
    for (int i = 0; i < p.position.count; ++i) {
      const int v = p.first_vertex + i;
      const size_t at = p.position.offset + size_t(i) * p.position.stride;
      if (positions.row(v) != file.rest.row(v)) {
        const Eigen::Vector3d world = positions.row(v).transpose();
        const Eigen::Vector3d local = inverse.solve(world - shift);
        for (int k = 0; k < 3; ++k) out.put(at + 4 * k, to_float(local[k], "a position"));
      }
      // The min and max of what the file holds (an unchanged value kept its bytes).
      Eigen::Vector3f stored;
      std::memcpy(stored.data(), buffers[p.position.buffer].data() + at, 12);
      lo = lo.min(stored.array());
      hi = hi.max(stored.array());
    }
    changed[p.position.buffer] |= out.changed;
    Json& accessor = json["accessors"][p.position.accessor];
    if (out.changed) {  // an accessor nothing moved in keeps its min and max as written
      accessor["min"] = {lo[0], lo[1], lo[2]};
      accessor["max"] = {hi[0], hi[1], hi[2]};
    }
    if (p.normal.accessor >= 0 && normals.rows() > 0) {
      FloatWriter n{buffers[p.normal.buffer]};
      for (int i = 0; i < p.normal.count; ++i) {
        if (normals.row(p.first_vertex + i) == file.attributes.normals.row(p.first_vertex + i)) {
          continue;
        }
        const Eigen::Vector3d local =
            (A.transpose() * normals.row(p.first_vertex + i).transpose()).normalized();
        const size_t at = p.normal.offset + size_t(i) * p.normal.stride;
        for (int k = 0; k < 3; ++k) n.put(at + 4 * k, float(local[k]));
      }
      changed[p.normal.buffer] |= n.changed;
    }
    if (p.tangent.accessor >= 0 && tangents.rows() > 0) {
      FloatWriter t{buffers[p.tangent.buffer]};
      for (int i = 0; i < p.tangent.count; ++i) {
        if (tangents.row(p.first_vertex + i) == layout.tangents.row(p.first_vertex + i).head<3>()) {
          continue;
        }
        const Eigen::Vector3d local =
            inverse.solve(tangents.row(p.first_vertex + i).transpose()).normalized();
        const size_t at = p.tangent.offset + size_t(i) * p.tangent.stride;
        for (int k = 0; k < 3; ++k) t.put(at + 4 * k, float(local[k]));
      }
      changed[p.tangent.buffer] |= t.changed;
    }
  }

  EncodedMesh encoded;
  encoded.files.push_back({out_name.filename().string(), {}});
  int renamed = 0;
  for (size_t b = 0; b < buffers.size(); ++b) {
    const GltfBuffer& buffer = layout.buffers[b];
    if (!changed[b] || buffer.source == GltfBufferSource::GlbChunk) continue;
    if (buffer.source == GltfBufferSource::DataUri) {
      const size_t comma = buffer.uri.find(',');
      json["buffers"][b]["uri"] = buffer.uri.substr(0, comma + 1) + base64(buffers[b]);
      continue;
    }
    // An external buffer: beside the output under its own name, unless that is the input's.
    const std::filesystem::path uri(buffer.uri);
    const bool inside = uri.is_relative() && !buffer.uri.empty() &&
                        std::find(uri.begin(), uri.end(), "..") == uri.end();
    std::string name = buffer.uri;
    if (same_folder || !inside) {
      name = out_name.stem().string() + (renamed > 0 ? "-" + std::to_string(renamed) : "") + ".bin";
      ++renamed;
      json["buffers"][b]["uri"] = name;
      encoded.notes.push_back("buffer " + std::to_string(b) + " ('" + buffer.uri +
                              "') written as " + name);
    }
    encoded.files.push_back({name, std::move(buffers[b])});
  }

  std::string text = layout.json;
  if (json != original) {
    const bool pretty = layout.json.find('\n') < layout.json.size() - 1;
    text = json.dump(pretty ? 2 : -1, ' ', false, Json::error_handler_t::replace);
    if (layout.json.ends_with('\n')) text += '\n';
  }
  std::string& main = encoded.files.front().bytes;
  if (layout.container == GltfContainer::Gltf) {
    main = text;
    return encoded;
  }
  std::string padded_json = text;
  padded_json.resize((padded_json.size() + 3) / 4 * 4, ' ');
  const bool has_bin =
      !layout.buffers.empty() && layout.buffers[0].source == GltfBufferSource::GlbChunk;
  std::string bin = has_bin ? buffers[0] : std::string();
  bin.resize((bin.size() + 3) / 4 * 4, '\0');
  const size_t total =
      12 + 8 + padded_json.size() + (has_bin ? 8 + bin.size() : 0) + layout.glb_tail.size();
  main.reserve(total);
  main.append("glTF", 4);
  append_u32(main, 2);
  append_u32(main, static_cast<uint32_t>(total));
  append_u32(main, static_cast<uint32_t>(padded_json.size()));
  append_u32(main, 0x4E4F534A);
  main += padded_json;
  if (has_bin) {
    append_u32(main, static_cast<uint32_t>(bin.size()));
    append_u32(main, 0x004E4942);
    main += bin;
  }
  main += layout.glb_tail;
  main += layout.glb_after;
  return encoded;
}

}  // namespace specdeform::detail
