#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include "mesh/polygon_soup.h"
#include "mesh/text_scanner.h"
#include "stl.h"

namespace specdeform::detail {

namespace {

// Merges exactly coincident corners into one vertex; a NaN or infinite coordinate stops the
// reading at once, naming its triangle (a garbage file is not read to its end first).
class Welder {
 public:
  Welder(PolygonSoup& soup, const std::string& name) : soup_(soup), name_(name) {}
  void add_corner(double x, double y, double z) {
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
      throw InputError(name_ + ": triangle " + std::to_string(soup_.num_polygons()) +
                       " has a NaN or infinite coordinate");
    }
    const int v = soup_.num_vertices();
    soup_.xyz.insert(soup_.xyz.end(), {x + 0.0, y + 0.0, z + 0.0});  // -0.0 as +0.0
    const int first = index_.first_at(v);
    if (first != v) {
      soup_.xyz.resize(3 * size_t(v));
      ++soup_.welded_corners;
    }
    soup_.add_polygon_corner(first);
  }

 private:
  PolygonSoup& soup_;
  const std::string& name_;
  PositionIndex index_{soup_.xyz};
};

PolygonSoup parse_binary(std::string_view data, const std::string& name, KeptRecord* keep) {
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
  Welder welder(soup, name);
  if (keep) keep->attributes.normals.resize(count, 3);
  for (uint32_t t = 0; t < count; ++t) {
    const char* rec = data.data() + 84 + 50 * size_t{t};
    float p[12];  // the normal, then the corners
    std::memcpy(p, rec, sizeof p);
    for (int c = 1; c <= 3; ++c) welder.add_corner(p[3 * c], p[3 * c + 1], p[3 * c + 2]);
    soup.end_polygon();
    if (keep) keep->attributes.normals.row(t) << p[0], p[1], p[2];
  }
  if (keep) keep->layout.format = StlLayout{};
  return soup;
}

PolygonSoup parse_ascii(std::string_view data, const std::string& name, KeptRecord* keep) {
  TextScanner in(data, name);
  PolygonSoup soup;
  Welder welder(soup, name);
  bool in_loop = false;
  StlLayout layout;
  layout.ascii = true;
  std::vector<double> normals;  // 3 per facet
  // The offset of the next token, which the scanner is about to read.
  const auto next_offset = [&] {
    const size_t at = in.position();
    const std::string_view t = in.next(false);
    in.set_position(at);
    return size_t(t.data() - data.data());
  };
  for (std::string_view t = in.next(false); !t.empty(); t = in.next(false)) {
    if (t == "solid" || t == "endsolid") {
      in.skip_line();  // the solid's name
    } else if (keep && t == "normal") {
      layout.facet_normal.push_back(next_offset());
      for (int k = 0; k < 3; ++k) normals.push_back(in.next_double("a facet normal"));
    } else if (t == "outer") {
      in_loop = true;
    } else if (t == "vertex") {
      if (!in_loop) in.fail("'vertex' outside an 'outer loop'");
      if (keep) layout.corner.push_back(next_offset());
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
  if (keep) {
    if (layout.facet_normal.size() != size_t(soup.num_polygons())) {
      in.fail("a facet without a normal");
    }
    keep->attributes.normals =
        Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(
            normals.data(), soup.num_polygons(), 3);
    keep->layout.format = std::move(layout);
  }
  return soup;
}

PolygonSoup parse_stl_soup(std::string_view data, const std::string& name, KeptRecord* keep) {
  if (data.empty()) throw InputError(name + ": empty file");
  const size_t first = data.find_first_not_of(" \t\r\n");
  const bool says_solid =
      first != std::string_view::npos && data.substr(first).starts_with("solid");
  if (data.size() >= 84) {
    uint32_t count = 0;
    std::memcpy(&count, data.data() + 80, 4);
    const bool sized_as_binary = data.size() == 84 + 50 * uint64_t{count};
    // Many binary files begin their free-form header with "solid"; the size decides.
    if (sized_as_binary || !says_solid) return parse_binary(data, name, keep);
  }
  if (!says_solid) throw InputError(name + ": too short for a binary STL and not ASCII STL");
  return parse_ascii(data, name, keep);
}

}  // namespace

void check_stl_start(std::string_view start, uint64_t size, const std::string& name) {
  if (start.size() < 84) return;
  uint32_t count = 0;
  std::memcpy(&count, start.data() + 80, 4);
  const size_t first = start.find_first_not_of(" \t\r\n");
  const bool says_solid =
      first != std::string_view::npos && start.substr(first).starts_with("solid");
  if (says_solid && size != 84 + 50 * uint64_t{count}) return;  // ASCII
  const uint64_t whole = std::min<uint64_t>(count, (start.size() - 84) / 50);
  for (uint64_t t = 0; t < whole; ++t) {
    float p[12];
    std::memcpy(p, start.data() + 84 + 50 * t, sizeof p);
    for (int k = 3; k < 12; ++k) {
      if (!std::isfinite(p[k])) {
        throw InputError(name + ": triangle " + std::to_string(t) +
                         " has a NaN or infinite coordinate");
      }
    }
  }
}

PolygonSoup parse_stl(std::string_view data, const std::string& name, KeptRecord* keep) {
  PolygonSoup soup = parse_stl_soup(data, name, keep);
  if (keep) {
    // The facet normals, one row a facet.
    std::vector<int>& normal = keep->attributes.corner_normal;
    for (int p = 0; p < soup.num_polygons(); ++p) normal.resize(soup.offsets[p + 1], p);
    keep->layout.bytes.assign(data);
  }
  return soup;
}

}  // namespace specdeform::detail
