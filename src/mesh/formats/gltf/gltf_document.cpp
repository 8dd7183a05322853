#include "gltf_document.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>

#include "data_uri.h"
#include "specdeform/exceptions.h"

namespace specdeform::detail {

namespace {

constexpr uint32_t kGlbMagic = 0x46546C67, kJsonChunk = 0x4E4F534A, kBinChunk = 0x004E4942;

uint32_t read_u32(std::string_view data, size_t at) {
  uint32_t v;
  std::memcpy(&v, data.data() + at, 4);
  return v;
}

void append_u32(std::string& s, uint32_t v) {
  char b[4];
  std::memcpy(b, &v, 4);
  s.append(b, 4);
}

// A .glb's chunks: the JSON, the BIN chunk (if any) and what follows it.
struct GlbChunks {
  std::string_view json, bin, tail, after;  // after: bytes beyond the header's length
  bool has_bin = false;
};

GlbChunks split_glb(std::string_view data, const std::string& name) {
  const auto fail = [&](const std::string& what) -> GlbChunks {
    throw InputError(name + ": not a glTF binary file (" + what + ")");
  };
  if (data.size() < 20) fail("shorter than its header");
  if (read_u32(data, 0) != kGlbMagic) fail("no 'glTF' magic");
  if (read_u32(data, 4) != 2) fail("version " + std::to_string(read_u32(data, 4)) + ", not 2");
  if (read_u32(data, 8) > data.size()) fail("truncated: the header announces more bytes");
  GlbChunks out;
  out.after = data.substr(read_u32(data, 8));
  data = data.substr(0, read_u32(data, 8));
  size_t at = 12;
  for (int chunk = 0; at + 8 <= data.size(); ++chunk) {
    const uint32_t length = read_u32(data, at), type = read_u32(data, at + 4);
    if (length > data.size() - at - 8) fail("truncated chunk " + std::to_string(chunk));
    const std::string_view body = data.substr(at + 8, length);
    if (chunk == 0) {
      if (type != kJsonChunk) fail("the first chunk is not JSON");
      out.json = body;
    } else if (chunk == 1 && type == kBinChunk) {
      out.bin = body;
      out.has_bin = true;
    } else {
      out.tail = data.substr(at);
      break;
    }
    at += 8 + length;
  }
  if (out.tail.empty()) out.tail = data.substr(std::min(at, data.size()));  // under a chunk header
  if (out.json.empty()) fail("no JSON chunk");
  return out;
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// A count, index or byte offset: SIZE_MAX for anything but a whole number >= 0.
size_t index_of(const Json& v) {
  return v.is_number_integer() && v.get<long long>() >= 0 ? v.get<size_t>() : SIZE_MAX;
}

}  // namespace

int json_index(const Json& v) {
  return v.is_number_integer() && v.get<long long>() >= 0 && v.get<long long>() < INT32_MAX
             ? v.get<int>()
             : -1;
}

const Json& array_at(const Json& object, const char* key) {
  static const Json empty = Json::array();
  if (!object.is_object()) return empty;
  const auto it = object.find(key);
  return it != object.end() && it->is_array() ? *it : empty;
}

const Json& object_at(const Json& object, const char* key) {
  static const Json empty = Json::object();
  if (!object.is_object()) return empty;
  const auto it = object.find(key);
  return it != object.end() && it->is_object() ? *it : empty;
}

std::string decode_uri(std::string_view uri) {
  std::string out;
  out.reserve(uri.size());
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && hex_value(uri[i + 1]) >= 0 &&
        hex_value(uri[i + 2]) >= 0) {
      out += char(hex_value(uri[i + 1]) * 16 + hex_value(uri[i + 2]));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

std::string encode_uri(std::string_view name) {
  std::string out;
  for (const unsigned char c : name) {
    if (std::isalnum(c) || std::strchr("-._~/", c)) {
      out += char(c);
    } else {
      char hex[4];
      std::snprintf(hex, sizeof hex, "%%%02X", c);
      out += hex;
    }
  }
  return out;
}

FileResolver uri_resolver(FileResolver resolve) {
  if (!resolve) return resolve;
  return [resolve = std::move(resolve)](const std::string& name) {
    std::optional<std::string> bytes = resolve(name);
    if (const std::string uri = encode_uri(name); !bytes && uri != name) bytes = resolve(uri);
    return bytes;
  };
}

int type_components(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4" || type == "MAT2") return 4;
  if (type == "MAT3") return 9;
  if (type == "MAT4") return 16;
  return 0;
}

int component_size(int component_type) {
  switch (component_type) {
    case 5120:  // BYTE
    case 5121:  // UNSIGNED_BYTE
      return 1;
    case 5122:  // SHORT
    case 5123:  // UNSIGNED_SHORT
      return 2;
    case 5125:  // UNSIGNED_INT
    case 5126:  // FLOAT
      return 4;
  }
  return 0;
}

void GltfDocument::fail(const std::string& what) const {
  throw InputError(name + ": " + what);
}

std::string_view GltfDocument::view_bytes(int view, const std::string& what) const {
  if (const auto decoded = decoded_views.find(view); decoded != decoded_views.end()) {
    return decoded->second;
  }
  const Json& views = array_at(json, "bufferViews");
  if (view < 0 || size_t(view) >= views.size() || !views[view].is_object()) {
    fail(what + " names a missing buffer view");
  }
  const Json& v = views[view];
  const size_t buffer = index_of(v.value("buffer", Json(-1)));
  if (buffer >= buffers.size())
    fail(what + ": buffer view " + std::to_string(view) + " names a missing buffer");
  const std::string& bytes = buffers[buffer].bytes;
  const size_t offset = index_of(v.value("byteOffset", Json(0)));
  const size_t length = index_of(v.value("byteLength", Json(-1)));
  if (offset > bytes.size() || length > bytes.size() - offset) {
    fail(what + ": buffer view " + std::to_string(view) + " reaches beyond its buffer");
  }
  return std::string_view(bytes).substr(offset, length);
}

int GltfDocument::data_buffer(int preferred) {
  const auto has_bytes = [&](int b) {
    return b >= 0 && size_t(b) < buffers.size() && buffers[b].source != GltfBufferSource::None;
  };
  if (has_bytes(preferred)) return preferred;
  if (container == GltfContainer::Glb && !buffers.empty() &&
      buffers[0].source == GltfBufferSource::GlbChunk) {
    return 0;
  }
  for (size_t b = 0; b < buffers.size(); ++b)
    if (has_bytes(int(b))) return int(b);
  GltfBuffer buffer;
  buffer.source = container == GltfContainer::Glb && buffers.empty() ? GltfBufferSource::GlbChunk
                                                                     : GltfBufferSource::External;
  buffer.changed = true;
  buffers.push_back(buffer);
  json["buffers"].push_back({{"byteLength", 0}});
  return int(buffers.size()) - 1;
}

size_t GltfDocument::append(int buffer, std::string_view bytes) {
  std::string& data = buffers[buffer].bytes;
  data.resize((data.size() + 3) / 4 * 4, '\0');
  const size_t offset = data.size();
  data.append(bytes);
  buffers[buffer].changed = true;
  json["buffers"][buffer]["byteLength"] = data.size();
  return offset;
}

int GltfDocument::append_view(int buffer, std::string_view bytes, int target) {
  Json view = {
      {"buffer", buffer}, {"byteOffset", append(buffer, bytes)}, {"byteLength", bytes.size()}};
  if (target != 0) view["target"] = target;
  json["bufferViews"].push_back(std::move(view));
  return int(json["bufferViews"].size()) - 1;
}

bool GltfDocument::uses(const std::string& extension) const {
  const Json& used = array_at(json, "extensionsUsed");
  return used.is_array() && std::find(used.begin(), used.end(), extension) != used.end();
}

void GltfDocument::drop_extension(const std::string& extension) {
  for (const char* list : {"extensionsUsed", "extensionsRequired"}) {
    if (!json.contains(list) || !json[list].is_array()) continue;
    Json kept = Json::array();
    for (const Json& e : json[list])
      if (e != extension) kept.push_back(e);
    if (kept.empty()) {
      json.erase(list);
    } else {
      json[list] = std::move(kept);
    }
  }
}

GltfDocument load_gltf_document(std::string_view data, MeshFormat format, const std::string& name,
                                const FileResolver& resolve) {
  GltfDocument doc;
  doc.name = name;
  if (data.empty()) doc.fail("empty file");
  GlbChunks glb;
  if (format == MeshFormat::Glb) {
    doc.container = GltfContainer::Glb;
    glb = split_glb(data, name);
    const size_t end = glb.json.find_last_not_of(std::string_view("\0 ", 2)) + 1;
    doc.text = std::string(glb.json.substr(0, end));
    doc.padding = std::string(glb.json.substr(end));
    doc.glb_tail = std::string(glb.tail);
    doc.glb_after = std::string(glb.after);
  } else {
    doc.container = GltfContainer::Gltf;
    doc.text = std::string(data);
  }
  doc.original = Json::parse(doc.text, nullptr, false);
  if (doc.original.is_discarded() || !doc.original.is_object()) {
    doc.fail("not a valid glTF file (its JSON does not parse to an object)");
  }
  const Json& asset = object_at(doc.original, "asset");
  const std::string version = asset.is_object() ? asset.value("version", "2.0") : "2.0";
  if (!version.starts_with("2.")) doc.fail("glTF version " + version + " (2.0 is read)");
  doc.json = doc.original;

  const Json& buffers = array_at(doc.json, "buffers");
  if (!buffers.is_array()) doc.fail("\"buffers\" is not an array");
  for (size_t b = 0; b < buffers.size(); ++b) {
    const std::string which = "buffer " + std::to_string(b);
    if (!buffers[b].is_object()) doc.fail(which + " is not an object");
    GltfBuffer buffer;
    const size_t length = index_of(buffers[b].value("byteLength", Json(-1)));
    if (length == SIZE_MAX) doc.fail(which + " has no byteLength");
    if (!buffers[b].contains("uri")) {
      if (format == MeshFormat::Glb && b == 0) {
        if (!glb.has_bin && length > 0) doc.fail(which + ": the .glb has no BIN chunk");
        buffer.source = GltfBufferSource::GlbChunk;
        buffer.bytes = std::string(glb.bin);
      } else if (object_at(buffers[b], "extensions").contains("EXT_meshopt_compression")) {
        buffer.source = GltfBufferSource::None;
      } else {
        doc.fail(which + " has no uri");
      }
    } else {
      buffer.uri = buffers[b].value("uri", "");
      if (is_data_uri(buffer.uri)) {
        buffer.source = GltfBufferSource::DataUri;
        std::optional<DataUri> decoded = decode_data_uri(buffer.uri);
        if (!decoded) doc.fail(which + "'s data URI is not base64 data");
        buffer.bytes = std::move(decoded->bytes);
      } else {
        buffer.source = GltfBufferSource::External;
        const std::string file = decode_uri(buffer.uri);
        std::optional<std::string> bytes = resolve ? resolve(file) : std::nullopt;
        if (!bytes) {
          doc.fail(which + "'s file '" + file +
                   "' was not found (a .gltf's buffers must be beside it; or open the .glb)");
        }
        buffer.bytes = std::move(*bytes);
      }
    }
    if (buffer.source != GltfBufferSource::None && buffer.bytes.size() < length) {
      doc.fail(which + " holds " + std::to_string(buffer.bytes.size()) + " bytes, fewer than its " +
               "byteLength " + std::to_string(length));
    }
    doc.buffers.push_back(std::move(buffer));
  }
  return doc;
}

AccessorValues read_accessor(const GltfDocument& doc, int accessor, const std::string& what,
                             bool raw) {
  const std::string which = what + " (accessor " + std::to_string(accessor) + ")";
  const Json& accessors = array_at(doc.json, "accessors");
  if (accessor < 0 || size_t(accessor) >= accessors.size() || !accessors[accessor].is_object()) {
    doc.fail(what + " names a missing accessor");
  }
  const Json& a = accessors[accessor];
  AccessorValues out;
  out.component_type = a.value("componentType", 0);
  out.components = type_components(a.value("type", ""));
  const size_t count = index_of(a.value("count", Json(-1)));
  const int size = component_size(out.component_type);
  if (size == 0 || out.components == 0) doc.fail(which + " has an unknown type");
  if (count > size_t(INT32_MAX) / 16) doc.fail(which + " has no valid count");
  out.count = int(count);
  out.values.assign(count * out.components, 0.0);
  const bool normalized = a.value("normalized", false) && !raw;
  const auto element_reader = [&](int type) {
    return [type, normalized](const char* p) -> double {
      const auto as = [p](auto v) {
        std::memcpy(&v, p, sizeof v);
        return v;
      };
      switch (type) {
        case 5126:
          return as(float{});
        case 5121:
          return normalized ? as(uint8_t{}) / 255.0 : as(uint8_t{});
        case 5123:
          return normalized ? as(uint16_t{}) / 65535.0 : as(uint16_t{});
        case 5125:
          return as(uint32_t{});
        case 5120:
          return normalized ? std::max(as(int8_t{}) / 127.0, -1.0) : as(int8_t{});
        case 5122:
          return normalized ? std::max(as(int16_t{}) / 32767.0, -1.0) : as(int16_t{});
      }
      return 0.0;
    };
  };
  const auto read = element_reader(out.component_type);
  const size_t element = size_t(size) * out.components;
  if (const auto decoded = doc.decoded_accessors.find(accessor);
      decoded != doc.decoded_accessors.end()) {
    // Draco's point count is the truth where the accessor's count disagrees (as loaders take it).
    out.count = int(decoded->second.size() / element);
    out.values.assign(size_t(out.count) * out.components, 0.0);
    for (int i = 0; i < out.count; ++i) {
      const char* p = decoded->second.data() + size_t(i) * element;
      for (int k = 0; k < out.components; ++k) {
        out.values[size_t(i) * out.components + k] = read(p + k * size);
      }
    }
    return out;
  }
  if (a.contains("bufferView")) {
    const int view = json_index(a["bufferView"]);
    const std::string_view bytes = doc.view_bytes(view, which);
    const size_t stride_json = index_of(doc.json["bufferViews"][view].value("byteStride", Json(0)));
    const size_t stride = stride_json == 0 ? element : stride_json;
    const size_t offset = index_of(a.value("byteOffset", Json(0)));
    if (stride < element || offset > bytes.size() ||
        (count > 0 && (bytes.size() - offset < element ||
                       (bytes.size() - offset - element) / stride < count - 1))) {
      doc.fail(which + " reaches beyond its buffer view");
    }
    for (size_t i = 0; i < count; ++i) {
      const char* p = bytes.data() + offset + i * stride;
      for (int k = 0; k < out.components; ++k)
        out.values[i * out.components + k] = read(p + k * size);
    }
  }
  if (a.contains("sparse")) {
    const Json& sparse = a["sparse"];
    const size_t n = index_of(sparse.value("count", Json(-1)));
    const Json& indices = object_at(sparse, "indices");
    const Json& values = object_at(sparse, "values");
    const int index_type = indices.value("componentType", 0);
    if (n > count || component_size(index_type) == 0 || index_type == 5126) {
      doc.fail(which + " has malformed sparse values");
    }
    const std::string_view index_bytes = doc.view_bytes(indices.value("bufferView", -1), which);
    const std::string_view value_bytes = doc.view_bytes(values.value("bufferView", -1), which);
    const size_t index_offset = index_of(indices.value("byteOffset", Json(0)));
    const size_t value_offset = index_of(values.value("byteOffset", Json(0)));
    const size_t index_size = size_t(component_size(index_type));
    if (index_offset > index_bytes.size() || (index_bytes.size() - index_offset) / index_size < n ||
        value_offset > value_bytes.size() || (value_bytes.size() - value_offset) / element < n) {
      doc.fail(which + "'s sparse values reach beyond their buffer views");
    }
    const auto read_index = element_reader(index_type);
    for (size_t j = 0; j < n; ++j) {
      const double i = read_index(index_bytes.data() + index_offset + j * index_size);
      if (!(i < double(count))) doc.fail(which + " has a sparse index beyond its count");
      const char* p = value_bytes.data() + value_offset + j * element;
      for (int k = 0; k < out.components; ++k) {
        out.values[size_t(i) * out.components + k] = read(p + k * size);
      }
    }
  }
  return out;
}

std::pair<Json, Json> accessor_bounds(const GltfDocument& doc, int accessor) {
  const AccessorValues v = read_accessor(doc, accessor, "accessor", true);
  Json lo = Json::array(), hi = Json::array();
  for (int k = 0; k < v.components; ++k) {
    double a = INFINITY, b = -INFINITY;
    for (int i = 0; i < v.count; ++i) {
      a = std::min(a, v(i, k));
      b = std::max(b, v(i, k));
    }
    const auto number = [&](double x) {
      return v.component_type == 5126 ? Json(double(float(x))) : Json(static_cast<long long>(x));
    };
    lo.push_back(number(a));
    hi.push_back(number(b));
  }
  return {lo, hi};
}

std::optional<FloatSlots> float_slots(const GltfDocument& doc, int accessor) {
  const Json& a = doc.json["accessors"][accessor];
  if (a.value("componentType", 0) != 5126 || a.contains("sparse") || !a.contains("bufferView") ||
      doc.decoded_accessors.count(accessor) ||
      doc.decoded_views.count(a["bufferView"].get<int>())) {
    return std::nullopt;
  }
  const Json& view = doc.json["bufferViews"][a["bufferView"].get<int>()];
  const int buffer = view.value("buffer", 0);
  if (doc.buffers[buffer].source == GltfBufferSource::None) return std::nullopt;
  const size_t element = 4 * size_t(type_components(a.value("type", "")));
  const size_t stride = view.value("byteStride", size_t(0));
  return FloatSlots{buffer, view.value("byteOffset", size_t(0)) + a.value("byteOffset", size_t(0)),
                    stride == 0 ? element : stride};
}

void write_floats(GltfDocument& doc, int accessor, const std::vector<float>& values,
                  int components) {
  const FloatSlots slots = *float_slots(doc, accessor);
  GltfBuffer& buffer = doc.buffers[slots.buffer];
  const size_t bytes = components * sizeof(float);
  for (size_t i = 0; i < values.size() / components; ++i) {
    char* at = buffer.bytes.data() + slots.offset + i * slots.stride;
    if (std::memcmp(at, values.data() + i * components, bytes) != 0) {
      std::memcpy(at, values.data() + i * components, bytes);
      buffer.changed = true;
    }
  }
}

int add_float_accessor(GltfDocument& doc, int like, const std::vector<float>& values,
                       int components, int target) {
  Json a = doc.json["accessors"][like];
  int buffer = -1;
  if (a.contains("bufferView")) {
    buffer = doc.json["bufferViews"][a["bufferView"].get<int>()].value("buffer", -1);
  }
  const std::string_view bytes(reinterpret_cast<const char*>(values.data()),
                               values.size() * sizeof(float));
  a["bufferView"] = doc.append_view(doc.data_buffer(buffer), bytes, target);
  a.erase("byteOffset");
  a.erase("sparse");
  a.erase("normalized");
  a["componentType"] = 5126;
  a["count"] = values.size() / components;
  set_float_bounds(a, values, components, false);
  doc.json["accessors"].push_back(std::move(a));
  return int(doc.json["accessors"].size()) - 1;
}

void set_float_bounds(Json& accessor, const std::vector<float>& values, int components,
                      bool always) {
  if (!always && !accessor.contains("min") && !accessor.contains("max")) return;
  Json lo = Json::array(), hi = Json::array();
  for (int k = 0; k < components; ++k) {
    float a = INFINITY, b = -INFINITY;
    for (size_t i = k; i < values.size(); i += components) {
      a = std::min(a, values[i]);
      b = std::max(b, values[i]);
    }
    lo.push_back(double(a));
    hi.push_back(double(b));
  }
  accessor["min"] = std::move(lo);
  accessor["max"] = std::move(hi);
}

EncodedDocument encode_gltf_document(const GltfDocument& doc) {
  Json json = doc.json;
  EncodedDocument out;
  for (size_t b = 0; b < doc.buffers.size(); ++b) {
    const GltfBuffer& buffer = doc.buffers[b];
    if (!buffer.changed) continue;
    if (buffer.source == GltfBufferSource::DataUri) {
      const std::string uri = json["buffers"][b].value("uri", "");
      const std::string mime = uri.substr(5, uri.find_first_of(";,") - 5);
      json["buffers"][b]["uri"] = encode_data_uri(mime, buffer.bytes);
    } else if (buffer.source == GltfBufferSource::External) {
      out.buffers.push_back({decode_uri(json["buffers"][b].value("uri", "")), buffer.bytes});
    }
  }
  std::string text = doc.text;
  std::string padding = doc.padding;
  if (json != doc.original) {
    try {
      text = patch_json_text(doc.text, doc.original, json);
    } catch (const std::logic_error&) {  // a text that parses otherwise (repeated keys)
      text = json.dump(doc.text.find('\n') == std::string::npos ? -1 : 2);
    }
    padding.clear();
  }
  if (doc.container == GltfContainer::Gltf) {
    out.main = std::move(text);
    return out;
  }
  text += padding;
  text.resize((text.size() + 3) / 4 * 4, ' ');
  const bool has_bin = !doc.buffers.empty() && doc.buffers[0].source == GltfBufferSource::GlbChunk;
  std::string bin = has_bin ? doc.buffers[0].bytes : std::string();
  bin.resize((bin.size() + 3) / 4 * 4, '\0');
  const size_t total = 12 + 8 + text.size() + (has_bin ? 8 + bin.size() : 0) + doc.glb_tail.size();
  std::string& main = out.main;
  main.reserve(total + doc.glb_after.size());
  main.append("glTF", 4);
  append_u32(main, 2);
  append_u32(main, static_cast<uint32_t>(total));
  append_u32(main, static_cast<uint32_t>(text.size()));
  append_u32(main, kJsonChunk);
  main += text;
  if (has_bin) {
    append_u32(main, static_cast<uint32_t>(bin.size()));
    append_u32(main, kBinChunk);
    main += bin;
  }
  main += doc.glb_tail;
  main += doc.glb_after;
  return out;
}

}  // namespace specdeform::detail
