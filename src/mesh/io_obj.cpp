#include <string>

#include "linalg/parallel.h"
#include "polygon_soup.h"
#include "text_scanner.h"

namespace specdeform::detail {

namespace {

// Joins lines ending in a backslash (OBJ line continuation) into one.
std::string join_continued_lines(std::string_view data) {
  std::string out;
  out.reserve(data.size());
  for (size_t i = 0; i < data.size(); ++i) {
    if (data[i] == '\\') {
      size_t j = i + 1;
      while (j < data.size() && (data[j] == ' ' || data[j] == '\t' || data[j] == '\r')) ++j;
      if (j == data.size() || data[j] == '\n') {
        out += ' ';
        i = j;
        continue;
      }
    }
    out += data[i];
  }
  return out;
}

// The vertex lines ("v x y z ...") of the data.
int count_vertex_lines(std::string_view data) {
  int count = 0;
  for (size_t line = 0; line < data.size();) {
    size_t i = line;
    while (i < data.size() && (data[i] == ' ' || data[i] == '\t')) ++i;
    if (i + 1 < data.size() && data[i] == 'v' && (data[i + 1] == ' ' || data[i + 1] == '\t')) {
      ++count;
    }
    const size_t end = data.find('\n', i);
    line = end == std::string_view::npos ? data.size() : end + 1;
  }
  return count;
}

// The soup of whole lines of a file, after `preceding` vertices of earlier lines (the indices
// come out numbered in the whole file).
PolygonSoup parse_lines(std::string_view data, const std::string& name, int preceding) {
  TextScanner in(data, name);
  PolygonSoup soup;
  std::vector<int> corners;
  int line_faces = 0;
  for (std::string_view key = in.next(); !key.empty(); key = in.next()) {
    if (key == "v") {
      for (int k = 0; k < 3; ++k) soup.xyz.push_back(in.next_double("a vertex"));
    } else if (key == "f") {
      // Corners are v, v/vt, v//vn or v/vt/vn (also "v/vt/"); only v matters. Negative indices
      // count back from the last vertex read so far.
      corners.clear();
      while (!in.at_line_end()) {
        const std::string_view corner = in.next();
        const std::string_view v = corner.substr(0, corner.find('/'));
        long long index = 0;
        const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), index);
        if (ec != std::errc() || end != v.data() + v.size() || index == 0) {
          in.fail("bad face corner '" + std::string(corner.substr(0, 32)) + "' in face " +
                  std::to_string(line_faces));
        }
        const long long nv = preceding + soup.num_vertices();
        const long long zero_based = index > 0 ? index - 1 : nv + index;
        if (zero_based < 0 || zero_based >= nv) {
          in.fail("face " + std::to_string(line_faces) + " references vertex " +
                  std::to_string(index) + " but only " + std::to_string(nv) +
                  " vertices precede it");
        }
        corners.push_back(static_cast<int>(zero_based));
      }
      if (corners.size() < 3) {
        if (in.position() == data.size() && !data.ends_with('\n')) {
          in.fail("truncated: the file ends inside face " + std::to_string(line_faces));
        }
        in.fail("face " + std::to_string(line_faces) + " has " + std::to_string(corners.size()) +
                " corners (a face needs 3 or more)");
      }
      for (const int c : corners) soup.add_polygon_corner(c);
      soup.end_polygon();
      ++line_faces;
    }
    in.skip_line();  // vt, vn, g, o, s, usemtl, mtllib, l, p, and the rest of a v line (colours)
  }
  return soup;
}

}  // namespace

// A large file is read in two halves at once, split at a line: the second half counts the
// first's vertex lines before its own (for its indices); a failure in either is reported by
// reading the file again from the start, whose message then names the face as a single pass
// does (692k vertices: 0.20 -> 0.12 s).
PolygonSoup parse_obj(std::string_view raw, const std::string& name) {
  constexpr size_t kSplitFrom = 8 << 20;  // bytes
  const std::string joined = raw.find('\\') == std::string_view::npos
                                 ? std::string()
                                 : join_continued_lines(raw);  // most files have none
  const std::string_view data = joined.empty() ? raw : joined;
  const size_t split =
      data.size() < kSplitFrom ? std::string_view::npos : data.find('\n', data.size() / 2);
  PolygonSoup soup;
  if (split == std::string_view::npos) {
    soup = parse_lines(data, name, 0);
  } else {
    PolygonSoup second;
    bool failed = false;
    try {
      run_pair([&] { soup = parse_lines(data.substr(0, split + 1), name, 0); },
               [&] {
                 second = parse_lines(data.substr(split + 1), name,
                                      count_vertex_lines(data.substr(0, split + 1)));
               });
    } catch (const InputError&) {
      failed = true;
    }
    if (failed) return parse_lines(data, name, 0);  // throws, naming the face
    const int offset = static_cast<int>(soup.indices.size());
    soup.xyz.insert(soup.xyz.end(), second.xyz.begin(), second.xyz.end());
    soup.indices.insert(soup.indices.end(), second.indices.begin(), second.indices.end());
    for (size_t p = 1; p < second.offsets.size(); ++p)
      soup.offsets.push_back(offset + second.offsets[p]);
  }
  if (soup.num_vertices() == 0 && soup.num_polygons() == 0) {
    TextScanner(data, name).fail("empty file (no vertices)");
  }
  return soup;
}

}  // namespace specdeform::detail
