// A mesh file kept whole, and written again with new positions.
//
// read_mesh(path, {.keep_file = true}) keeps, beside the triangle mesh the algorithms use, what the
// file holds: its bytes, where each position and normal sits in them, and the surface as the file
// describes it (FileAttributes: polygons, texture coordinates, normals, colours, materials).
// encode_mesh_file() writes new positions back:
//  - into the input's format, the same file with only positions, normals (and glTF tangents and
//    POSITION min/max) changed; every other line, property, byte and chunk as it was, in order. A
//    number whose value did not change keeps its text; a new one is written as the shortest text
//    that reads back to it: to double where any of the file's positions has more than 9
//    significant digits (written in double precision), to float32 otherwise (written from single
//    precision, as most are); binary values in the file's own type and byte order.
//  - into another format, what that format can hold (polygons, texture coordinates, normals,
//    colours, material names), naming each thing it drops in EncodedMesh::notes.
// A normal none of whose faces moved is written as it was. glTF tangents follow their faces'
// deformation gradient J (t <- J t, made orthogonal to the new normal; w kept).
//
// Positions are one row per file vertex (MeshReadInfo::file_vertices' numbering, to_file_order),
// in world space for glTF (written back in each mesh's own space, through the inverse of its
// node's world matrix).
#pragma once

#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform {

enum class MeshFormat { Obj, Off, Ply, Stl, Gltf, Glb };

// Format from a file name's extension, case-insensitive. Throws InputError for anything else.
MeshFormat mesh_format_from_path(const std::filesystem::path& path);

// "OBJ", "glTF binary (.glb)", ...
std::string format_name(MeshFormat format);

// Reads a file that a mesh file names (an OBJ's MTL and its textures, a glTF's buffers and
// images) by that name, relative to the mesh file's folder; nullopt when there is no such file.
// Throws InputError for a name it refuses.
using FileResolver = std::function<std::optional<std::string>(const std::string& name)>;

// The files in `folder`. Confined: a name that leaves the folder (absolute, or with a ".." part)
// is refused, as the editor's server must; otherwise any relative name is read.
enum class Confinement { Confined, Relative };
FileResolver folder_resolver(const std::filesystem::path& folder,
                             Confinement confinement = Confinement::Relative);

// How a base colour image is laid over the texture coordinates (u, v as the file has them).
struct TextureSampling {
  enum class Wrap {
    Repeat,
    Clamp,
    Mirror
  };  // outside [0, 1]: glTF's REPEAT, CLAMP_TO_EDGE,
      // MIRRORED_REPEAT; MTL's -clamp off / on
  Wrap wrap_u = Wrap::Repeat;
  Wrap wrap_v = Wrap::Repeat;
  bool nearest = false;  // magnified by the nearest texel (glTF magFilter NEAREST), not blended
  // The image is read at (u', v') = transform * (u, v, 1): glTF's KHR_texture_transform
  // (offset * rotation * scale), MTL's -o and -s. Identity by default.
  Eigen::Matrix<float, 2, 3> transform = Eigen::Matrix<float, 2, 3>::Identity();
};

// A material as far as files of different formats share it.
struct Material {
  std::string name;
  Eigen::Vector4f base_color{1, 1, 1, 1};  // linear RGBA (MTL Kd; glTF baseColorFactor)
  std::string texture;                     // base colour image: a name for the FileResolver
                                           // (MTL map_Kd, a glTF image's uri), or empty
  int gltf_image = -1;                     // glTF: the image's index (in a buffer view or not)
  TextureSampling sampling;                // of the base colour image
  bool unlit = false;                      // drawn without shading (glTF KHR_materials_unlit)
};

// The surface as the file describes it, in the file's vertex numbering.
struct FileAttributes {
  // Polygons as written (glTF: its triangle primitives' triangles; STL: its facets), over file
  // vertices: polygon p has the corners corners[offsets[p] .. offsets[p + 1]).
  std::vector<int> corners;
  std::vector<int> offsets{0};
  // Texture coordinates (u, v as the file has them): corner c uses uv row corner_uv[c], -1 none.
  // Both empty when the file has none.
  Eigen::MatrixX2d uv;
  std::vector<int> corner_uv;
  // Normals: corner c uses normals row corner_normal[c] (-1: none). A row shared by the corners
  // around a vertex is smooth there; rows of their own make a hard edge (OBJ vn indices, glTF's
  // split vertices, STL's facets; PLY and OFF: one per vertex). Empty when the file has none.
  Eigen::MatrixX3d normals;
  std::vector<int> corner_normal;
  // Vertex colours, RGBA in [0, 1], one row per file vertex; empty when the file has none.
  Eigen::MatrixX4f colours;
  // Polygon p uses materials[polygon_material[p]] (-1: none); empty when the file names none.
  std::vector<Material> materials;
  std::vector<int> polygon_material;

  int num_polygons() const { return static_cast<int>(offsets.size()) - 1; }
};

// What a file holds besides positions (`specdeform info`).
struct FileSummary {
  std::string format;                // "PLY (binary little endian)", ...
  std::map<int, int> polygon_sizes;  // corners -> polygons
  int texture_coordinates = 0;       // distinct uv rows
  int uv_sets = 0;                   // glTF TEXCOORD_n sets; 1 for other formats with uvs
  int normals = 0;                   // distinct normal rows
  bool vertex_colours = false;
  std::vector<std::string> materials;
  int groups = 0;  // OBJ g/o lines
  // glTF: nodes; meshes drawn and their drawings (a mesh drawn by k nodes counts k); triangle
  // primitives as drawn; skins, animations, morph targets, images; extensionsUsed.
  int nodes = 0, meshes = 0, drawings = 0, primitives = 0, skins = 0, animations = 0,
      morph_targets = 0, images = 0;
  std::vector<std::string> extensions;
  std::vector<std::string> properties;  // PLY: "element.property (type)" beyond x y z
  std::string round_trip;               // what writing the same format keeps
  std::vector<std::string> changes;     // what writing it changes beyond that (decompression)
};

