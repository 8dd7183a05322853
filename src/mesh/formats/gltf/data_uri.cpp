#include "data_uri.h"

#include <array>
#include <cstdint>

namespace specdeform::detail {

namespace {

constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

constexpr std::array<int8_t, 256> digit_values() {
  std::array<int8_t, 256> v{};
  v.fill(-1);
  for (int i = 0; i < 64; ++i) v[uint8_t(kDigits[i])] = int8_t(i);
  return v;
}

constexpr std::array<int8_t, 256> kValue = digit_values();

}  // namespace

bool is_data_uri(std::string_view uri) {
  return uri.starts_with("data:");
}

std::optional<DataUri> decode_data_uri(std::string_view uri) {
  if (!is_data_uri(uri)) return std::nullopt;
  const size_t comma = uri.find(',');
  if (comma == std::string_view::npos) return std::nullopt;
  const std::string_view header = uri.substr(5, comma - 5);
  if (!header.ends_with(";base64")) return std::nullopt;
  DataUri out;
  out.mime_type = std::string(header.substr(0, header.find(';')));
  const std::string_view payload = uri.substr(comma + 1);
  out.bytes.reserve(payload.size() / 4 * 3);
  uint32_t bits = 0;
  int count = 0;
  for (size_t i = 0; i < payload.size(); ++i) {
    const char c = payload[i];
    if (c == '=') {
      if (payload.find_first_not_of('=', i) != std::string_view::npos) return std::nullopt;
      break;
    }
    const int8_t v = kValue[uint8_t(c)];
    if (v < 0) return std::nullopt;
    bits = bits << 6 | uint32_t(v);
    if (++count == 4) {
      out.bytes += char(bits >> 16);
      out.bytes += char(bits >> 8);
      out.bytes += char(bits);
      bits = 0;
      count = 0;
    }
  }
  if (count == 1) return std::nullopt;
  if (count >= 2) out.bytes += char(bits >> (6 * count - 8));
  if (count == 3) out.bytes += char(bits >> 2);
  return out;
}

std::string encode_data_uri(std::string_view mime_type, std::string_view bytes) {
  std::string out = "data:" + std::string(mime_type) + ";base64,";
  out.reserve(out.size() + (bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t n = uint32_t(uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) n |= uint32_t(uint8_t(bytes[i + 1])) << 8;
    if (i + 2 < bytes.size()) n |= uint8_t(bytes[i + 2]);
    out += kDigits[n >> 18];
    out += kDigits[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? kDigits[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[n & 63] : '=';
  }
  return out;
}

}  // namespace specdeform::detail
