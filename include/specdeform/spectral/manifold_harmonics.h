// Manifold harmonics: the first m eigenpairs of the Laplace-Beltrami operator,
//     K h = lambda M h,   ascending lambda,   H^T M H = I,
// with K the stiffness matrix and M the lumped or consistent mass matrix of the chosen Laplacian
// (operators/laplacian.h: the cotangent Laplacian, or the intrinsic Delaunay one for bad
// meshes). Vallet & Levy, "Spectral geometry processing with manifold harmonics" (2008); the
// basis of Rong, Cao & Guo, "Spectral mesh deformation" (2008).
//
// Units: eigenvalues in 1/length^2 of the mesh (the unit sphere gives l(l+1)); the basis is
// M-orthonormal in the mesh's units (H^T M H = I). Internally the problem is solved on the mesh
// scaled to unit area, so tolerances and the shift do not depend on the mesh's size.
//
// Solvers:
//  - BlockKrylov (default): shift-invert block Krylov-Schur with thick restarts. K - sigma M is
//    factored once per band with CHOLMOD, each step solves for a whole block of right-hand sides,
//    and orthogonalises it against the basis by block Gram-Schmidt, twice, in two fused passes
//    over the basis (the subtraction of one pass with the projection of the next; the second
//    pass's subtraction lagged into the next block, DCGS2-style) and Cholesky QR within the block.
//    For large m the spectrum is computed band by band (interior shifts, LDL^T with one step of
//    iterative refinement), each band deflated against the pairs already found. K's null space (the
//    constants of each connected component) is known exactly and deflated from the start.
//  - Lanczos: Spectra's SymGEigsShiftSolver (implicitly restarted Lanczos, ncv = 2m + 1) on the
//    same CHOLMOD shift-invert operator. The plain baseline.
//  - Multilevel: an approximation for large meshes (Nasikun, Brandt & Hildebrandt, "Fast
//    approximation of Laplace-Beltrami eigenproblems", SGP 2018): the Galerkin projection of the
//    problem onto N ~ 10 m locally supported partition-of-unity functions P of the graph distance
//    around farthest-point samples, P^T K P z = lambda P^T M P z solved exactly, H = P Z. H is
//    exactly M-orthonormal and H^T K H = Lambda, so the low pass, the detail split and every
//    deformation energy (computed from H itself) stay exact in its span; but H is not made of
//    eigenvectors of K and M (`approximate`; the residuals say how far). Linear in n: no fine
//    factorisation. Meshes of fewer than multilevel_reduction * N vertices get the exact solver.
// Several connected pieces: K and M are block diagonal, and the harmonics are the union of each
// piece's own, computed piece by piece (spectral/piecewise.h). m is split by area with a floor:
// a piece gets m a_i / A modes, at least min(policy.piece_min_modes, its vertices), so that
// every piece can deform (the whole mesh's first m pairs would begin with one zero eigenvalue per
// piece: a 100-piece assembly at m = 100 would get constants only). The basis then has more than
// m columns (m_i summed; `pieces` and `requested_modes` record the split), each supported on
// one piece, in ascending order of eigenvalue.
// Each eigenvector's sign is fixed so that its entry of largest magnitude is positive; random
// start vectors are seeded, so the output is reproducible. If m ends inside a cluster of
// (nearly) equal eigenvalues, the truncated basis depends on an arbitrary rotation of that
// cluster: `cluster_truncated` says so.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Sparse>

#include "specdeform/mesh/triangle_mesh.h"
#include "specdeform/operators/laplacian.h"
#include "specdeform/operators/mass_matrix.h"

