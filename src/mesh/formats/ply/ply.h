// Internal: PLY (docs/files.md, "Per format"): read into a polygon soup (ply_reader.cpp),
// rewritten with new positions and normals in their own types (ply_rewriter.cpp), written afresh
// (ply_writer.cpp).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "mesh/formats/binary_value.h"
#include "specdeform/mesh/mesh_file.h"

namespace specdeform::detail {

struct PolygonSoup;
struct KeptRecord;

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
  std::vector<std::string> textures;  // the images its `comment TextureFile` lines name
};

PolygonSoup parse_ply(std::string_view data, const std::string& name, KeptRecord* keep);

std::string rewrite_ply(const MeshFile& file, const Vertices& positions,
                        const Eigen::MatrixX3d& normals);

// Binary little endian with double positions: polygons, normals where each vertex has one
// (`vertex_normal`), colours (uchar), texture coordinates as each face's texcoord list.
std::string ply_bytes(const FileAttributes& a, const Vertices& X, const Eigen::MatrixX3d& normals,
                      const std::vector<int>& vertex_normal);

}  // namespace specdeform::detail
