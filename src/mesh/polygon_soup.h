// Internal: what every format reader produces before validation and clean-up.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "file_layout.h"
#include "specdeform/mesh/io.h"

namespace specdeform::detail {

struct PolygonSoup {
  std::vector<double> xyz;      // 3 per file vertex
  std::vector<int> indices;     // polygon corners, concatenated
  std::vector<int> offsets{0};  // polygon p has corners indices[offsets[p] .. offsets[p+1])
  std::vector<int> weld;        // glTF: file vertex v is welded into weld[v] (empty: none)
  int welded_corners = 0;

  void add_polygon_corner(int v) { indices.push_back(v); }
  void end_polygon() { offsets.push_back(static_cast<int>(indices.size())); }
  int num_vertices() const { return static_cast<int>(xyz.size() / 3); }
  int num_polygons() const { return static_cast<int>(offsets.size()) - 1; }
};

// What a reader keeps to write the file back (ReadOptions::keep_file): the layout and the
// attributes but the polygons, which build_mesh takes from the soup.
struct KeptRecord {
  FileAttributes attributes;
  FileLayout layout;
};

// Hashes a position's bits (callers add +0.0 first, so that -0.0 and +0.0 weld).
struct PositionHash {
  size_t operator()(const std::array<double, 3>& p) const {
    size_t h = 0;
    for (const double v : p) {
      uint64_t bits;
      std::memcpy(&bits, &v, sizeof bits);
      h ^= std::hash<uint64_t>{}(bits) + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
    }
    return h;
  }
};

// Each vertex of `xyz` (3 per vertex) welded into the first at exactly the same position (-0.0
// as +0.0): PolygonSoup::weld for files that split vertices where their attributes differ.
std::vector<int> weld_coincident(const std::vector<double>& xyz);

// Validates the soup (indices, finiteness, emptiness), triangulates it and drops what no face
// uses; throws InputError naming `name`.
LoadedMesh build_mesh(PolygonSoup soup, const std::string& name);

}  // namespace specdeform::detail
