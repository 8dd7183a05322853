#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <string>
#include <vector>

#include "mesh/polygon_soup.h"
#include "mesh/text_scanner.h"
#include "ply.h"

namespace specdeform::detail {

namespace {

using Scalar = PlyScalar;
using Property = PlyProperty;
using Element = PlyElement;

// A value as the file holds it, for an error message: it may be 1.5, 1e300 or nan.
std::string as_read(double v) {
  char text[32];
  const auto [end, ec] = std::to_chars(text, text + sizeof text, v);
  return std::string(text, end);
}

bool parse_scalar(std::string_view t, Scalar& out) {
  static constexpr std::pair<std::string_view, Scalar> kNames[] = {
      {"char", Scalar::I8},    {"int8", Scalar::I8},     {"uchar", Scalar::U8},
      {"uint8", Scalar::U8},   {"short", Scalar::I16},   {"int16", Scalar::I16},
      {"ushort", Scalar::U16}, {"uint16", Scalar::U16},  {"int", Scalar::I32},
      {"int32", Scalar::I32},  {"uint", Scalar::U32},    {"uint32", Scalar::U32},
      {"float", Scalar::F32},  {"float32", Scalar::F32}, {"double", Scalar::F64},
      {"float64", Scalar::F64}};
  for (const auto& [n, s] : kNames) {
    if (t == n) {
      out = s;
      return true;
    }
  }
  return false;
}

// Reads the body's values one at a time, whatever the encoding.
class BodyReader {
 public:
  using Encoding = PlyEncoding;

  BodyReader(std::string_view body, Encoding enc, const std::string& name)
      : body_(body), enc_(enc), text_(body, name), name_(name) {}

  double read(Scalar s, const char* what) {
    if (enc_ == Encoding::Ascii) return text_.next_double(what);
    const size_t size = ply_scalar_size(s);
    if (pos_ + size > body_.size()) {
      throw InputError(name_ + ": truncated binary data while reading " + what);
    }
    const double v = ply_binary_value(body_.data() + pos_, s, enc_ == Encoding::Big);
    pos_ += size;
    return v;
  }

  // ASCII PLY puts one element entry on a line: values beyond the declared ones are ignored.
  void end_entry() {
    if (enc_ == Encoding::Ascii) text_.skip_line();
  }

  // Bytes (binary) or characters (ascii) left after the current position.
  size_t remaining() const { return body_.size() - position(); }
  size_t position() const { return enc_ == Encoding::Ascii ? text_.position() : pos_; }

 private:
  std::string_view body_;
  Encoding enc_;
  TextScanner text_;
  std::string name_;
  size_t pos_ = 0;
};

// Triangle strips s0 s1 s2 s3 ...: (s0 s1 s2), (s2 s1 s3), (s2 s3 s4), ..., every second one
// reversed so that all face the same way. -1 starts a new strip; triangles that repeat a vertex
// (a strip's turns) are left out.
class StripReader {
 public:
  explicit StripReader(PolygonSoup& soup) : soup_(soup) {}
  void restart() { count_ = 0; }
  void add(int v) {
    if (v < 0) return restart();
    if (count_ >= 2 && v != a_ && v != b_ && a_ != b_) {
      const bool odd = count_ % 2 == 1;
      for (const int c : {odd ? b_ : a_, odd ? a_ : b_, v}) soup_.add_polygon_corner(c);
      soup_.end_polygon();
    }
    a_ = b_;
    b_ = v;
    ++count_;
  }

