// A well-shaped version of a mesh's surface, for measurements: CGAL's isotropic remeshing
// (Botsch & Kobbelt 2004: splits, collapses, flips and tangential relaxation, the vertices
// projected back onto the input surface). Edges sharper than 60 degrees and the boundary are kept
// as features (split and collapsed along themselves, never flipped).
#pragma once

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform::bench {

// Throws InputError where CGAL cannot make a surface of the faces.
TriangleMesh isotropic_remesh(const TriangleMesh& mesh, double target_edge_length,
                              int iterations = 5);

// The mean length of the mesh's edges (each counted once per face).
double mean_edge_length(const TriangleMesh& mesh);

}  // namespace specdeform::bench
