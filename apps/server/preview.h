// A coarse view of a mesh for drawing during drags, when the browser cannot draw every frame of
// the full mesh at the rate the server delivers them: vertex clustering on a uniform grid
// (Rossignac & Borrel 1993). Each occupied cell keeps the vertex nearest to the mean of its
// vertices; a triangle whose corners fall in three different cells becomes a triangle between
// their kept vertices (duplicates dropped). The kept vertices are mesh vertices, so a frame's
// preview is its result at those vertices, exact there.
#pragma once

#include "protocol.h"
#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform::server {

// About `target` vertices (within a quarter, by adjusting the cell size); the whole mesh when
// it has no more than `target`. Throws InputError for target < 4.
PreviewMesh make_preview(const TriangleMesh& mesh, int target);

}  // namespace specdeform::server
