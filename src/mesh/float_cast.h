// Internal: doubles into the float32 and integer fields of binary formats, checked: a finite value
// beyond the field's range is an InputError naming `what` (the conversion itself would be
// undefined), never a silently wrong number.
#pragma once

#include <cmath>
#include <limits>
#include <string>

#include "specdeform/exceptions.h"

namespace specdeform::detail {

template <typename T>
T checked_cast(double v, const char* what) {
  if constexpr (std::is_floating_point_v<T>) {
    if (std::isfinite(v) && std::abs(v) > std::numeric_limits<T>::max()) {
      throw InputError(std::string(what) + " beyond the range of float32 (" + std::to_string(v) +
                       ")");
    }
    return static_cast<T>(v);
  } else {
    const double r = std::round(v);
    if (!(r >= double(std::numeric_limits<T>::lowest()) &&
          r <= double(std::numeric_limits<T>::max()))) {
      throw InputError(std::string(what) + " beyond the range of its integer type (" +
                       std::to_string(v) + ")");
    }
    return static_cast<T>(r);
  }
}

inline float to_float(double v, const char* what) {
  return checked_cast<float>(v, what);
}

}  // namespace specdeform::detail
