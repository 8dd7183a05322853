// Internal: OFF (docs/files.md, "Per format"): read into a polygon soup (off_reader.cpp),
// rewritten with new positions and NOFF normals (off_rewriter.cpp), written afresh
// (off_writer.cpp).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "specdeform/mesh/mesh_file.h"

namespace specdeform::detail {

struct PolygonSoup;
struct KeptRecord;

// The first number of each vertex line; NOFF: the normal follows the position (tokens 3-5).
struct OffLayout {
  std::vector<size_t> vertex;
  bool normals = false;
};

PolygonSoup parse_off(std::string_view data, const std::string& name, KeptRecord* keep);

std::string rewrite_off(const MeshFile& file, const Vertices& positions,
                        const Eigen::MatrixX3d& normals);

// Polygons, colours (COFF), normals where each vertex has one (`vertex_normal`: its row, NOFF),
// in parts to be concatenated.
std::vector<std::string> off_parts(const FileAttributes& a, const Vertices& X,
                                   const Eigen::MatrixX3d& normals,
                                   const std::vector<int>& vertex_normal);

}  // namespace specdeform::detail
