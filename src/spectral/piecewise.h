// Internal: the manifold harmonics of a mesh of several connected pieces. K and M are block
// diagonal over the pieces, so the spectrum is the union of the pieces' own spectra: each piece
// is solved alone with its share of the modes (piece_modes) and the pairs are merged in
// ascending order. A piece of c identical ones costs what one piece costs (no eigenvalue of
// multiplicity c for the shifts to avoid), and every piece gets modes that deform, where the
// whole mesh's first m pairs would begin with the c constants.
#pragma once

#include <functional>
#include <vector>

#include <Eigen/Sparse>

#include "spectral/eigensolvers.h"

namespace specdeform::detail {

// The modes of each piece, for m asked in all: its share of the area, m a_i / A rounded, and at
// least min(policy.piece_min_modes, its vertices), at most its vertices. When that comes to more
// than policy.piece_modes_limit * m in all, or more columns than policy.piece_basis_bytes hold
// (but never fewer than m), the pieces of least area keep their constant mode
// only, smallest first, until it fits; where the constants alone exceed it (thousands of specks
// of a scan), the smallest pieces get none (their low-pass is the origin; as free pieces they
// follow or stay all the same), so that the basis stays within the limit.
std::vector<int> piece_modes(const std::vector<double>& area, const std::vector<int>& vertices,
                             int m, const ManifoldHarmonicsPolicy& policy);

// Solves one connected piece: K, M of unit area, the multilevel solver's edge lengths (or null).
using ConnectedSolver = std::function<Spectrum(
    const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M,
    const Eigen::SparseMatrix<double>* lengths, const ManifoldHarmonicsOptions& options)>;

// The pairs of all pieces (labels from stiffness_components, `count` of them), M of unit area,
// each piece solved by `solve` on its own unit-area scale; the result on M's scale, ascending.
// Progress is reported by the pieces' share of the vertices.
Spectrum solve_by_piece(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M,
                        const Eigen::SparseMatrix<double>* lengths, const std::vector<int>& label,
                        int count, const ManifoldHarmonicsOptions& options,
                        const ConnectedSolver& solve);

}  // namespace specdeform::detail
