// Internal: pieces that follow (UnconstrainedPieces::Follow). A connected component with no
// handle or fixed vertex moves rigidly with the deformed surface around it: teeth with the
// mouth, an eye with its socket, a wheel with its fender.
//
// Built once per selection. A free piece follows one constrained piece, the nearest to it (of
// several within softening * r of the nearest distance, r the free piece's bounding-box
// diagonal, the one it touches most: the largest sum of the weights below): a part squeezed
// between a turned cab and a bending body keeps its contact with the one it sits on, where a
// rotation between the two would keep neither. Each sample p of the free piece (its vertices,
// at most policy.samples of them spread over it) finds its closest point q on that piece's
// triangles (the driving surface), weighted by w = 1 / (|p - q| + softening * r)^2, so that
// contacts and near-contacts dominate. Per frame, from the driving surface's rest and deformed
// positions:
//     R = the rotation nearest to  sum_j w_j R_j,     t = sum_j w_j (q'_j - R q_j) / sum_j w_j,
// R_j the rotation of the deformation gradient of q_j's triangle (its normal included), q'_j
// the deformed point at q_j's barycentric coordinates. The piece moves by x -> R x + t: its
// shape is kept exactly, and its contact points stay on their deformed counterparts as well as
// one rigid motion allows (a piece pressed against a bending surface keeps its mean gap).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform::detail {

struct FreePiecePolicy {
  int samples = 1024;       // closest-point samples per free piece
  double softening = 0.01;  // of the piece's diagonal: the distance below which all samples
                            // weigh alike (a contact)
};

class FreePieces {
 public:
  // `driving[c]`: component c (labels of vertex_components) has a constrained vertex; the
  // others are the free pieces. Throws InputError when no driving component has a triangle.
  FreePieces(const TriangleMesh& mesh, const Eigen::VectorXi& components,
             const std::vector<char>& driving, const FreePiecePolicy& policy = {});

  int count() const { return static_cast<int>(pieces_.size()); }

  // One rigid motion per free piece, from the driving surface's positions at rest (those the
  // samples were found on) and deformed (n x 3; only the driving rows are read).
  std::vector<Eigen::Affine3d> motions(const Vertices& rest, const Vertices& deformed) const;

  // Rows of the free pieces' vertices of `out` set to their motion applied to `positions`.
  void apply(const std::vector<Eigen::Affine3d>& motions, const Vertices& positions,
             Vertices& out) const;

 private:
  struct Sample {
    int face;
    Eigen::Vector3d barycentric;
    double weight;
  };
  struct Piece {
    std::vector<int> vertices;
    std::vector<Sample> samples;
  };
  Faces faces_;  // the mesh's, for the samples' triangles
  std::vector<Piece> pieces_;
};

}  // namespace specdeform::detail
