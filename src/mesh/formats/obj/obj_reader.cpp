#include <algorithm>
#include <array>
#include <map>
#include <string>
#include <vector>

#include "linalg/parallel.h"
#include "mesh/polygon_soup.h"
#include "mesh/text_scanner.h"
#include "obj.h"

namespace specdeform::detail {

namespace {

// Lines ending in a backslash (OBJ line continuation) joined into one: the text, and where
// each join put its blank (an offset in `text`) with the raw bytes it replaced.
struct JoinedLines {
  std::string text;
  std::vector<size_t> at, replaced;
};

JoinedLines join_continued_lines(std::string_view data) {
  JoinedLines out;
  out.text.reserve(data.size());
  for (size_t i = 0; i < data.size(); ++i) {
    if (data[i] == '\\') {
      size_t j = i + 1;
      while (j < data.size() && (data[j] == ' ' || data[j] == '\t' || data[j] == '\r')) ++j;
      if (j == data.size() || data[j] == '\n') {
        out.at.push_back(out.text.size());
        out.replaced.push_back(std::min(j + 1, data.size()) - i);
        out.text += ' ';
        i = j;
        continue;
      }
    }
    out.text += data[i];
  }
  return out;
}

// Whether a join falls on a v or vn line (whose numbers a rewrite replaces).
bool joins_a_vertex_line(const JoinedLines& joined) {
  for (const size_t at : joined.at) {
    const size_t newline = joined.text.rfind('\n', at);
    std::string_view line =
        std::string_view(joined.text).substr(newline == std::string::npos ? 0 : newline + 1);
    while (!line.empty() && (line.front() == ' ' || line.front() == '\t')) line.remove_prefix(1);
    if (line.starts_with("v ") || line.starts_with("v\t") || line.starts_with("vn")) return true;
  }
  return false;
}

// The offsets of the joined text moved to the raw bytes' (`offsets` ascending).
void to_raw_offsets(const JoinedLines& joined, std::vector<size_t>& offsets) {
  size_t k = 0, shift = 0;
  for (size_t& o : offsets) {
    for (; k < joined.at.size() && joined.at[k] < o; ++k) shift += joined.replaced[k] - 1;
    o += shift;
  }
}

// The v, vt and vn lines of a part of the file.
struct LineCounts {
  int v = 0, vt = 0, vn = 0;
};

LineCounts count_lines(std::string_view data) {
  LineCounts count;
  for (size_t line = 0; line < data.size();) {
    size_t i = line;
    while (i < data.size() && (data[i] == ' ' || data[i] == '\t')) ++i;
    if (i + 1 < data.size() && data[i] == 'v') {
      const char next = data[i + 1];
      const bool blank_after = i + 2 < data.size() && (data[i + 2] == ' ' || data[i + 2] == '\t');
      if (next == ' ' || next == '\t') {
        ++count.v;
      } else if (next == 't' && blank_after) {
        ++count.vt;
      } else if (next == 'n' && blank_after) {
        ++count.vn;
      }
    }
    const size_t end = data.find('\n', i);
    line = end == std::string_view::npos ? data.size() : end + 1;
  }
  return count;
}

constexpr int kInherit = -2;  // a polygon before its part's first usemtl: the material in force

// What one part of the file keeps (ReadOptions::keep_file).
struct ObjRecord {
  std::vector<size_t> v, vn;                  // offsets in the part, after the keyword
  std::vector<std::array<float, 4>> colour;   // per v line, from the first coloured one on
  std::vector<double> uv, normal;             // 2 per vt, 3 per vn
  std::vector<int> corner_uv, corner_normal;  // numbered in the whole file (-1: none)
  std::vector<int> material;                  // per polygon, into `materials`; -1 none, kInherit
  std::vector<std::string> materials, mtllib;
  int current = kInherit, groups = 0;
  bool has_uv = false, has_normal = false;
};

// The rest of the line from the scanner's position, without surrounding blanks.
std::string_view rest_of_line(std::string_view data, size_t pos) {
  size_t end = data.find('\n', pos);
  if (end == std::string_view::npos) end = data.size();
  std::string_view s = data.substr(pos, end - pos);
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

// A corner's index `text` (1-based, or negative: back from the last of `count` so far) as a
// 0-based one; fails naming `what` for anything else.
int corner_index(const TextScanner& in, std::string_view text, long long count, const char* what,
                 const char* whats, std::string_view corner, int face) {
  long long index = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), index);
  if (ec != std::errc() || end != text.data() + text.size() || index == 0) {
    in.fail("bad face corner '" + std::string(corner.substr(0, 32)) + "' in face " +
            std::to_string(face));
  }
  const long long zero_based = index > 0 ? index - 1 : count + index;
  if (zero_based < 0 || zero_based >= count) {
    in.fail("face " + std::to_string(face) + " references " + what + " " + std::to_string(index) +
            " but only " + std::to_string(count) + " " + whats + " precede it");
  }
  return static_cast<int>(zero_based);
}

// The soup of whole lines of a file, after `preceding` lines of earlier parts (the indices come
// out numbered in the whole file).
PolygonSoup parse_lines(std::string_view data, const std::string& name, LineCounts preceding,
                        ObjRecord* keep) {
  TextScanner in(data, name);
  PolygonSoup soup;
  std::vector<int> corners;
  int line_faces = 0;
  for (std::string_view key = in.next(); !key.empty(); key = in.next()) {
    if (key == "v") {
      if (keep) keep->v.push_back(in.position());
      for (int k = 0; k < 3; ++k) soup.xyz.push_back(in.next_double("a vertex"));
      if (keep && (!keep->colour.empty() || !in.at_line_end())) {
        std::array<float, 4> rgba{1, 1, 1, 1};
        int extra = 0;
        for (; extra < 5 && !in.at_line_end(); ++extra) {
          const double c = in.next_double("a vertex colour");
          if (extra < 4) rgba[extra] = static_cast<float>(c);
        }
        const bool coloured = extra == 3 || extra == 4;
        if (coloured && keep->colour.empty()) keep->colour.resize(keep->v.size() - 1, {1, 1, 1, 1});
        if (!keep->colour.empty())
          keep->colour.push_back(coloured ? rgba : std::array{1.f, 1.f, 1.f, 1.f});
      }
    } else if (keep && key == "vt") {
      const double u = in.next_double("a texture coordinate");
      const double v = in.at_line_end() ? 0.0 : in.next_double("a texture coordinate");
      keep->uv.insert(keep->uv.end(), {u, v});
    } else if (keep && key == "vn") {
      keep->vn.push_back(in.position());
      for (int k = 0; k < 3; ++k) keep->normal.push_back(in.next_double("a normal"));
    } else if (key == "f") {
      // Corners are v, v/vt, v//vn or v/vt/vn (also "v/vt/"). Negative indices count back from
      // the last one read so far.
      corners.clear();
      const int v_count = preceding.v + soup.num_vertices();
      while (!in.at_line_end()) {
        const std::string_view corner = in.next();
        const size_t slash = corner.find('/');
        corners.push_back(corner_index(in, corner.substr(0, slash), v_count, "vertex", "vertices",
                                       corner, line_faces));
        if (!keep) continue;
        int uv = -1, normal = -1;
        if (slash != std::string_view::npos) {
          const std::string_view rest = corner.substr(slash + 1);
          const size_t second = rest.find('/');
          const std::string_view t = rest.substr(0, second);
          if (!t.empty()) {
            uv = corner_index(in, t, preceding.vt + long(keep->uv.size() / 2), "texture coordinate",
                              "texture coordinates", corner, line_faces);
            keep->has_uv = true;
          }
          if (second != std::string_view::npos && second + 1 < rest.size()) {
            normal = corner_index(in, rest.substr(second + 1),
                                  preceding.vn + long(keep->normal.size() / 3), "normal", "normals",
                                  corner, line_faces);
            keep->has_normal = true;
          }
        }
        keep->corner_uv.push_back(uv);
        keep->corner_normal.push_back(normal);
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
      if (keep) keep->material.push_back(keep->current);
      ++line_faces;
    } else if (keep && key == "usemtl") {
      const std::string material(rest_of_line(data, in.position()));
      const auto found = std::find(keep->materials.begin(), keep->materials.end(), material);
      keep->current = static_cast<int>(found - keep->materials.begin());
      if (found == keep->materials.end()) keep->materials.push_back(material);
    } else if (keep && key == "mtllib") {
      keep->mtllib.emplace_back(rest_of_line(data, in.position()));
    } else if (keep && (key == "g" || key == "o")) {
      ++keep->groups;
    }
    in.skip_line();  // the rest of a v line (colours), s, l, p, and whatever else
  }
  return soup;
}

// The second part's record appended to the first's: offsets moved by `shift` bytes, its
// materials renumbered into the first's, its polygons before its first usemtl given the
// first's material in force.
void append_record(ObjRecord& a, ObjRecord&& b, size_t shift) {
  for (size_t& o : b.v) o += shift;
  for (size_t& o : b.vn) o += shift;
  a.v.insert(a.v.end(), b.v.begin(), b.v.end());
  a.vn.insert(a.vn.end(), b.vn.begin(), b.vn.end());
  if (!a.colour.empty() || !b.colour.empty()) {
    a.colour.resize(a.v.size() - b.v.size(), {1, 1, 1, 1});
    b.colour.resize(b.v.size(), {1, 1, 1, 1});
    a.colour.insert(a.colour.end(), b.colour.begin(), b.colour.end());
  }
  a.uv.insert(a.uv.end(), b.uv.begin(), b.uv.end());
  a.normal.insert(a.normal.end(), b.normal.begin(), b.normal.end());
  a.corner_uv.insert(a.corner_uv.end(), b.corner_uv.begin(), b.corner_uv.end());
  a.corner_normal.insert(a.corner_normal.end(), b.corner_normal.begin(), b.corner_normal.end());
  std::vector<int> renumber;
  for (const std::string& m : b.materials) {
    const auto found = std::find(a.materials.begin(), a.materials.end(), m);
    renumber.push_back(static_cast<int>(found - a.materials.begin()));
    if (found == a.materials.end()) a.materials.push_back(m);
  }
  for (const int m : b.material) a.material.push_back(m == kInherit ? a.current : renumber[m]);
  if (b.current != kInherit) a.current = renumber[b.current];
  a.mtllib.insert(a.mtllib.end(), b.mtllib.begin(), b.mtllib.end());
  a.groups += b.groups;
  a.has_uv |= b.has_uv;
  a.has_normal |= b.has_normal;
}

void merge_halves(PolygonSoup& soup, PolygonSoup&& second) {
  const int offset = static_cast<int>(soup.indices.size());
  soup.xyz.insert(soup.xyz.end(), second.xyz.begin(), second.xyz.end());
  soup.indices.insert(soup.indices.end(), second.indices.begin(), second.indices.end());
  for (size_t p = 1; p < second.offsets.size(); ++p)
    soup.offsets.push_back(offset + second.offsets[p]);
}

void keep_record(ObjRecord&& r, std::string_view data, KeptRecord& keep) {
  keep.layout.bytes.assign(data);
  FileAttributes& a = keep.attributes;
  if (r.has_uv) {
    a.uv = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>(
        r.uv.data(), Eigen::Index(r.uv.size() / 2), 2);
    a.corner_uv = std::move(r.corner_uv);
  }
  if (r.has_normal) {
    a.normals = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(
        r.normal.data(), Eigen::Index(r.normal.size() / 3), 3);
    a.corner_normal = std::move(r.corner_normal);
  }
  if (!r.colour.empty()) {
    a.colours.resize(Eigen::Index(r.colour.size()), 4);
    for (size_t i = 0; i < r.colour.size(); ++i)
      for (int k = 0; k < 4; ++k) a.colours(Eigen::Index(i), k) = r.colour[i][k];
  }
  if (!r.materials.empty()) {
    for (std::string& m : r.materials) {
      Material material;
      material.name = std::move(m);
      a.materials.push_back(std::move(material));
    }
    a.polygon_material = std::move(r.material);
    for (int& m : a.polygon_material) m = std::max(m, -1);  // before any usemtl: none
  }
  keep.layout.format =
      ObjLayout{std::move(r.v), std::move(r.vn), std::move(r.mtllib), r.groups, {}};
}

}  // namespace

// A large file is read in two halves at once, split at a line: the second half counts the
// first's v, vt and vn lines before its own (for its indices); a failure in either is reported by
// reading the file again from the start, whose message then names the face as a single pass
// does (692k vertices: 0.20 -> 0.12 s). A kept file keeps its line continuations, but where one
// splits a v or vn line (the rewrite then writes that line joined).
PolygonSoup parse_obj(std::string_view raw, const std::string& name, KeptRecord* keep) {
  constexpr size_t kSplitFrom = 8 << 20;  // bytes
  const JoinedLines joined = raw.find('\\') == std::string_view::npos
                                 ? JoinedLines()
                                 : join_continued_lines(raw);  // most files have none
  const std::string_view data = joined.at.empty() ? raw : std::string_view(joined.text);
  const size_t split =
      data.size() < kSplitFrom ? std::string_view::npos : data.find('\n', data.size() / 2);
  PolygonSoup soup;
  ObjRecord first, second_record;
  if (split == std::string_view::npos) {
    soup = parse_lines(data, name, {}, keep ? &first : nullptr);
  } else {
    PolygonSoup second;
    bool failed = false;
    try {
      run_pair(
          [&] { soup = parse_lines(data.substr(0, split + 1), name, {}, keep ? &first : nullptr); },
          [&] {
            second =
                parse_lines(data.substr(split + 1), name, count_lines(data.substr(0, split + 1)),
                            keep ? &second_record : nullptr);
          });
    } catch (const InputError&) {
      failed = true;
    }
    if (failed) {  // throws, naming the face
      first = ObjRecord();
      soup = parse_lines(data, name, {}, keep ? &first : nullptr);
    } else {
      merge_halves(soup, std::move(second));
      if (keep) append_record(first, std::move(second_record), split + 1);
    }
  }
  if (soup.num_vertices() == 0 && soup.num_polygons() == 0) {
    TextScanner(data, name).fail("empty file (no vertices)");
  }
  if (keep && !joined.at.empty() && !joins_a_vertex_line(joined)) {
    to_raw_offsets(joined, first.v);
    to_raw_offsets(joined, first.vn);
    keep_record(std::move(first), raw, *keep);
  } else if (keep) {
    keep_record(std::move(first), data, *keep);
  }
  // Some exporters (trimesh, scanners) write a position once per texture coordinate or normal
  // instead of indexing them apart: copies at one place are one vertex, or the seams open.
  soup.weld = weld_coincident(soup.xyz);
  return soup;
}

}  // namespace specdeform::detail
