// Internal: the part of a mesh on some of its vertices.
#pragma once

#include <vector>

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform::detail {

// The vertices with keep[v] (n flags) and the faces whose corners are all kept, renumbered in
// the mesh's order; original[k] receives the mesh's vertex of the part's vertex k.
TriangleMesh sub_mesh(const TriangleMesh& mesh, const std::vector<char>& keep,
                      std::vector<int>& original);

}  // namespace specdeform::detail