 private:
  PolygonSoup& soup_;
  long long count_ = 0;
  int a_ = -1, b_ = -1;  // the strip's last two vertices
};

// The position of the element's list of vertex indices; InputError if it has none.
int index_list(const Element& e, const std::string& name) {
  for (size_t i = 0; i < e.properties.size(); ++i) {
    const Property& p = e.properties[i];
    if (p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index")) return int(i);
  }
  throw InputError(name + ": PLY element '" + e.name + "' has no vertex_indices list");
}

}  // namespace

PolygonSoup parse_ply(std::string_view data, const std::string& name, KeptRecord* keep) {
  if (data.empty()) throw InputError(name + ": empty file");
  const size_t header_end = data.find("end_header");
  if (!data.starts_with("ply")) throw InputError(name + ": not a PLY file (no 'ply' magic)");
  if (header_end == std::string_view::npos)
    throw InputError(name + ": PLY header has no end_header");
  size_t body_start = data.find('\n', header_end);
  body_start = body_start == std::string_view::npos ? data.size() : body_start + 1;

  TextScanner header(data.substr(0, header_end), name);
  header.skip_line();  // "ply"
  BodyReader::Encoding enc = BodyReader::Encoding::Ascii;
  bool have_format = false;
  std::vector<Element> elements;
  std::vector<std::string> textures;
  for (std::string_view key = header.next(false); !key.empty(); key = header.next(false)) {
    if (key == "format") {
      const std::string_view f = header.next(false);
      if (f == "ascii") {
        enc = BodyReader::Encoding::Ascii;
      } else if (f == "binary_little_endian") {
        enc = BodyReader::Encoding::Little;
      } else if (f == "binary_big_endian") {
        enc = BodyReader::Encoding::Big;
      } else {
        header.fail("unknown PLY format '" + std::string(f) + "'");
      }
      have_format = true;
      header.skip_line();
    } else if (key == "element") {
      Element e;
      e.name = std::string(header.next(false));
      e.count = header.next_integer("an element count");
      if (e.count < 0) header.fail("negative count for element '" + e.name + "'");
      elements.push_back(std::move(e));
    } else if (key == "property") {
      if (elements.empty()) header.fail("property before any element in the PLY header");
      Property p;
      std::string_view t = header.next(false);
      if (t == "list") {
        p.is_list = true;
        if (!parse_scalar(header.next(false), p.count_type)) header.fail("bad list count type");
        t = header.next(false);
      }
      if (!parse_scalar(t, p.type)) header.fail("unknown property type '" + std::string(t) + "'");
      p.name = std::string(header.next(false));
      elements.back().properties.push_back(std::move(p));
    } else if (key == "comment" && header.next(false) == "TextureFile") {
      // MeshLab names the image of its texcoord lists so; the name may hold spaces.
      const size_t start = header.position();
      size_t end = std::min(data.find('\n', start), header_end);
      std::string_view line = data.substr(start, end - start);
      while (!line.empty() && (line.front() == ' ' || line.front() == '\t')) line.remove_prefix(1);
      while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.remove_suffix(1);
      if (!line.empty()) textures.emplace_back(line);
      header.skip_line();
    } else {  // comment, obj_info and unknown keywords
      header.skip_line();
    }
  }
  if (!have_format) throw InputError(name + ": PLY header has no format line");

  const Element* vertex = nullptr;
  const Element* face = nullptr;
  const Element* strips = nullptr;
  for (const Element& e : elements) {
    if (e.name == "vertex") vertex = &e;
    if (e.name == "face") face = &e;
    if (e.name == "tristrips") strips = &e;
  }
  if (vertex == nullptr || vertex->count == 0) throw InputError(name + ": no vertices");
  if (face != nullptr && face->count == 0) face = nullptr;
  if (strips != nullptr && strips->count == 0) strips = nullptr;
  if (face == nullptr && strips == nullptr) {
    throw InputError(name + ": no faces (a point cloud is not a surface)");
  }
  // What each vertex property is to the mesh; -1: nothing it uses.
  enum Role { X, Y, Z, NX, NY, NZ, RED, GREEN, BLUE, ALPHA, U, V, kRoles };
  static constexpr std::pair<std::string_view, Role> kRoleNames[] = {
      {"x", X},         {"y", Y},         {"z", Z},         {"nx", NX},     {"ny", NY},
      {"nz", NZ},       {"red", RED},     {"green", GREEN}, {"blue", BLUE}, {"alpha", ALPHA},
      {"s", U},         {"t", V},         {"u", U},         {"v", V},       {"texture_u", U},
      {"texture_v", V}, {"texture_s", U}, {"texture_t", V}};
  std::vector<int> role(vertex->properties.size(), -1);
  int where[kRoles];
  std::fill(std::begin(where), std::end(where), -1);
  for (size_t i = 0; i < vertex->properties.size(); ++i) {
    const Property& p = vertex->properties[i];
    for (const auto& [n, r] : kRoleNames) {
      if (!p.is_list && p.name == n && where[r] < 0) {
        role[i] = r;
        where[r] = static_cast<int>(i);
      }
    }
  }
  if (where[X] < 0 || where[Y] < 0 || where[Z] < 0) {
    throw InputError(name + ": PLY vertices lack an x, y or z property");
  }
  const int face_list = face != nullptr ? index_list(*face, name) : -1;
  const int strip_list = strips != nullptr ? index_list(*strips, name) : -1;
  int face_texcoord = -1;
  for (size_t i = 0; face != nullptr && i < face->properties.size(); ++i) {
    if (face->properties[i].is_list && face->properties[i].name == "texcoord")
      face_texcoord = int(i);
  }

  PlyLayout layout;
  const bool normals = where[NX] >= 0 && where[NY] >= 0 && where[NZ] >= 0;
  const bool colours = where[RED] >= 0 && where[GREEN] >= 0 && where[BLUE] >= 0;
  const bool vertex_uv = where[U] >= 0 && where[V] >= 0;
  std::vector<double> values(kRoles);  // of the vertex being read
  std::vector<double> face_uv;         // the faces' texcoord lists, u v per corner
  FileAttributes* a = keep ? &keep->attributes : nullptr;
  if (keep) {
    layout.encoding = enc;
    layout.textures = std::move(textures);
    layout.vertex_element = static_cast<int>(vertex - elements.data());
    for (int k = 0; k < 3; ++k) {
      layout.xyz[k] = where[X + k];
      layout.normal[k] = normals ? where[NX + k] : -1;
    }
    layout.vertex.reserve(vertex->count);
    if (normals) a->normals.setZero(vertex->count, 3);
    if (colours) a->colours.setOnes(vertex->count, 4);
    if (vertex_uv) a->uv.setZero(vertex->count, 2);
  }
  // A colour channel in [0, 1] from its type's range.
  const auto channel = [&](int r) {
    const Scalar t = vertex->properties[where[r]].type;
    const double scale = t == Scalar::U8 ? 255.0 : t == Scalar::U16 ? 65535.0 : 1.0;
    return static_cast<float>(values[r] / scale);
  };

  BodyReader in(data.substr(body_start), enc, name);
  PolygonSoup soup;
  StripReader strip(soup);
  // Each value takes at least one byte (binary) or two characters (ascii).
  for (const Element& e : elements) {
    if (e.count > static_cast<long long>(in.remaining())) {
      throw InputError(name + ": truncated data (element '" + e.name + "' announces " +
                       std::to_string(e.count) + " entries)");
    }
    for (long long r = 0; r < e.count; ++r) {
      if (keep && &e == vertex) layout.vertex.push_back(body_start + in.position());
      for (size_t i = 0; i < e.properties.size(); ++i) {
        const Property& p = e.properties[i];
        if (!p.is_list) {
          const double v = in.read(p.type, e.name.c_str());
          if (&e == vertex && role[i] >= 0) values[role[i]] = v;
          continue;
        }
        const double count = in.read(p.count_type, "a list length");
        if (!(count >= 0) || count != std::floor(count)) {
          throw InputError(name + ": bad list length in element '" + e.name + "'");
        }
        if (count > static_cast<double>(in.remaining())) {  // each value takes a byte at least
          throw InputError(name + ": truncated data (element '" + e.name + "' entry " +
                           std::to_string(r) + "'s list of " + as_read(count) +
                           " values runs past the end)");
        }
        const bool is_face = &e == face && int(i) == face_list;
        const bool is_strip = &e == strips && int(i) == strip_list;
        const bool is_texcoord = keep && &e == face && int(i) == face_texcoord;
        for (long long c = 0; c < static_cast<long long>(count); ++c) {
          const double v = in.read(p.type, "a list");
          if (is_texcoord) face_uv.push_back(v);
          if (!is_face && !is_strip) continue;
          if (!(v >= (is_strip ? -1 : 0) && v < static_cast<double>(vertex->count)) ||
              v != std::floor(v)) {
            throw InputError(name + ": " + (is_face ? "face " : "triangle strip ") +
                             std::to_string(r) + " references vertex " + as_read(v) +
                             " but there are " + std::to_string(vertex->count) + " vertices");
          }
          if (is_face) {
            soup.add_polygon_corner(static_cast<int>(v));
          } else {
            strip.add(static_cast<int>(v));
          }
        }
        if (is_face) soup.end_polygon();
        if (is_strip) strip.restart();
      }
      if (&e == vertex) {
        soup.xyz.insert(soup.xyz.end(), {values[X], values[Y], values[Z]});
        if (keep && normals) a->normals.row(r) << values[NX], values[NY], values[NZ];
        if (keep && colours) {
          a->colours.row(r) << channel(RED), channel(GREEN), channel(BLUE),
              where[ALPHA] >= 0 ? channel(ALPHA) : 1.0f;
        }
        if (keep && vertex_uv) a->uv.row(r) << values[U], values[V];
      }
      in.end_entry();
    }
  }
  // Exporters split a vertex where its texture coordinates or normals differ (Blender's along UV
  // seams): such files are welded where positions coincide, as glTF's are, or the seams open.
  if (vertex_uv || normals) soup.weld = weld_coincident(soup.xyz);
  if (keep) {
    // Per-vertex normals and uvs: each corner uses its vertex's row; the faces' texcoord lists,
    // when they have them, give each corner a row of its own.
    if (normals) a->corner_normal = soup.indices;
    if (face_texcoord >= 0 && face_uv.size() != 2 * soup.indices.size()) {
      throw InputError(name + ": the faces' texcoord lists do not hold two numbers per corner");
    }
    if (face_texcoord >= 0) {
      a->uv = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>(
          face_uv.data(), Eigen::Index(face_uv.size() / 2), 2);
      a->corner_uv.resize(soup.indices.size());
      std::iota(a->corner_uv.begin(), a->corner_uv.end(), 0);
    } else if (vertex_uv) {
      a->corner_uv = soup.indices;
    }
    layout.elements = std::move(elements);
    keep->layout.bytes.assign(data);
    keep->layout.format = std::move(layout);
  }
  return soup;
}

}  // namespace specdeform::detail
