// Handle selections and their targets, shared by the spectral and the spatial solvers.
//
// A selection names, by vertex index, one or more handle groups (each moved by its own rigid or
// affine transform) and a fixed set (held in place); every other vertex is free. A vertex may
// belong to one group only. Transforms act on positions: p -> A p + t (Eigen::Affine3d).
#pragma once

#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "specdeform/deform/deform_options.h"
#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform {

struct Selection {
  std::vector<std::vector<int>> handles;  // vertex indices of each handle group
  std::vector<int> fixed;                 // vertex indices held in place
};

// The constrained vertices of a selection in one list, with the group of each (-1 = fixed).
// The vertices of free pieces (connected components without a handle or fixed vertex, under
// UnconstrainedPieces::Follow or Keep) end the list, as fixed vertices, from index `first_free`
// on: the solvers hold them, and the deformer then keeps them or moves them along.
struct ConstrainedSet {
  std::vector<int> vertices;
  std::vector<int> group;
  int num_groups = 0;
  int free_pieces = 0;
  size_t first_free = 0;
};

// Throws InputError for an empty selection, an index out of [0, n), a vertex in two groups, or,
// under UnconstrainedPieces::Error, a connected component with no constrained vertex (the
// message names its size and its first vertex). Messages name vertex v as file_index[v] when
// file_index is given (the file's numbering, MeshReadInfo::vertex_to_file), and start with
// `name` (the scene's file, say).
ConstrainedSet constrained_set(const Selection& selection, const TriangleMesh& mesh,
                               UnconstrainedPieces pieces = UnconstrainedPieces::Keep,
                               const std::vector<int>& file_index = {},
                               std::string_view name = "selection");

// The same with the mesh's vertex_components() computed beforehand (labels 0 .. count-1).
ConstrainedSet constrained_set(const Selection& selection, const Eigen::VectorXi& components,
                               int count, UnconstrainedPieces pieces,
                               const std::vector<int>& file_index = {},
                               std::string_view name = "selection");

// The soft constraints' vertex weights a_i: each vertex's lumped area over its connected
// piece's area, so that a piece weighs its constraints as it would alone (on the whole mesh's
// area, a sphere of a 100-sphere assembly would hold its handle 100 times more loosely).
Eigen::VectorXd piece_area_fractions(const Eigen::VectorXd& vertex_area,
                                     const Eigen::VectorXi& components, int count);

// Target position of every constrained vertex (|C| x 3): the group's transform applied to
// `positions` (fixed vertices keep theirs). Throws InputError for a wrong number of transforms,
// a non-finite, singular or mirroring (negative determinant) transform, or a target more than a
// million times the constrained region's size (the mesh's, for a region of one vertex) from its
// vertex.
Eigen::MatrixX3d constraint_targets(const ConstrainedSet& set, const Eigen::MatrixX3d& positions,
                                    const std::vector<Eigen::Affine3d>& transforms);

}  // namespace specdeform