struct MeshReadInfo;

namespace detail {
struct FileLayout;  // where positions and normals sit in the bytes (src/mesh/file_layout.h)
}

class MeshFile {
 public:
  MeshFormat format;
  std::string name;  // for messages
  Vertices rest;     // the file's positions (file numbering; world space)
  FileAttributes attributes;
  FileResolver companions;  // the files it names (MTL, textures, glTF buffers)
  std::shared_ptr<const detail::FileLayout> layout;

  FileSummary summary() const;
  // The bytes of material m's base colour image and its MIME type; nullopt when it has none or
  // the image cannot be read.
  std::optional<std::pair<std::string, std::string>> texture(int material) const;
};

// How file normals follow a deformation (measured in docs/results.md, "Normals").
enum class NormalUpdate {
  Follow,     // each file normal carried by the deformation gradient of the faces that use it
              // (n <- cof(J) n summed angle-weighted, J the map of a face's rest triangle to its
              // deformed one): hard edges stay hard, custom normals keep their offset from the
              // surface, exact where nothing moved
  Recompute,  // the angle-weighted mean of the deformed normals of the faces that use it
  Rotate,     // turned by its vertex's local rotation (the rotation nearest to the map of its
              // one-ring's rest edges to their deformed ones)
};

// "follow", "recompute", "rotate"; from_name throws InputError for anything else.
std::string_view name(NormalUpdate mode);
NormalUpdate normal_update_from_name(std::string_view name);

// How a glTF's morph targets follow a deformation of the rest shape.
enum class MorphTargets {
  Turn,  // each POSITION, NORMAL and TANGENT delta turned by its vertex's local rotation (the
         // rotation nearest to the map of its welded one-ring's rest edges to their deformed
         // ones), so a target does to the bent rest what it did to the unbent one, relative to
         // the surface; deltas of vertices whose one-ring did not move keep their bytes
  Keep,  // every delta as the file has it
};

// How a glTF's skins follow a deformation of the rest shape.
enum class Joints {
  Follow,  // each joint moved by the rigid motion that best maps the vertices it drives, weighted
           // by their skin weights, to their new places; inverse bind matrices, rest transforms
           // and the animation keys of moved joints updated together, so the bind pose is the
           // deformed rest and each animation turns every part about its joint's new place
  Keep,    // joints, inverse bind matrices and animations as the file has them
};

// "turn", "keep"; "follow", "keep". from_name throws InputError for anything else.
std::string_view name(MorphTargets mode);
std::string_view name(Joints mode);
MorphTargets morph_targets_from_name(std::string_view name);
Joints joints_from_name(std::string_view name);

struct WriteOptions {
  NormalUpdate normals = NormalUpdate::Follow;
  MorphTargets morph_targets = MorphTargets::Turn;  // glTF only
  Joints joints = Joints::Follow;                   // glTF only
};

struct OutputFile {
  std::string name;  // the main file's name as asked; companions relative to its folder
  std::string bytes;
};

struct EncodedMesh {
  std::vector<OutputFile> files;  // the mesh file first, then the companions it wrote (a glTF's
                                  // changed buffers, an MTL and images made for another format)
  std::vector<std::string> companions;  // the files it names that stay as the input has them
                                        // (names relative to both: MeshFile::companions reads
                                        // them), to be beside it
  std::vector<std::string> notes;       // what was dropped or changed beyond positions and normals
};

// The file with new `positions` (one row per file vertex), in the format of `out_name`'s
// extension. A position within 1e-10 of the bounding box's diagonal from its rest is written as
// the rest (a solve's rounding, not a move: a zero deformation gives the input's bytes). Throws
// InputError if the positions do not match the file or cannot be written in its layout.
EncodedMesh encode_mesh_file(const MeshFile& file, const Vertices& positions,
                             const std::filesystem::path& out_name,
                             const WriteOptions& options = {});

// encode_mesh_file() written atomically to `path`; the companions that did not change (an MTL
// and its textures, a glTF's images and other buffers) are copied beside it when `path` is in
// another folder and no file of that name is there yet. Returns the notes.
std::vector<std::string> write_mesh_file(const std::filesystem::path& path, const MeshFile& file,
                                         const Vertices& positions,
                                         const WriteOptions& options = {});

// For each corner of the mesh's triangles F (3 per triangle, in order), the corner of the file
// polygon it comes from (an index into FileAttributes::corners): where a viewer finds the
// triangle's texture coordinates and normals. `info` and `F` as read with `file`.
std::vector<int> triangle_corners(const MeshFile& file, const MeshReadInfo& info, const Faces& F);

// What the file holds beyond positions and triangles ("texture coordinates", "normals",
// "3 skins", ...): what a mesh written from triangles alone (subdivide) leaves behind.
std::vector<std::string> contents_beyond_triangles(const MeshFile& file);

// The names, relative to the file's folder, of the companions it names (MTL files and every
// texture they name, glTF buffers and images, a PLY's TextureFile), each once.
std::vector<std::string> companion_names(const MeshFile& file);

}  // namespace specdeform
