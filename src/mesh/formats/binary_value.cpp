#include "binary_value.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>

namespace specdeform::detail {

size_t ply_scalar_size(PlyScalar s) {
  switch (s) {
    case PlyScalar::I8:
    case PlyScalar::U8:
      return 1;
    case PlyScalar::I16:
    case PlyScalar::U16:
      return 2;
    case PlyScalar::I32:
    case PlyScalar::U32:
    case PlyScalar::F32:
      return 4;
    case PlyScalar::F64:
      return 8;
  }
  return 0;
}

double ply_binary_value(const char* bytes, PlyScalar s, bool big_endian) {
  const size_t size = ply_scalar_size(s);
  unsigned char b[8];
  std::memcpy(b, bytes, size);
  if (big_endian != (std::endian::native == std::endian::big)) std::reverse(b, b + size);
  const auto as = [&](auto v) {
    std::memcpy(&v, b, sizeof v);
    return static_cast<double>(v);
  };
  switch (s) {
    case PlyScalar::I8:
      return as(int8_t{});
    case PlyScalar::U8:
      return as(uint8_t{});
    case PlyScalar::I16:
      return as(int16_t{});
    case PlyScalar::U16:
      return as(uint16_t{});
    case PlyScalar::I32:
      return as(int32_t{});
    case PlyScalar::U32:
      return as(uint32_t{});
    case PlyScalar::F32:
      return as(float{});
    case PlyScalar::F64:
      return as(double{});
  }
  return 0.0;
}

const char* ply_scalar_name(PlyScalar s) {
  static constexpr const char* kNames[] = {"char", "uchar", "short", "ushort",
                                           "int",  "uint",  "float", "double"};
  return kNames[static_cast<int>(s)];
}

}  // namespace specdeform::detail
