// Options of the deformation solvers (spectral and spatial) and of the detail reconstruction.
//
// Two energies of the displacement d (n x 3) of the smooth base s, both on the mesh scaled to
// unit area (so the weights mean the same on any mesh size and resolution):
//  - Linear: the linearised thin-shell energy of Rong, Cao & Guo 2008 (eqs. 10-13) in symmetric
//    form,  E(d) = ks d^T K d + kb d^T K M^-1 K d,  K the cotangent stiffness matrix, M the mass
//    matrix. One linear solve per frame, but it cannot rotate: a turned handle shrinks the
//    surface between it and the fixed part (the "candy wrapper").
//  - Arap: as-rigid-as-possible (Sorkine & Alexa 2007): the same energy with its rest edge
//    vectors (stretching) and mean-curvature normals (bending) turned by one rotation per
//    cluster of vertices, minimised by quasi-Newton local/global iterations (arap_solver.h).
//    It keeps the shape under large rotations; the default.
// Soft constraints add  w sum_{i in C} a_i |s'_i - t_i|^2,  a_i the vertex's lumped area over
// its connected piece's area (so w does not depend on resolution, nor on the other pieces).
#pragma once

#include <string_view>

namespace specdeform {

enum class DeformEnergy {
  Linear,  // the paper's linearised thin shell: one solve per frame, no rotation
  Arap,    // as-rigid-as-possible, one rotation per vertex cluster: iterations per frame
};

enum class ConstraintMode {
  Soft,  // least squares, area-weighted (the default)
  Hard,  // exact; the spectral solver needs no more constrained vertices than modes
};

enum class DeformSolver {
  Spectral,  // in the span of the first m manifold harmonics (an m x m Hessian)
  Spatial,   // over all n vertices, prefactored with CHOLMOD (the reference, paper eq. 14)
};

enum class DetailMethod {
  None,          // the deformed smooth base itself
  Displacement,  // x' = s' + (x - s)
  Frames,        // details in per-vertex local frames (paper section 4.4)
  Transfer,      // deformation transfer with a prefactored Poisson system (the default)
};

// A connected component of the mesh with no handle or fixed vertex.
enum class UnconstrainedPieces {
  Follow,  // moves rigidly with the deformed surface around it (deform/free_pieces.h)
  Keep,    // stays where it is (its vertices are held in place)
  Error,   // is an InputError naming the piece
};

// DeformEnergy::Arap: its bending weight, rotation clusters and iterations.
struct ArapOptions {
  int clusters = 200;           // rotation clusters (at least one per connected component)
  double bending = 1e-3;        // the bending weight against the membrane's 1 (arap_solver.h)
  int max_iterations = 100;     // a cap on the iterations per frame
  double tolerance = 1e-4;      // stop when an iteration lowers the energy by less than this
                                // fraction of it (see arap_solver.h)
  double energy_floor = 1e-10;  // energies below this fraction of the base's Dirichlet energy
                                // are rounding noise (rigid motion): changes are measured
                                // against at least it
  int history = 5;              // L-BFGS pairs kept; 0: plain local/global steps
  bool warm_start = false;      // start from the previous frame's solution instead of the
                                // handles' rotations spread over the surface (interactive drags;
                                // not for timing a cold frame)
};

struct DeformOptions {
  DeformEnergy energy = DeformEnergy::Arap;  // measured: docs/results.md, "Rotations"
  double ks = 0.0;                           // Linear: stretching weight
  double kb = 1.0;                           // Linear: bending weight
  ArapOptions arap;
  ConstraintMode constraints = ConstraintMode::Soft;
  double constraint_weight = 1e5;  // w of the soft constraints
  DeformSolver solver = DeformSolver::Spectral;
  DetailMethod detail = DetailMethod::Transfer;
  UnconstrainedPieces unconstrained = UnconstrainedPieces::Follow;
  bool float32_basis = false;  // keep the basis in single precision (faster frames; a factored
                               // multilevel basis is read as P Z instead, faster still)
  // Transfer: build and factor its Poisson system on a background thread; until the last
  // selection's factorisation is ready, frames add the details as displacements
  // (SpectralDeformer::detail_pending). For interactive front ends.
  bool background_transfer = false;
  // One solve only (deform(), the command line's deform): the deformer releases the basis and
  // the reduced solvers once the deformed base is solved, and only then builds and factors the
  // detail reconstruction, so that the two never take memory at once (2.77M vertices: the
  // peak 8.4 -> 5.x GB). A second solve() is an InputError. Not with background_transfer.
  bool single_solve = false;

  // Throws InputError, naming the field, for a value out of range.
  void validate() const;
};

// The modes' names in scene files, on the command line and in the editor ("soft", "spatial",
// "transfer", ...). The *_from_name functions throw InputError for an unknown name.
std::string_view name(DeformEnergy energy);
std::string_view name(ConstraintMode mode);
std::string_view name(DeformSolver solver);
std::string_view name(DetailMethod method);
std::string_view name(UnconstrainedPieces pieces);
DeformEnergy deform_energy_from_name(std::string_view name);
ConstraintMode constraint_mode_from_name(std::string_view name);
DeformSolver deform_solver_from_name(std::string_view name);
DetailMethod detail_method_from_name(std::string_view name);
UnconstrainedPieces unconstrained_pieces_from_name(std::string_view name);

}  // namespace specdeform
