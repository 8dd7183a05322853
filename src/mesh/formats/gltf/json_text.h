// Internal: a JSON document edited as text, so that what did not change keeps its bytes (a .gltf
// checked into version control diffs only where its numbers changed).
//
// patch_json_text(text, before, after): `before` is `text` parsed (in its key order); the result
// is `text` with every value where `after` differs from `before` written anew, and nothing else
// touched: members and elements that are equal keep their text (spacing, number spelling,
// escapes); changed scalars are replaced in place; members `after` adds go at the end of their
// object and elements at the end of their array, laid out as their neighbours are (one per line
// with their indentation, or compact where the container is compact); members and elements
// `after` lacks are removed with their separators. A new number is written as the shortest text
// that reads back to it, as float32 where it is a float32 value (the min and max of float
// accessors), else as double. Throws std::logic_error where `text` is not `before`.
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace specdeform::detail {

using Json = nlohmann::ordered_json;

std::string patch_json_text(std::string_view text, const Json& before, const Json& after);

}  // namespace specdeform::detail
