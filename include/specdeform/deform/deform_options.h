// Options of the deformation solvers (spectral and spatial) and of the detail reconstruction.
//
// The energy of a displacement field d (n x 3) of the base surface is the linearised
// thin-shell energy of Rong, Cao & Guo 2008 (eqs. 10-13) in symmetric form,
//     E(d) = ks d^T K d + kb d^T K M^-1 K d,
// K the cotangent stiffness matrix, M the mass matrix, both measured on the mesh scaled to unit
// area: stretching and bending then scale alike (as length^2), so ks, kb and the constraint
// weight mean the same on any mesh size and resolution. Soft constraints add
//     w sum_{i in C} a_i |d_i - t_i|^2,
// a_i the vertex's lumped area on the same unit-area scale (so w does not depend on resolution).
#pragma once

#include <string_view>

namespace specdeform {

enum class ConstraintMode {
  Soft,  // least squares, area-weighted (the default)
  Hard,  // exact; the spectral solver needs no more constrained vertices than modes
};

enum class DeformSolver {
  Spectral,  // in the span of the first m manifold harmonics (reduced, diagonal Hessian)
  Spatial,   // over all n vertices, prefactored with CHOLMOD (the reference, paper eq. 14)
};

enum class DetailMethod {
  None,          // the deformed smooth base itself
  Displacement,  // x' = s' + (x - s)
  Frames,        // details in per-vertex local frames (paper section 4.4)
  Transfer,      // deformation transfer with a prefactored Poisson system (the default)
};

struct DeformOptions {
  double ks = 0.0;  // stretching weight
  double kb = 1.0;  // bending weight
  ConstraintMode constraints = ConstraintMode::Soft;
  double constraint_weight = 1e5;  // w of the soft constraints
  DeformSolver solver = DeformSolver::Spectral;
  DetailMethod detail = DetailMethod::Transfer;
  bool float32_basis = false;  // keep the basis in single precision (faster frames)
};

// The modes' names in scene files, on the command line and in the editor ("soft", "spatial",
// "transfer", ...). The *_from_name functions throw InputError for an unknown name.
std::string_view name(ConstraintMode mode);
std::string_view name(DeformSolver solver);
std::string_view name(DetailMethod method);
ConstraintMode constraint_mode_from_name(std::string_view name);
DeformSolver deform_solver_from_name(std::string_view name);
DetailMethod detail_method_from_name(std::string_view name);

}  // namespace specdeform
