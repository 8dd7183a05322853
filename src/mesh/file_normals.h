// Internal: a file's normals (and glTF tangents) after its positions moved, as NormalUpdate says
// (mesh_file.h).
//
// Each normal row is shared by the polygon corners that use it (FileAttributes::corner_normal).
// Per corner, the triangle (previous corner, corner, next corner) of its polygon gives the
// corner's angle (the weight), the deformed unit normal (Recompute) and the deformation gradient
// J = D R^-1, R = [e1 e2 n] at rest and D = [e1' e2' n'] deformed, e1, e2 the corner's two edges
// and n the unit normal (Follow: n <- J^-T n, tangents: t <- J t). A row none of whose polygons
// moved (every corner exactly at rest) keeps its value; a row whose update vanishes (a zero file
// normal, degenerate faces) takes the Recompute one, else keeps its value.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "specdeform/mesh/mesh_file.h"

namespace specdeform::detail {

// The rows of a.normals for the file vertices' positions `deformed` (`rest`: the file's own).
Eigen::MatrixX3d updated_normals(const FileAttributes& a, const Vertices& rest,
                                 const Vertices& deformed, NormalUpdate mode);

// Normal rows used at several positions (exporters merge equal normals: Blender's OBJ writer
// on flat and cylindrical parts): one row cannot follow corners that the deformation turns
// apart. How many rows have a corner whose own transported normal (J^-T n) is more than
// kTurnedApart degrees from the row's `normals` (updated), and the largest such angle.
struct SharedNormals {
  static constexpr double kTurnedApart = 5.0;
  int turned_apart = 0;
  double largest_degrees = 0.0;
};
SharedNormals shared_normals(const FileAttributes& a, const Vertices& rest,
                             const Vertices& deformed, const Eigen::MatrixX3d& normals);

// Each file vertex's local rotation: the rotation nearest to the map of its one-ring's rest edges
// to their deformed ones (the polygon edges at the vertex, over every file vertex at the same rest
// position: glTF and OBJ split vertices along seams). `turned[v]` is 0, and the rotation exactly
// the identity, where no vertex of the ring moved.
std::vector<Eigen::Matrix3d> vertex_rotations(const FileAttributes& a, const Vertices& rest,
                                              const Vertices& deformed, std::vector<char>& turned);

// Tangents with rows like a.normals' (glTF: one per split vertex), carried by the gradients of
// the corners that use them, made orthogonal to `normals` (the updated normals) and unit.
Eigen::MatrixX3d updated_tangents(const FileAttributes& a, const Vertices& rest,
                                  const Vertices& deformed, const Eigen::MatrixX3d& tangents,
                                  const Eigen::MatrixX3d& normals);

}  // namespace specdeform::detail
