// Internal: glTF 2.0 (.gltf with its buffers in files or data URIs, .glb) read, rewritten and
// written (docs/files.md, "glTF").
//
// parse_gltf: the triangle primitives (modes 4, 5, 6) of every drawing of the default scene
// (gltf_scene.h), in world space: a mesh drawn by k nodes is k pieces; an accessor shared by
// several primitives or meshes is read once per drawing. File vertices: drawing by drawing
// (meshes in the `meshes` order, each mesh's drawings in node order), primitive by primitive,
// POSITION element by element. Vertices at exactly the same world position are welded for the
// solve (glTF splits them along UV seams and hard edges); a mirroring node's triangles are turned
// to face outwards in world space. Draco and meshopt data are decoded and EXT_mesh_gpu_instancing
// drawn instance by instance (gltf_decode.h); positions of any component type
// (KHR_mesh_quantization) and sparse accessors are read.
//
// rewrite_gltf: the document with new positions (one row per file vertex, world space), normals
// and tangents, morph targets and skins as `options` say (gltf_rig.h), in the container of
// `out_name` (.glb or .gltf), its changed buffers named after it but never as one of `taken`: see
// gltf_rewriter.cpp.
//
// gltf_bytes: a mesh of another format as a new glTF (mesh_writers.h).
#pragma once

#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "gltf_document.h"

namespace specdeform::detail {

struct PolygonSoup;
struct KeptRecord;

// A triangle primitive as one node draws it: file vertices first_vertex .. first_vertex + count
// - 1 are its POSITION elements, and the same rows of FileAttributes::normals and
// GltfLayout::tangents its NORMAL and TANGENT elements.
struct GltfUnit {
  int mesh = -1, primitive = -1, node = -1, instance = -1;
  int first_vertex = 0, count = 0;
  Eigen::Matrix4d world = Eigen::Matrix4d::Identity();  // mesh space -> world space
  int position = -1, normal = -1, tangent = -1;         // accessors (-1: absent)
};

struct GltfLayout {
  GltfDocument doc;  // as read, compressed data decoded
  std::vector<GltfUnit> units;
  Eigen::MatrixX4d tangents;  // per file vertex, world space xyz and w (with NORMAL)
};

PolygonSoup parse_gltf(std::string_view data, MeshFormat format, const std::string& name,
                       const FileResolver& companions, KeptRecord* keep);

EncodedMesh rewrite_gltf(const MeshFile& file, const Vertices& positions,
                         const Eigen::MatrixX3d& normals, const std::filesystem::path& out_name,
                         const std::set<std::string>& taken, const WriteOptions& options);

// One mesh of one primitive per material: TEXCOORD_0 (v turned), NORMAL, COLOR_0, materials
// with their base colour and image (embedded).
std::string gltf_bytes(const FileAttributes& a, const Vertices& X, const Eigen::MatrixX3d& normals,
                       bool binary, const MeshFile* file);

// What the file holds (MeshFile::summary's glTF part): the document's nodes, meshes, primitives,
// skins, animations, images, materials and extensions; with a layout, the meshes, drawings and
// triangle primitives of the default scene.
void summarize_gltf_document(const GltfDocument& doc, FileSummary& s);
void summarize_gltf(const GltfLayout& layout, FileSummary& s);
// The document's summary of a file that parses but draws nothing deform can take (inspect).
FileSummary gltf_document_summary(std::string_view data, MeshFormat format, const std::string& name,
                                  const FileResolver& companions);

// Image `image`'s bytes and MIME type, wherever it lives (a buffer view, a data URI); nullopt
// for one in a file (read it through the companions) or out of range.
std::optional<std::pair<std::string, std::string>> gltf_image(const GltfDocument& doc, int image);

// The files the glTF names beside it: its external buffers and images (decoded uris).
std::vector<std::string> gltf_companions(const GltfDocument& doc);

}  // namespace specdeform::detail
