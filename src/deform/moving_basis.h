// Internal: the basis a deformer solves in on a mesh of several pieces, under soft constraints.
//
// Only the pieces with a handle vertex deform: a piece held by fixed vertices alone stays at
// rest (its best displacement is zero) and a free piece follows rigidly (free_pieces.h). Their
// modes are dead weight in the solve, and they took the basis's share of m: on a 100-gear
// assembly at m = 100 the pulled gear had 16 modes (the floor of spectral/piecewise.h) and its
// base missed the handle by 0.85% of the diagonal. So the solve works in the modes of the
// moving pieces alone, m split among them by area as spectral/piecewise.h splits it among all
// pieces; a moving piece of more than policy.piece_min_modes vertices that the basis gives fewer
// modes than that share is solved again on its own (its first modes, exact, or multilevel from
// policy.multilevel_from vertices; a smaller piece, a speck, keeps the modes it had). The columns
// are n x k, zero outside the moving pieces, M-orthonormal (each piece's modes are), ascending. The
// low-pass base stays the basis's; ARAP's rotation clusters cover the moving pieces only (the 200
// clusters had been spread over all 100 gears, two to the pulled one).
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "specdeform/mesh/triangle_mesh.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform::detail {

// `components`: vertex_components labels; `moving[c]`: component c has a handle vertex;
// `piece_of_mode[j]`: the component of the basis's column j.
std::shared_ptr<const ManifoldHarmonics> moving_basis(const TriangleMesh& mesh,
                                                      const ManifoldHarmonics& basis,
                                                      const Eigen::VectorXi& components,
                                                      const std::vector<int>& piece_of_mode,
                                                      const std::vector<char>& moving);

}  // namespace specdeform::detail
