// Handle selections and their targets, shared by the spectral and the spatial solvers.
//
// A selection names, by vertex index, one or more handle groups (each moved by its own rigid or
// affine transform) and a fixed set (held in place); every other vertex is free. A vertex may
// belong to one group only. Transforms act on positions: p -> A p + t (Eigen::Affine3d).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform {

struct Selection {
  std::vector<std::vector<int>> handles;  // vertex indices of each handle group
  std::vector<int> fixed;                 // vertex indices held in place
};

// The constrained vertices of a selection in one list, with the group of each (-1 = fixed).
struct ConstrainedSet {
  std::vector<int> vertices;
  std::vector<int> group;
  int num_groups = 0;
};

// Throws InputError for an empty selection, an index out of [0, n), a vertex in two groups, or a
// connected component of the mesh with no constrained vertex (its position would be undefined).
ConstrainedSet constrained_set(const Selection& selection, const TriangleMesh& mesh);

// The same with the mesh's vertex_components() computed beforehand (labels 0 .. count-1).
ConstrainedSet constrained_set(const Selection& selection, const Eigen::VectorXi& components,
                               int count);

// Target position of every constrained vertex (|C| x 3): the group's transform applied to
// `positions` (fixed vertices keep theirs). Throws InputError for a wrong number of transforms
// or a non-finite or singular transform.
Eigen::MatrixX3d constraint_targets(const ConstrainedSet& set, const Eigen::MatrixX3d& positions,
                                    const std::vector<Eigen::Affine3d>& transforms);

}  // namespace specdeform
