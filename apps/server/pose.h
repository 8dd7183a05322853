// Pose-aware editing: pinning a region where it is shown, and taking the shown result as the
// rest shape of the next edit.
#pragma once

#include <vector>

#include <Eigen/Geometry>

#include "specdeform/mesh/triangle_mesh.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform::server {

struct FittedTransform {
  Eigen::Affine3d transform;
  double max_error = 0.0;  // largest |T rest_i - current_i| over the vertices
};

// The affine transform T that best maps `rest` to `current` at `vertices` (least squares),
// pulled towards the best rotation where the vertices leave it undetermined (a flat or thin
// region), so that T is always invertible. Throws InputError for no vertices.
FittedTransform fit_transform(const Vertices& rest, const Vertices& current,
                              const std::vector<int>& vertices);

// The basis of a mesh reused for the same mesh in another pose (same triangles, other
// positions): its span, made M-orthonormal and K-diagonal on `mesh` (Rayleigh-Ritz), with its
// eigen-residual there (max_residual, eigen_residual()'s measure). The deformation energy in
// that span is then exact in its stretching term and off by the square of the residual in
// its bending term.
ManifoldHarmonics reuse_basis(const TriangleMesh& mesh, const ManifoldHarmonics& basis);

}  // namespace specdeform::server
