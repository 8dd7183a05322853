// Internal: where a kept file's positions and normals sit in its bytes, per format, as its reader
// found them; the same-format writers (file_rewriters.cpp, gltf_writer.cpp) put new values there.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Geometry>

#include "specdeform/mesh/mesh_file.h"

namespace specdeform::detail {

// The first number of each `v` and `vn` line (just after the keyword); the vn lines in order.
struct ObjLayout {
  std::vector<size_t> v, vn;
  std::vector<std::string> mtllib;  // the MTL files named, in order
  int groups = 0;                   // g and o lines
};

// The first number of each vertex line; NOFF: the normal follows the position (tokens 3-5).
struct OffLayout {
  std::vector<size_t> vertex;
  bool normals = false;
};

enum class PlyScalar { I8, U8, I16, U16, I32, U32, F32, F64 };
size_t ply_scalar_size(PlyScalar s);
const char* ply_scalar_name(PlyScalar s);
// The binary value of type `s` at `bytes`, stored big- or little-endian, as a double.
double ply_binary_value(const char* bytes, PlyScalar s, bool big_endian);

struct PlyProperty {
  std::string name;
  PlyScalar type = PlyScalar::F32;
  bool is_list = false;
  PlyScalar count_type = PlyScalar::U8;
};

struct PlyElement {
  std::string name;
  long long count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyEncoding { Ascii, Little, Big };

// Each vertex entry's start (a line in ASCII); the property positions of x y z and nx ny nz
// (-1: absent) in the vertex element.
struct PlyLayout {
  PlyEncoding encoding = PlyEncoding::Ascii;
  std::vector<PlyElement> elements;
  int vertex_element = 0;
  int xyz[3] = {-1, -1, -1};
  int normal[3] = {-1, -1, -1};
  std::vector<size_t> vertex;
};

// ASCII: each facet's "normal" numbers and its three "vertex" lines' numbers, in file order.
// Binary: none needed (50-byte records after the 84-byte header).
struct StlLayout {
  bool ascii = false;
  std::vector<size_t> facet_normal;
  std::vector<size_t> corner;  // 3 per facet
};

// A float accessor's elements in a buffer.
struct GltfSlots {
  int accessor = -1;
  int buffer = 0;
  size_t offset = 0;  // of element 0 in the buffer
  size_t stride = 0;  // bytes from one element to the next
  int count = 0;
};

// A triangle primitive's attributes as the writer rewrites them: file vertices first_vertex ..
// first_vertex + position.count - 1 are its POSITION elements, and the same rows of the
// FileAttributes' normals and GltfLayout::tangents its NORMAL and TANGENT elements.
struct GltfPrimitive {
  GltfSlots position, normal, tangent;  // accessor -1: absent
  int first_vertex = 0;
  Eigen::Matrix4d world = Eigen::Matrix4d::Identity();  // mesh space -> world space
};

enum class GltfContainer { Glb, Gltf };
enum class GltfBufferSource { GlbChunk, DataUri, External };

struct GltfBuffer {
  GltfBufferSource source = GltfBufferSource::GlbChunk;
  std::string uri;    // External and DataUri: as written in the JSON
  std::string bytes;  // the buffer's contents, decoded
};

struct GltfLayout {
  GltfContainer container = GltfContainer::Glb;
  std::string json;  // the JSON as written (a .glb's JSON chunk, unpadded)
  std::vector<GltfBuffer> buffers;
  std::string glb_tail;   // a .glb's chunks after BIN, as they were
  std::string glb_after;  // bytes after the length its header gives, as they were
  std::vector<GltfPrimitive> primitives;
  Eigen::MatrixX4d tangents;  // per file vertex, world space xyz and w (with NORMAL)
  int meshes = 0, skins = 0, animations = 0, morph_targets = 0, images = 0, uv_sets = 0;
};

struct FileLayout {
  std::string bytes;  // the file as read (glTF: see GltfLayout)
  std::variant<ObjLayout, OffLayout, PlyLayout, StlLayout, GltfLayout> format;
};

}  // namespace specdeform::detail
