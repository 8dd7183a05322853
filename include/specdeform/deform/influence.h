// A drag's region of influence (Blender's proportional editing radius): the vertices farther than
// `radius` from every handle vertex, along the surface, join the fixed set, so that the handles
// move only the surface near them; the deformation energy makes the transition to the held part
// smooth. Distances are shortest paths along the mesh's edges (Dijkstra from all handle vertices
// at once, edge lengths of the mesh's positions, in single precision): at most a few percent
// above the geodesic distance on a well-shaped mesh. Only the pieces that hold a handle vertex are
// limited.
#pragma once

#include <Eigen/Core>

#include "specdeform/deform/selection.h"
#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform {

// Each vertex's distance along the edges to the nearest handle vertex (n; infinity on pieces
// without one). Throws InputError for a handle vertex out of range.
Eigen::VectorXd handle_distances(const TriangleMesh& mesh, const Selection& selection);

// `selection` with every vertex farther than `radius` (mesh units, > 0) from the handles added
// to its fixed set (handle vertices stay handles). Throws InputError for a radius that is not a
// positive number.
Selection limit_influence(const TriangleMesh& mesh, const Selection& selection, double radius);

}  // namespace specdeform
