// On-disk cache of a manifold-harmonics basis.
//
// Binary, little-endian, versioned:
//   "SDBASIS\0" (8 bytes) | version u32 | n u32 | m u32 | mass u8 (0 lumped, 1 consistent) |
//   scalar u8 (8 = float64, 4 = float32) | laplacian u8 (0 cotan, 1 intrinsic-delaunay) |
//   reserved u8 | mesh hash u64 | solver report | layout | eigenvalues (m x f64) | residuals (m x
//   f64, version 4 on) | basis (n x m, column-major, float64 or float32)
// or, for a factored basis (version 6 on, scalar 0), in place of the basis its factors H = P Z:
//   N u32 | nnz u64 | P's row starts ((n + 1) x i32) | columns (nnz x i32) | values (nnz x f64) |
//   Z (N x m, column-major, f64): exact, and about half the float32 basis's bytes at m = 100.
// with the solver report (version 3 on) max_residual, rounding_floor, threshold,
// max_orthogonality_error (f64 each) | bands u32 | restarts u32 | solves u64 | converged u8 |
// cluster_truncated u8 | approximate u8 | coarse_functions u32 | 1 reserved byte (version 3:
// 6 reserved bytes, zero: an exact basis), so that a basis read back reports how it was computed
// (a multilevel basis says it is approximate, and its residual per pair); then (version 5 on)
// the layout: pieces u32 | requested_modes u32 (a basis of several pieces has more columns
// than asked).
// Version 2 added the Laplacian in a byte that version 1 reserved (always 0): version 1 files
// are read as cotan bases; files of versions 1 and 2 read back with max_residual NaN (unknown). The
// mesh hash covers the vertex positions and the faces, so loading refuses, with a clear message, a
// basis that was computed for another mesh (or another version of it). float32 storage halves the
// file; loading converts back to double, or multiplies the factors out (the loaded basis keeps
// them). A factored basis is saved as its factors where they are fewer bytes than the basis in
// the precision asked for (FactoredBasis::smaller_than_dense). Files are written atomically.
#pragma once

#include <cstdint>
#include <filesystem>

#include "specdeform/mesh/triangle_mesh.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform {

enum class BasisPrecision { Float64, Float32 };

// 64-bit FNV-1a of the vertex coordinates' bits and the face indices.
uint64_t mesh_hash(const TriangleMesh& mesh);

void save_basis(const std::filesystem::path& path, const ManifoldHarmonics& basis,
                const TriangleMesh& mesh, BasisPrecision precision = BasisPrecision::Float64);

// Throws InputError if the file is unreadable, not a basis file, of another version, truncated,
// or computed for another mesh. The result's `mass` and `laplacian` are the file's.
ManifoldHarmonics load_basis(const std::filesystem::path& path, const TriangleMesh& mesh);

// Throws InputError, naming the file and both choices, unless the basis was computed with this
// mass matrix and Laplacian: a basis is orthonormal only in its own operators.
void require_operators(const std::filesystem::path& path, const ManifoldHarmonics& basis,
                       MassType mass, LaplacianType laplacian);

}  // namespace specdeform
