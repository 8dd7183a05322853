// Uniform 1-to-4 subdivision of a triangle mesh: every edge gets a new vertex and every triangle
// becomes four. Loop (1987) smooths the surface, with the usual crease rules on boundary and
// non-manifold edges (Warren's weights beta = 3/(8k), 3/16 for valence 3); Midpoint keeps the
// geometry exactly. Each level multiplies the face count by 4; vertices become n + edges.
// The first n vertices of the result correspond to the input's vertices, in order.
#pragma once

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform {

enum class SubdivisionScheme { Loop, Midpoint };

TriangleMesh subdivide(const TriangleMesh& mesh, int levels,
                       SubdivisionScheme scheme = SubdivisionScheme::Loop);

}  // namespace specdeform
