// The peer the comparison measures against: CGAL's smooth-rotation-enhanced ARAP (Levi &
// Gotsman, "Smooth rotation enhanced as-rigid-as-possible mesh animation", 2014;
// CGAL::Surface_mesh_deformation with SRE_ARAP, its default alpha), on the detailed mesh over all
// vertices, with the handle and fixed vertices as hard constraints, from the rest pose.
#pragma once

#include <memory>
#include <vector>

#include "specdeform/deform/selection.h"
#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform::cli {

class SrArapPeer {
 public:
  // Throws InputError where CGAL cannot represent the mesh (non-manifold).
  SrArapPeer(const TriangleMesh& mesh, const ConstrainedSet& set, const Eigen::MatrixX3d& targets);
  ~SrArapPeer();

  // Back to the rest pose.
  void reset();
  // `iterations` more local/global iterations; the positions (n x 3).
  Vertices iterate(int iterations);

  double setup_seconds() const { return setup_seconds_; }  // CGAL's factorisation

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double setup_seconds_ = 0.0;
};

}  // namespace specdeform::cli
