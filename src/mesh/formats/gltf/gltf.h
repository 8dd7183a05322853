// Internal: glTF 2.0 (.gltf, .glb; docs/files.md, "glTF"): read into a polygon soup
// (gltf_reader.cpp), rewritten with new positions, normals and tangents (gltf_rewriter.cpp),
// written afresh (gltf_writer.cpp).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "specdeform/mesh/mesh_file.h"

namespace specdeform::detail {

struct PolygonSoup;
struct KeptRecord;

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

PolygonSoup parse_gltf(std::string_view data, MeshFormat format, const std::string& name,
                       const FileResolver& companions, KeptRecord* keep);

// The .glb or .gltf, then the external buffers whose bytes changed, named as `out_name`'s
// companions (the buffer's own uri where `out_name` is in another folder than the input, else
// "<out stem>.bin", "<out stem>-1.bin", ...).
EncodedMesh rewrite_gltf(const MeshFile& file, const Vertices& positions,
                         const Eigen::MatrixX3d& normals, const std::filesystem::path& out_name,
                         bool same_folder);

// One mesh of one primitive per material: TEXCOORD_0 (v turned), NORMAL, COLOR_0, materials
// with their base colour and image (embedded).
std::string gltf_bytes(const FileAttributes& a, const Vertices& X, const Eigen::MatrixX3d& normals,
                       bool binary, const MeshFile* file);

}  // namespace specdeform::detail