namespace specdeform {

enum class EigenSolver { BlockKrylov, Lanczos, Multilevel };

// The solver the command line and the editor use when none is asked for: Multilevel for meshes
// of policy.multilevel_from vertices or more, BlockKrylov below.
struct ManifoldHarmonicsPolicy;
EigenSolver default_eigensolver(int vertices, const ManifoldHarmonicsPolicy& policy);

// "krylov", "lanczos" or "multilevel"; eigen_solver_from_name throws InputError for another name.
std::string_view name(EigenSolver solver);
EigenSolver eigen_solver_from_name(std::string_view name);

// Called now and then during long computations: fraction done in [0, 1] and the stage's name.
using ProgressCallback = std::function<void(double fraction, std::string_view stage)>;

// The tuning constants of the solvers, measured on the armadillo (docs/results.md); unit-area
// scale. Rarely changed; named here so that each is in one place.
struct ManifoldHarmonicsPolicy {
  // Meshes of at most this many vertices are solved densely, and those whose first band's Krylov
  // space (about twice the band) would take half of the unknowns or more (measured: a 300-vertex
  // torus at m = 20 took 0.6 s dense, 0.03 s Krylov; the 502-vertex knight 0.27 s and 0.02 s).
  int dense_limit = 200;
  int single_band_limit = 150;  // m up to this: one band, shift below the spectrum
  int band_size = 90;           // larger m: bands of this many pairs at interior shifts
  int wide_block_from = 72;     // bands of this many pairs or more: blocks of 8, else of 4
  double shift_advance = 0.35;  // next shift: last eigenvalue found + this * band * spacing
  double near_radius = 1.2;     // found pairs within this * band * spacing of a shift are
                                // deflated from every block (the others at the end)
  double krylov_margin = 0.1;   // the Krylov-Schur test asks this fraction of the tolerance, so
                                // that the verified residuals meet the tolerance itself
  double redo_factor = 10;      // an interior band this far above its thresholds is redone
  double floor_factor = 100;    // a pair's threshold: max(tolerance, this * its rounding floor)
  // Multilevel: N = max(samples_per_mode * m, min_samples) coarse functions of support radius
  // `support` times the sampling's covering radius; meshes of fewer than reduction * N vertices
  // are solved exactly. Measured on the armadillo (43k and 692k, m = 100): support 2, 2.5 and 3
  // gave the first 20 eigenvalues within 17%, 1.9% and 1.7%; 15 and 20 samples per mode did not
  // bring the deformation closer to the exact basis's.
  int multilevel_samples_per_mode = 10;
  int multilevel_min_samples = 500;
  double multilevel_support = 2.5;
  int multilevel_reduction = 4;
  // The front ends' choice without a flag (default_eigensolver): multilevel from this many
  // vertices (docs/results.md, "Large meshes").
  int multilevel_from = 200000;
  // From this many vertices, the solvers work in a breadth-first numbering of the vertices
  // (linalg/locality_order.h; the basis comes back in the mesh's).
  int reorder_from = 50000;
  // Several pieces (spectral/piecewise.h): each gets at least this many modes (or all its
  // vertices), with at most piece_modes_limit * m in all (beyond, the pieces of least area keep
  // their constant only, or none: spectral/piecewise.h). A sphere of a 100-sphere assembly, pulled
  // by 0.8 radii and turned by 0.6 rad: its base missed the handle by 0.41% of the diagonal with 10
  // modes, 0.11% with 16 (the spherical harmonics of degree <= 3), 0.09% with 20
  // (tests/spectral/piecewise_test.cpp).
  int piece_min_modes = 16;
  int piece_modes_limit = 16;
  // ... and at most as many columns as this many bytes of dense basis hold (n rows of doubles),
  // but never fewer than m: 1,899 teapots (3.96M vertices, 5,698 pieces) at m = 100 asked for
  // 1,600 columns, 51 GB; within 4 GB they get 126 (the largest pieces their modes, the smallest
  // none: they follow the surface as free pieces).
  double piece_basis_bytes = 4e9;

  void validate() const;  // throws InputError
};

struct ManifoldHarmonicsOptions {
  int num_modes = 100;  // m, 1 <= m < n (split among several pieces, see above)
  MassType mass = MassType::Lumped;
  LaplacianType laplacian = LaplacianType::Cotan;  // the mesh overload's K and M
  EigenSolver solver = EigenSolver::BlockKrylov;
  double tolerance = 1e-8;    // residual each pair must reach, see eigen_residual
  double shift = -0.1;        // first shift sigma on the unit-area scale; must be < 0
  int block_size = 0;         // columns per block solve; 0: automatic
  int band_size = 0;          // eigenpairs per band; 0: automatic
  int max_restarts = 60;      // restarts per band (BlockKrylov) or Lanczos iterations / 10
  uint64_t seed = 1;          // for the random start block
  ProgressCallback progress;  // optional
  ManifoldHarmonicsPolicy policy;

  void validate() const;  // throws InputError; num_modes is checked against the mesh later
};

// The default m for a mesh of `vertices` vertices: ManifoldHarmonicsOptions' num_modes, or one
// fewer than the vertices where the mesh has no more (every eigensolver takes m < n). Front ends
// that lower it so say it.
int default_modes(int vertices);

enum class SolveStatus { Converged, NotConverged };

// One stage of a computation, as its progress names it, and the wall-clock seconds spent in it.
struct StageTime {
  std::string stage;
  double seconds = 0.0;
};

// A basis held as the multilevel solver makes it: H = P Z, P n x N sparse (rows summing to 1, a
// dozen entries each), Z N x m. A frame's product H c = P (Z c) reads P, not H: at 692k
// vertices ~100 MB against H's 553 MB (277 MB in float32).
struct FactoredBasis {
  Eigen::SparseMatrix<double, Eigen::RowMajor> prolongation;  // P, compressed
  Eigen::MatrixXd coarse;                                     // Z

  FactoredBasis() = default;
  FactoredBasis(const FactoredBasis&) = default;
  FactoredBasis& operator=(const FactoredBasis&) = default;
  // Eigen 3.4's sparse matrices have no moves (a "move" copies): these swap, so that a basis
  // handed on (and a ManifoldHarmonics or a Spectrum holding one) is not copied.
  FactoredBasis(FactoredBasis&& other) noexcept { swap(other); }
  FactoredBasis& operator=(FactoredBasis&& other) noexcept {
    FactoredBasis(std::move(other)).swap(*this);
    return *this;
  }
  void swap(FactoredBasis& other) noexcept {
    prolongation.swap(other.prolongation);
    coarse.swap(other.coarse);
  }

