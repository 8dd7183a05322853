#include <string>

#include "mesh/polygon_soup.h"
#include "mesh/text_scanner.h"
#include "off.h"

namespace specdeform::detail {

namespace {

// OFF header keywords: [ST][C][N]OFF. The 4D and n-dimensional variants are not surfaces in 3D.
struct OffHeader {
  bool uv = false, colour = false, normal = false;
};

bool parse_off_keyword(std::string_view t, OffHeader& header) {
  if (t.size() < 3 || t.substr(t.size() - 3) != "OFF") return false;
  std::string_view prefix = t.substr(0, t.size() - 3);
  header.uv = prefix.starts_with("ST");
  if (header.uv) prefix.remove_prefix(2);
  header.colour = prefix.starts_with("C");
  if (header.colour) prefix.remove_prefix(1);
  header.normal = prefix.starts_with("N");
  if (header.normal) prefix.remove_prefix(1);
  return prefix.empty();
}

// A vertex line's values after x y z, as the header announces them (kept files only).
void keep_vertex_extras(TextScanner& in, const OffHeader& header, long long i, FileAttributes& a) {
  double value[9];
  int count = 0;
  while (count < 9 && !in.at_line_end()) value[count++] = in.next_double("vertex values");
  int at = 0;
  if (header.normal && count >= 3) {
    a.normals.row(i) << value[0], value[1], value[2];
    at = 3;
  }
  const int colour_end = header.uv ? count - 2 : count;
  if (header.colour && colour_end - at >= 3) {
    const bool bytes = value[at] > 1 || value[at + 1] > 1 || value[at + 2] > 1;
    for (int k = 0; k < 4 && at + k < colour_end; ++k)
      a.colours(i, k) = static_cast<float>(bytes ? value[at + k] / 255.0 : value[at + k]);
  }
  if (header.uv && count - at >= 2) a.uv.row(i) << value[count - 2], value[count - 1];
}

}  // namespace

PolygonSoup parse_off(std::string_view data, const std::string& name, KeptRecord* keep) {
  TextScanner in(data, name);
  const size_t start = in.position();
  const std::string_view first = in.next();
  if (first.empty()) in.fail("empty file");
  OffHeader header;
  const bool keyword = parse_off_keyword(first, header);
  if (first.ends_with("OFF") && !keyword) {
    in.fail("unsupported OFF variant '" + std::string(first) + "' (only 3D OFF is read)");
  }
  if (keyword) {
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
  OffLayout layout;
  layout.normals = header.normal;
  if (keep) {
    FileAttributes& a = keep->attributes;
    layout.vertex.reserve(nv);
    if (header.normal) a.normals.setZero(nv, 3);
    if (header.colour) a.colours.setOnes(nv, 4);
    if (header.uv) a.uv.setZero(nv, 2);
  }
  for (long long i = 0; i < nv; ++i) {
    for (int k = 0; k < 3; ++k) {
      const std::string_view t = in.next();
      if (keep && k == 0) layout.vertex.push_back(size_t(t.data() - data.data()));
      soup.xyz.push_back(in.to_double(t, "vertex coordinates"));
    }
    if (keep) keep_vertex_extras(in, header, i, keep->attributes);
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
    in.skip_line();  // a face's colour
  }
  if (keep) {
    FileAttributes& a = keep->attributes;
    // Normals and texture coordinates are per vertex: each corner uses its vertex's row.
    if (header.normal) a.corner_normal = soup.indices;
    if (header.uv) a.corner_uv = soup.indices;
    keep->layout.bytes.assign(data);
    keep->layout.format = std::move(layout);
  }
  return soup;
}

}  // namespace specdeform::detail
