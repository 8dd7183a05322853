#include "specdeform/deform/deform_options.h"

#include <array>
#include <cmath>
#include <string>

#include "specdeform/exceptions.h"

namespace specdeform {

namespace {

constexpr std::array<std::string_view, 2> kEnergies = {"linear", "arap"};
constexpr std::array<std::string_view, 2> kConstraintModes = {"soft", "hard"};
constexpr std::array<std::string_view, 2> kSolvers = {"spectral", "spatial"};
constexpr std::array<std::string_view, 4> kDetailMethods = {"none", "displacement", "frames",
                                                            "transfer"};
constexpr std::array<std::string_view, 3> kUnconstrainedPieces = {"follow", "keep", "error"};

// The enumerator at the name's position in `names` (the enums count from 0 in this order).
template <typename Enum, size_t N>
Enum from_name(std::string_view name, const std::array<std::string_view, N>& names,
               const char* what) {
  for (size_t i = 0; i < N; ++i) {
    if (names[i] == name) return static_cast<Enum>(i);
  }
  std::string choices;
  for (size_t i = 0; i < N; ++i)
    choices += (i == 0 ? "" : i + 1 == N ? " or " : ", ") + std::string(names[i]);
  throw InputError("unknown " + std::string(what) + " '" + std::string(name) + "' (" + choices +
                   ")");
}

void require(bool ok, const std::string& message) {
  if (!ok) throw InputError("deformation options: " + message);
}

}  // namespace

void DeformOptions::validate() const {
  require(std::isfinite(ks) && std::isfinite(kb) && ks >= 0 && kb >= 0 && ks + kb > 0,
          "ks and kb must be finite, >= 0 and not both 0");
  require(std::isfinite(constraint_weight) && constraint_weight > 0,
          "the constraint weight must be a finite number > 0");
  require(arap.clusters >= 1, "ARAP needs at least 1 rotation cluster");
  require(arap.max_iterations >= 1, "ARAP needs at least 1 iteration");
  require(std::isfinite(arap.bending) && arap.bending >= 0,
          "the ARAP bending weight must be a finite number >= 0");
  require(std::isfinite(arap.tolerance) && arap.tolerance >= 0,
          "the ARAP tolerance must be a finite number >= 0");
  require(arap.history >= 0 && arap.history <= 50, "the ARAP history must be in [0, 50]");
  require(std::isfinite(arap.energy_floor) && arap.energy_floor >= 0 && arap.energy_floor < 1,
          "the ARAP energy floor must be in [0, 1)");
  require(!(single_solve && background_transfer),
          "single_solve and background_transfer exclude each other");
}

std::string_view name(DeformEnergy energy) {
  return kEnergies[static_cast<int>(energy)];
}
std::string_view name(ConstraintMode mode) {
  return kConstraintModes[static_cast<int>(mode)];
}
std::string_view name(DeformSolver solver) {
  return kSolvers[static_cast<int>(solver)];
}
std::string_view name(DetailMethod method) {
  return kDetailMethods[static_cast<int>(method)];
}
std::string_view name(UnconstrainedPieces pieces) {
  return kUnconstrainedPieces[static_cast<int>(pieces)];
}

DeformEnergy deform_energy_from_name(std::string_view name) {
  return from_name<DeformEnergy>(name, kEnergies, "energy");
}
ConstraintMode constraint_mode_from_name(std::string_view name) {
  return from_name<ConstraintMode>(name, kConstraintModes, "constraint mode");
}
DeformSolver deform_solver_from_name(std::string_view name) {
  return from_name<DeformSolver>(name, kSolvers, "solver");
}
DetailMethod detail_method_from_name(std::string_view name) {
  return from_name<DetailMethod>(name, kDetailMethods, "detail method");
}
UnconstrainedPieces unconstrained_pieces_from_name(std::string_view name) {
  return from_name<UnconstrainedPieces>(name, kUnconstrainedPieces, "unconstrained-pieces policy");
}

}  // namespace specdeform
