#include <string>

#include "polygon_soup.h"
#include "text_scanner.h"

namespace specdeform::detail {

namespace {

// OFF header keywords: [ST][C][N]OFF. The 4D and n-dimensional variants are not surfaces in 3D.
bool is_off_keyword(std::string_view t) {
  if (t.size() < 3 || t.substr(t.size() - 3) != "OFF") return false;
  std::string_view prefix = t.substr(0, t.size() - 3);
  if (prefix.starts_with("ST")) prefix.remove_prefix(2);
  if (prefix.starts_with("C")) prefix.remove_prefix(1);
  if (prefix.starts_with("N")) prefix.remove_prefix(1);
  return prefix.empty();
}

}  // namespace

PolygonSoup parse_off(std::string_view data, const std::string& name) {
  TextScanner in(data, name);
  const size_t start = in.position();
  const std::string_view first = in.next();
  if (first.empty()) in.fail("empty file");
  if (first.ends_with("OFF") && !is_off_keyword(first)) {
    in.fail("unsupported OFF variant '" + std::string(first) + "' (only 3D OFF is read)");
  }
  if (is_off_keyword(first)) {
    if (!in.at_line_end()) {
      const size_t after = in.position();
      if (in.next() == "BINARY") in.fail("binary OFF is not supported");
      in.set_position(after);
    }
  } else {
    in.set_position(start);  // a headerless OFF starts with the counts
  }
  const long long nv = in.next_integer("the vertex count");
  const long long nf = in.next_integer("the face count");
  if (!in.at_line_end()) in.next_integer("the edge count");
  in.skip_line();
  if (nv < 0 || nf < 0) in.fail("negative vertex or face count");
  if (nv == 0) in.fail("no vertices");
  if (nf == 0) in.fail("no faces (a point cloud is not a surface)");
  // Every vertex needs at least 6 bytes of text ("0 0 0\n"); larger counts are lies.
  if (nv > static_cast<long long>(data.size()) || nf > static_cast<long long>(data.size())) {
    in.fail("the header announces more vertices or faces than the file can hold");
  }

  PolygonSoup soup;
  soup.xyz.reserve(3 * nv);
  for (long long i = 0; i < nv; ++i) {
    for (int k = 0; k < 3; ++k) soup.xyz.push_back(in.next_double("vertex coordinates"));
    in.skip_line();
  }
  for (long long f = 0; f < nf; ++f) {
    const long long k = in.next_integer("a face");
    if (k < 0 || k > nv) in.fail("face " + std::to_string(f) + " has a bad corner count");
    for (long long c = 0; c < k; ++c) {
      const long long v = in.next_integer("face indices");
      if (v < 0 || v >= nv) {
        in.fail("face " + std::to_string(f) + " references vertex " + std::to_string(v) +
                " but there are " + std::to_string(nv) + " vertices");
      }
      soup.add_polygon_corner(static_cast<int>(v));
    }
    soup.end_polygon();
    in.skip_line();
  }
  return soup;
}

}  // namespace specdeform::detail
