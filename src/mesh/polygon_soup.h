// Internal: what every format reader produces before validation and clean-up.
#pragma once

#include <cstddef>
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

// The first vertex at each exact position (-0.0 as +0.0; a NaN matches nothing): an
// open-addressing table of indices into the caller's coordinates (3 per vertex), which it reads
// where they are, so that they may grow between calls. A node-based map of positions took 0.3 s
// of reading a 692k-vertex OBJ.
class PositionIndex {
 public:
  explicit PositionIndex(const std::vector<double>& xyz, size_t expected = 0);
  // The first vertex added at vertex v's position; v itself (now added) when none was.
  int first_at(int v);

 private:
  size_t slot_of(int v) const;
  void grow();

  const std::vector<double>& xyz_;
  std::vector<int> slots_;  // a vertex, or -1 for an empty slot; the size a power of two
  size_t count_ = 0;
};

// Each vertex of `xyz` (3 per vertex) welded into the first at exactly the same position (-0.0
// as +0.0): PolygonSoup::weld for files that split vertices where their attributes differ.
std::vector<int> weld_coincident(const std::vector<double>& xyz);

// Validates the soup (indices, finiteness, emptiness), triangulates it and drops what no face
// uses; throws InputError naming `name`.
LoadedMesh build_mesh(PolygonSoup soup, const std::string& name);

}  // namespace specdeform::detail
