// Internal: a glTF 2.0 document as its file holds it: the JSON as text and parsed, each buffer's
// bytes and where they live (a .glb's BIN chunk, a data URI, a file beside the .gltf), and the
// container. Readers and writers work on it; what they change is the parsed JSON (`json`, against
// `original`) and the buffers' bytes, and encode_gltf_document() writes it back with the text of
// every unchanged JSON value and the bytes of every unchanged buffer as they were.
//
// Accessors are read whatever their storage (any component type, normalized or not, interleaved,
// sparse, all zeros without a buffer view, or compressed: the decoding passes of gltf_decode.h
// keep their decoded bytes beside the JSON, which they leave as it is); `float_slots` says where
// a plain float accessor's elements sit, for writing them in place.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "json_text.h"
#include "specdeform/mesh/mesh_file.h"

namespace specdeform::detail {

enum class GltfContainer { Glb, Gltf };
enum class GltfBufferSource {
  GlbChunk,  // a .glb's BIN chunk (buffer 0 without a uri)
  DataUri,   // base64 in the JSON
  External,  // a file the uri names (relative to the .gltf); a new buffer has no uri yet
  None,      // no bytes: an EXT_meshopt_compression fallback buffer
};

struct GltfBuffer {
  GltfBufferSource source = GltfBufferSource::GlbChunk;
  std::string uri;    // as the JSON writes it (percent-encoded)
  std::string bytes;  // decoded
  bool changed = false;
};

struct GltfDocument {
  std::string name;  // for messages
  GltfContainer container = GltfContainer::Glb;
  std::string text;     // the JSON as written (a .glb's chunk without its trailing padding)
  std::string padding;  // that padding (spaces or NULs)
  Json original;        // `text` parsed
  Json json;            // as read and edited (the decoding passes, the writer)
  std::vector<GltfBuffer> buffers;
  std::string glb_tail;   // a .glb's chunks after BIN, as they were
  std::string glb_after;  // bytes after the length its header gives, as they were
  // Decoded data of compressed buffer views (EXT_meshopt_compression) and accessors
  // (KHR_draco_mesh_compression): read in place of what the JSON says, never written.
  std::map<int, std::string> decoded_views, decoded_accessors;

  [[noreturn]] void fail(const std::string& what) const;

  // Buffer view `view`'s bytes; throws naming `what` where it reaches beyond its buffer.
  std::string_view view_bytes(int view, const std::string& what) const;
  // A buffer new data can go in: `preferred` where it has bytes of its own, else a .glb's BIN
  // chunk, else the first buffer with bytes; a new buffer (the BIN chunk, or a file named when
  // written) where there is none.
  int data_buffer(int preferred = -1);
  // `bytes` appended to buffer `buffer` at a multiple of 4; their offset.
  size_t append(int buffer, std::string_view bytes);
  // `bytes` appended to buffer `buffer` as a new buffer view with `target` (34962 vertices,
  // 34963 indices; 0 none); its index.
  int append_view(int buffer, std::string_view bytes, int target);
  // Whether extensionsUsed names `extension`; it removed from extensionsUsed and
  // extensionsRequired (each dropped where it becomes empty).
  bool uses(const std::string& extension) const;
  void drop_extension(const std::string& extension);
};

// A JSON index (a whole number >= 0 below 2^31) as an int; -1 for anything else.
int json_index(const Json& v);

// `object[key]` where it is an array (an object), else an empty one: the JSON's optional lists
// and objects, read without copying them.
const Json& array_at(const Json& object, const char* key);
const Json& object_at(const Json& object, const char* key);

// Parses a .glb or .gltf, reading the buffers a .gltf names through `resolve`.
GltfDocument load_gltf_document(std::string_view data, MeshFormat format, const std::string& name,
                                const FileResolver& resolve);

// A uri with its %XX escapes decoded: the name of the file it names; and a name as a uri (every
// byte but letters, digits and -._~/ escaped).
std::string decode_uri(std::string_view uri);
std::string encode_uri(std::string_view name);

// `resolve` reading a name also where the file is saved under the name's uri ("a%20b.png" for
// "a b.png", as some downloads save them).
FileResolver uri_resolver(FileResolver resolve);

// An accessor's elements as doubles (normalized integers mapped to [0, 1] or [-1, 1] unless
// `raw`; sparse values applied), `components` per element.
struct AccessorValues {
  int count = 0, components = 0;
  int component_type = 0;  // 5120 .. 5126
  std::vector<double> values;

  double operator()(int i, int k) const { return values[size_t(i) * components + k]; }
};
AccessorValues read_accessor(const GltfDocument& doc, int accessor, const std::string& what,
                             bool raw = false);

// The exact "min" and "max" of accessor `accessor`'s values, in its component type (as the
// validator checks them).
std::pair<Json, Json> accessor_bounds(const GltfDocument& doc, int accessor);

// Where a float accessor without sparse values keeps its elements: nullopt for any other, and for
// one whose data was compressed.
struct FloatSlots {
  int buffer = 0;
  size_t offset = 0, stride = 0;  // element 0's offset in the buffer; bytes between elements
};
std::optional<FloatSlots> float_slots(const GltfDocument& doc, int accessor);

// Writing float elements (`components` per element), for the rewriter and the rig:
//  - write_floats: over float accessor `accessor`'s own elements (float_slots gives them); its
//    buffer marked changed where a byte changed;
//  - add_float_accessor: a new accessor like `like` (its type, name, bounds' presence) holding
//    them in a new buffer view (`target`: 34962 vertices, 0 none) of the buffer `like`'s data is
//    in, dense, not normalized; its index;
//  - set_float_bounds: the accessor's min and max made those of `values` (where it has them, or
//    `always`).
void write_floats(GltfDocument& doc, int accessor, const std::vector<float>& values,
                  int components);
int add_float_accessor(GltfDocument& doc, int like, const std::vector<float>& values,
                       int components, int target);
void set_float_bounds(Json& accessor, const std::vector<float>& values, int components,
                      bool always);

// Components of a glTF accessor type ("VEC3" -> 3); 0 for an unknown one.
int type_components(const std::string& type);
// Bytes of a component type (5126 -> 4); 0 for an unknown one.
int component_size(int component_type);

// The files of the document: the .glb or .gltf (`name`), then each buffer that changed, written
// beside it as `buffer_names` gives them. A .glb's BIN chunk and data URIs stay inside.
struct EncodedDocument {
  std::string main;
  std::vector<OutputFile> buffers;
};
EncodedDocument encode_gltf_document(const GltfDocument& doc);

}  // namespace specdeform::detail
