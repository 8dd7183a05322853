// Internal: what every format reader produces before validation and clean-up.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "specdeform/mesh/io.h"

namespace specdeform::detail {

struct PolygonSoup {
  std::vector<double> xyz;      // 3 per file vertex
  std::vector<int> indices;     // polygon corners, concatenated
  std::vector<int> offsets{0};  // polygon p has corners indices[offsets[p] .. offsets[p+1])
  int welded_corners = 0;

  void add_polygon_corner(int v) { indices.push_back(v); }
  void end_polygon() { offsets.push_back(static_cast<int>(indices.size())); }
  int num_vertices() const { return static_cast<int>(xyz.size() / 3); }
  int num_polygons() const { return static_cast<int>(offsets.size()) - 1; }
};

// Each reader throws InputError("<name>: <problem>") for malformed data.
PolygonSoup parse_obj(std::string_view data, const std::string& name);
PolygonSoup parse_off(std::string_view data, const std::string& name);
PolygonSoup parse_ply(std::string_view data, const std::string& name);
PolygonSoup parse_stl(std::string_view data, const std::string& name);

// Validates the soup (indices, finiteness, emptiness), triangulates it and drops what no face
// uses; throws InputError naming `name`.
LoadedMesh build_mesh(PolygonSoup soup, const std::string& name);

}  // namespace specdeform::detail
