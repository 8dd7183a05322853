#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <unordered_map>

#include "polygon_soup.h"
#include "text_scanner.h"

namespace specdeform::detail {

namespace {

struct PointHash {
  size_t operator()(const std::array<double, 3>& p) const {
    size_t h = 0;
    for (const double v : p) {
      uint64_t bits;
      std::memcpy(&bits, &v, sizeof bits);
      h ^= std::hash<uint64_t>{}(bits) + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
    }
    return h;
  }
};

// Merges exactly coincident corners into one vertex.
class Welder {
 public:
  explicit Welder(PolygonSoup& soup) : soup_(soup) {}
  void add_corner(double x, double y, double z) {
    // Adding +0.0 turns -0.0 into +0.0, so the two zeros weld.
    const std::array<double, 3> p{x + 0.0, y + 0.0, z + 0.0};
    const auto [it, inserted] = index_.try_emplace(p, soup_.num_vertices());
    if (inserted) {
      soup_.xyz.insert(soup_.xyz.end(), p.begin(), p.end());
    } else {
      ++soup_.welded_corners;
    }
    soup_.add_polygon_corner(it->second);
  }

 private:
  PolygonSoup& soup_;
  std::unordered_map<std::array<double, 3>, int, PointHash> index_;
};

PolygonSoup parse_binary(std::string_view data, const std::string& name) {
  uint32_t count = 0;
  std::memcpy(&count, data.data() + 80, 4);
  const uint64_t expected = 84 + 50 * uint64_t{count};
  if (data.size() < expected) {
    throw InputError(name + ": truncated binary STL (" + std::to_string(count) +
                     " triangles announced, " + std::to_string((data.size() - 84) / 50) +
                     " present)");
  }
  if (count == 0) throw InputError(name + ": no faces (binary STL with 0 triangles)");
  PolygonSoup soup;
  Welder welder(soup);
  for (uint32_t t = 0; t < count; ++t) {
    const char* rec = data.data() + 84 + 50 * size_t{t} + 12;  // skip the normal
    for (int c = 0; c < 3; ++c) {
      float p[3];
      std::memcpy(p, rec + 12 * c, 12);
      welder.add_corner(p[0], p[1], p[2]);
    }
    soup.end_polygon();
  }
  return soup;
}

PolygonSoup parse_ascii(std::string_view data, const std::string& name) {
  TextScanner in(data, name);
  PolygonSoup soup;
  Welder welder(soup);
  bool in_loop = false;
  for (std::string_view t = in.next(false); !t.empty(); t = in.next(false)) {
    if (t == "solid" || t == "endsolid") {
      in.skip_line();  // the solid's name
    } else if (t == "outer") {
      in_loop = true;
    } else if (t == "vertex") {
      if (!in_loop) in.fail("'vertex' outside an 'outer loop'");
      const double x = in.next_double("a vertex");
      const double y = in.next_double("a vertex");
      const double z = in.next_double("a vertex");
      welder.add_corner(x, y, z);
    } else if (t == "endloop") {
      if (!in_loop) in.fail("'endloop' without 'outer loop'");
      soup.end_polygon();
      in_loop = false;
    }
  }
  if (in_loop) in.fail("truncated ASCII STL (unterminated loop)");
  if (soup.num_polygons() == 0) in.fail("no faces");
  return soup;
}

}  // namespace

PolygonSoup parse_stl(std::string_view data, const std::string& name) {
  if (data.empty()) throw InputError(name + ": empty file");
  const size_t first = data.find_first_not_of(" \t\r\n");
  const bool says_solid =
      first != std::string_view::npos && data.substr(first).starts_with("solid");
  if (data.size() >= 84) {
    uint32_t count = 0;
    std::memcpy(&count, data.data() + 80, 4);
    const bool sized_as_binary = data.size() == 84 + 50 * uint64_t{count};
    // Many binary files begin their free-form header with "solid"; the size decides.
    if (sized_as_binary || !says_solid) return parse_binary(data, name);
  }
  if (!says_solid) throw InputError(name + ": too short for a binary STL and not ASCII STL");
  return parse_ascii(data, name);
}

}  // namespace specdeform::detail
