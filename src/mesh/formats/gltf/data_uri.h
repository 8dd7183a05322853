// Internal: RFC 2397 data URIs with base64 payloads, as glTF embeds buffers and images
// ("data:application/octet-stream;base64,...").
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace specdeform::detail {

bool is_data_uri(std::string_view uri);

struct DataUri {
  std::string mime_type;  // as written ("image/png"); empty when the URI names none
  std::string bytes;
};
// nullopt for a URI that is not base64 data or whose payload is not base64.
std::optional<DataUri> decode_data_uri(std::string_view uri);

// "data:<mime_type>;base64,<bytes in base64>".
std::string encode_data_uri(std::string_view mime_type, std::string_view bytes);

}  // namespace specdeform::detail
