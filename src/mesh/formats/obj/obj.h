// Internal: OBJ, with the MTL files it names (docs/files.md, "OBJ"): read into a polygon soup
// (obj_reader.cpp), its materials completed from its MTL files (mtl.cpp), rewritten with new
// positions and normals (obj_rewriter.cpp), and written afresh from any file (obj_writer.cpp).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "specdeform/mesh/mesh_file.h"

namespace specdeform::detail {

struct PolygonSoup;
struct KeptRecord;
struct Encoded;
struct Target;

// The first number of each `v` and `vn` line (just after the keyword); the vn lines in order.
struct ObjLayout {
  std::vector<size_t> v, vn;
  std::vector<std::string> mtllib;    // the MTL files named, in order
  int groups = 0;                     // g and o lines
  std::vector<std::string> textures;  // every image the MTL files name (relative to the OBJ)
};

PolygonSoup parse_obj(std::string_view data, const std::string& name, KeptRecord* keep);

// A kept OBJ's materials completed from the MTL files it names (Kd, map_Kd), read through
// `companions`, and the images they name (every map_*, bump, disp, decal, refl, norm) in its
// layout; materials it cannot read stay plain.
void read_obj_materials(KeptRecord& record, const FileResolver& companions);

// An MTL texture statement, from the words after its keyword: the file it names (the rest of
// the line after the options -s 1 1 1, -o, -bm 0.5, -clamp on, ...; spaces kept, backslashes
// as slashes) and how it is laid (-clamp, -o and -s; the other options are skipped).
struct MtlTexture {
  std::string name;
  TextureSampling sampling;
};
MtlTexture mtl_texture(std::string_view rest);

// `positions`: one row per file vertex; `normals`: the updated rows of the file's normals
// (FileAttributes::normals; file_normals.h), empty when it has none.
std::string rewrite_obj(const MeshFile& file, const Vertices& positions,
                        const Eigen::MatrixX3d& normals);

// Polygons, texture coordinates, normals, vertex colours (after v) and materials (an MTL beside
// it, `<stem>.mtl`, with Kd and map_Kd; a glTF's embedded images written beside it).
Encoded encode_obj(const FileAttributes& a, const Vertices& X, const Eigen::MatrixX3d& normals,
                   const Target& target, const MeshFile* file);

}  // namespace specdeform::detail
