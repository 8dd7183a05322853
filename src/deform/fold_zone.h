// Internal: where the deformed smooth base folds, the details are not turned with the fold.
//
// A subspace of m harmonics cannot always hold the bend that a turning handle asks for. On the
// camelhead's 75-degree scene (m = 100) the smooth base's ARAP minimum folds 38 faces, 13-15
// edge lengths from the handle, where the turn compresses the snout; so does the M-projection
// onto the same span of the fold-free all-vertex ARAP solution (24 faces): the low pass rings.
// Deformation transfer copies each base triangle's deformation gradient onto the detail, folds
// included (49 folded faces, where adding the details as displacements gives none); frames
// turn each offset with its one-ring's rotation, folds included (63).
//
// The fold zone of a deformed base s' (against its rest shape s): the faces that fold (their
// unit normal against the sum of their edge neighbours', having agreed with it within 60
// degrees at rest), grown through edge neighbours whose in-plane stretch ratio (the larger
// singular value of the map s -> s' over the smaller) exceeds kStretchRatio, and then by kRings
// rings of edge neighbours. There the details are added as displacements, x'_d = s' + (x - s):
// the transfer takes x'_d's deformation gradient instead of the base's, frames leave the
// offsets unturned (detail_reconstruction.h). O(f) per frame to look for folds (none: nothing
// changes), O(zone) beyond. Measured on the camelhead's scene (default / frames folded faces):
// ratio 1.5 with 0, 1, 2 rings 1/10, 0/6, 0/0; ratio 2 14/47, 9/34, 3/19; no growth 31/64,
// 28/32, 12/32.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace specdeform::detail {

using RowVertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using FaceRows = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;

// Corners (rows a, b, c) -> [c - a, b - a, n], n the unit normal of (b - a) x (c - a) (zero for
// a degenerate triangle).
Eigen::Matrix3d triangle_frame(const Eigen::Matrix3d& corners);

// Corners (rows) -> Q = A [grad phi_a; grad phi_b; grad phi_c] [grad x, grad y, grad z]: the
// hat functions' gradients times the coordinates' gradients, area-weighted (zero when
// degenerate). The transfer's right-hand side of a triangle of gradient S is Q S^T.
Eigen::Matrix3d corner_gradients(const Eigen::Matrix3d& corners);

// The unit normals (b - a) x (c - a) of the faces (f x 3, in `normals`' memory; zero where
// degenerate), on two threads.
void unit_face_normals(const FaceRows& faces, const RowVertices& V, RowVertices& normals);

class FoldZone {
 public:
  static constexpr double kStretchRatio = 1.5;
  static constexpr int kRings = 2;

  // faces: f x 3 rows of `base`, the rest shape s (n x 3).
  FoldZone(FaceRows faces, RowVertices base);

  // The zone's faces for the deformed base s' (n x 3) with its unit face normals (f x 3); empty
  // where nothing folds.
  std::vector<int> find(const RowVertices& deformed, const RowVertices& normals) const;

  const FaceRows& faces() const { return faces_; }
  const RowVertices& base() const { return base_; }

 private:
  // The sum of the unit normals of face f's edge neighbours.
  Eigen::RowVector3d neighbour_normals(const RowVertices& normals, Eigen::Index f) const;

  FaceRows faces_;
  FaceRows neighbours_;  // per face, the face across each edge (-1: none)
  RowVertices base_;
  std::vector<char> agreed_;  // the face agreed with its neighbours at rest
};

}  // namespace specdeform::detail
