#include "specdeform/deform/deform_options.h"

#include <array>
#include <string>

#include "specdeform/exceptions.h"

namespace specdeform {

namespace {

constexpr std::array<std::string_view, 2> kConstraintModes = {"soft", "hard"};
constexpr std::array<std::string_view, 2> kSolvers = {"spectral", "spatial"};
constexpr std::array<std::string_view, 4> kDetailMethods = {"none", "displacement", "frames",
                                                            "transfer"};

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

}  // namespace

std::string_view name(ConstraintMode mode) {
  return kConstraintModes[static_cast<int>(mode)];
}
std::string_view name(DeformSolver solver) {
  return kSolvers[static_cast<int>(solver)];
}
std::string_view name(DetailMethod method) {
  return kDetailMethods[static_cast<int>(method)];
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

}  // namespace specdeform
