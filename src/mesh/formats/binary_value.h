// Internal: scalar values of binary files (PLY's types; STL's float32), read as doubles and
// written back where they changed.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <string>

#include "mesh/float_cast.h"

namespace specdeform::detail {

enum class PlyScalar { I8, U8, I16, U16, I32, U32, F32, F64 };
size_t ply_scalar_size(PlyScalar s);
const char* ply_scalar_name(PlyScalar s);
// The binary value of type `s` at `bytes`, stored big- or little-endian, as a double.
double ply_binary_value(const char* bytes, PlyScalar s, bool big_endian);

// A binary value of type `s` at `at`: read as a double, or written from one (rounded for integer
// types). Only a value that differs is written, so that an unchanged one keeps its bytes (-0.0,
// NaN payloads).
class BinaryValue {
 public:
  BinaryValue(std::string& bytes, bool big_endian) : bytes_(bytes), big_(big_endian) {}

  double get(size_t at, PlyScalar s) const { return ply_binary_value(bytes_.data() + at, s, big_); }

  void set(size_t at, PlyScalar s, double v) {
    switch (s) {
      case PlyScalar::I8:
        return put<int8_t>(at, s, v);
      case PlyScalar::U8:
        return put<uint8_t>(at, s, v);
      case PlyScalar::I16:
        return put<int16_t>(at, s, v);
      case PlyScalar::U16:
        return put<uint16_t>(at, s, v);
      case PlyScalar::I32:
        return put<int32_t>(at, s, v);
      case PlyScalar::U32:
        return put<uint32_t>(at, s, v);
      case PlyScalar::F32:
        return put<float>(at, s, v);
      case PlyScalar::F64:
        return put<double>(at, s, v);
    }
  }

 private:
  template <typename T>
  void put(size_t at, PlyScalar s, double v) {
    const T value = checked_cast<T>(v, "a PLY value");
    const double stored = get(at, s);
    if (static_cast<double>(value) == stored || (std::isnan(v) && std::isnan(stored))) return;
    unsigned char b[sizeof(T)];
    std::memcpy(b, &value, sizeof value);
    if (big_ != (std::endian::native == std::endian::big)) std::reverse(b, b + sizeof b);
    std::memcpy(bytes_.data() + at, b, sizeof b);
  }

  std::string& bytes_;
  bool big_;
};

}  // namespace specdeform::detail