  bool empty() const { return coarse.size() == 0; }
  // Whether P and Z are fewer bytes than H with `scalar_bytes` (8 or 4) per entry, so that a
  // frame's product reads less and a cache file holds less: from m of about 40 on. False when
  // empty.
  bool smaller_than_dense(int scalar_bytes) const {
    return !empty() &&
           12.0 * double(prolongation.nonZeros()) + 8.0 * double(coarse.size()) <
               double(scalar_bytes) * double(prolongation.rows()) * double(coarse.cols());
  }
};

struct ManifoldHarmonics {
  Eigen::VectorXd eigenvalues;  // m (more on several pieces), ascending, mesh units
  Eigen::MatrixXd basis;        // n x m, H^T M H = I
  FactoredBasis factored;       // the multilevel basis of one piece: basis = P Z; else empty
  MassType mass = MassType::Lumped;
  LaplacianType laplacian = LaplacianType::Cotan;  // H is orthonormal in this Laplacian's M

  // Converged: every pair's residual is within its threshold, max(tolerance,
  // floor_factor * its rounding floor); `threshold` is the largest threshold applied.
  SolveStatus status = SolveStatus::Converged;
  Eigen::VectorXd residuals;    // per pair, as `tolerance` defines it
  double max_residual = 0.0;    // their max
  double rounding_floor = 0.0;  // max over pairs of the rounding error of K h - l M h
                                // (0 for an approximate basis: not computed)
  double threshold = 0.0;       // max over pairs of the threshold applied
  // The pair furthest over its own threshold (or, converged, nearest to it): what a message
  // about the result names, its residual, threshold and floor agreeing with each other. Index
  // -1 where not known (a basis read from a cache file).
  struct Pair {
    int index = -1;
    double residual = 0.0, threshold = 0.0, floor = 0.0;
  } worst_pair;
  double max_orthogonality_error = 0.0;  // max |H^T M H - I|
  bool cluster_truncated = false;        // lambda_m is (nearly) equal to lambda_{m+1}
  // Multilevel: the basis spans a coarse space of this many functions and is not made of
  // eigenvectors; `status` is the coarse solve's and the residuals measure the approximation.
  bool approximate = false;
  int coarse_functions = 0;
  // H^T K H = diag(eigenvalues) to rounding by construction: the pairs of a Rayleigh-Ritz on K
  // (the multilevel solver's coarse problem), so a deformer takes its stiffness form from the
  // eigenvalues (deform/reduced_forms.h). False for a basis made otherwise, which may be any
  // M-orthonormal one.
  bool rayleigh_ritz = false;
  // Connected pieces, solved one by one when more than one (0: not recorded, a basis file of
  // version 4 or older); the m asked for (the basis has more columns when pieces > 1).
  int pieces = 1;
  int requested_modes = 0;
  int bands = 0;  // shifts used (= factorizations)
  int restarts = 0;
  long long solves = 0;  // right-hand sides solved with the factorization
  // Where the time went, in the order the stages came (each summed over the pieces); empty for a
  // basis read from a file.
  std::vector<StageTime> stages;
};

ManifoldHarmonics compute_manifold_harmonics(const TriangleMesh& mesh,
                                             const ManifoldHarmonicsOptions& options = {});

// The same from the operators: K (stiffness) and M (mass, symmetric positive definite), n x n.
ManifoldHarmonics compute_manifold_harmonics(const Eigen::SparseMatrix<double>& K,
                                             const Eigen::SparseMatrix<double>& M,
                                             const ManifoldHarmonicsOptions& options);

// The residual of the computed pairs on the unit-area scale (area A = sum of M's entries):
//     max_i  A ||K h_i - lambda_i M h_i||_{D^-1} / max(A lambda_i, 1),
// D the row sums of M (= M when lumped). This is the measure of `tolerance`. A pair counts as
// converged when its residual is within the tolerance or, on meshes whose nearly degenerate
// triangles make the rounding error of forming K h itself larger (rounding_floor), within
// policy.floor_factor times that.
double eigen_residual(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M,
                      const Eigen::MatrixXd& H, const Eigen::VectorXd& lambda);

// "residual 3.2e-08 (threshold 1e-08, rounding floor 1.1e-12)": for messages about a result,
// the figures of its worst pair ("pair 41 of 100: residual ..., the largest residual 5e-08"
// where that pair's residual is not the largest).
std::string residual_summary(const ManifoldHarmonics& h);

// max |H^T M H - I|.
double orthonormality_error(const Eigen::SparseMatrix<double>& M, const Eigen::MatrixXd& H);

}  // namespace specdeform
