// Internal: STL, ASCII and binary (docs/files.md, "Per format"): read into a polygon soup with
// coincident corners welded (stl_reader.cpp), rewritten with new corners and facet normals
// (stl_rewriter.cpp), written afresh as binary (stl_writer.cpp).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "specdeform/mesh/mesh_file.h"

namespace specdeform::detail {

struct PolygonSoup;
struct KeptRecord;

// ASCII: each facet's "normal" numbers and its three "vertex" lines' numbers, in file order.
// Binary: none needed (50-byte records after the 84-byte header).
struct StlLayout {
  bool ascii = false;
  std::vector<size_t> facet_normal;
  std::vector<size_t> corner;  // 3 per facet
};

// The first bytes of an STL file of `size` bytes: a binary one's triangles there are checked for
// NaN and infinite coordinates before the rest is read (a garbage file is refused at once).
void check_stl_start(std::string_view start, uint64_t size, const std::string& name);

PolygonSoup parse_stl(std::string_view data, const std::string& name, KeptRecord* keep);

std::string rewrite_stl(const MeshFile& file, const Vertices& positions,
                        const Eigen::MatrixX3d& normals);

// Binary: triangles, facet normals of the new shape.
std::string stl_bytes(const FileAttributes& a, const Vertices& X);

}  // namespace specdeform::detail
