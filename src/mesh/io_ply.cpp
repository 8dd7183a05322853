#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "polygon_soup.h"
#include "text_scanner.h"

namespace specdeform::detail {

namespace {

enum class Scalar { I8, U8, I16, U16, I32, U32, F32, F64 };

struct Property {
  std::string name;
  Scalar type = Scalar::F32;
  bool is_list = false;
  Scalar count_type = Scalar::U8;
};

struct Element {
  std::string name;
  long long count = 0;
  std::vector<Property> properties;
};

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

size_t scalar_size(Scalar s) {
  switch (s) {
    case Scalar::I8:
    case Scalar::U8:
      return 1;
    case Scalar::I16:
    case Scalar::U16:
      return 2;
    case Scalar::I32:
    case Scalar::U32:
    case Scalar::F32:
      return 4;
    case Scalar::F64:
      return 8;
  }
  return 0;
}

// Reads the body's values one at a time, whatever the encoding.
class BodyReader {
 public:
  enum class Encoding { Ascii, Little, Big };

  BodyReader(std::string_view body, Encoding enc, const std::string& name)
      : body_(body), enc_(enc), text_(body, name), name_(name) {}

  double read(Scalar s, const char* what) {
    if (enc_ == Encoding::Ascii) return text_.next_double(what);
    const size_t size = scalar_size(s);
    if (pos_ + size > body_.size()) {
      throw InputError(name_ + ": truncated binary data while reading " + what);
    }
    unsigned char b[8];
    std::memcpy(b, body_.data() + pos_, size);
    pos_ += size;
    if ((enc_ == Encoding::Big) != (std::endian::native == std::endian::big)) {
      for (size_t i = 0; i < size / 2; ++i) std::swap(b[i], b[size - 1 - i]);
    }
    switch (s) {
      case Scalar::I8:
        return static_cast<double>(static_cast<int8_t>(b[0]));
      case Scalar::U8:
        return b[0];
      case Scalar::I16:
        return as<int16_t>(b);
      case Scalar::U16:
        return as<uint16_t>(b);
      case Scalar::I32:
        return as<int32_t>(b);
      case Scalar::U32:
        return as<uint32_t>(b);
      case Scalar::F32:
        return as<float>(b);
      case Scalar::F64:
        return as<double>(b);
    }
    return 0.0;
  }

  // ASCII PLY puts one element entry on a line: values beyond the declared ones are ignored.
  void end_entry() {
    if (enc_ == Encoding::Ascii) text_.skip_line();
  }

  // Bytes (binary) or characters (ascii) left after the current position.
  size_t remaining() const {
    return enc_ == Encoding::Ascii ? body_.size() - text_.position() : body_.size() - pos_;
  }

 private:
  template <typename T>
  static double as(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof(T));
    return static_cast<double>(v);
  }

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

PolygonSoup parse_ply(std::string_view data, const std::string& name) {
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
  int xyz_index[3] = {-1, -1, -1};
  for (size_t i = 0; i < vertex->properties.size(); ++i) {
    const Property& p = vertex->properties[i];
    for (int k = 0; k < 3; ++k) {
      if (!p.is_list && p.name == std::string(1, static_cast<char>('x' + k))) xyz_index[k] = int(i);
    }
  }
  if (xyz_index[0] < 0 || xyz_index[1] < 0 || xyz_index[2] < 0) {
    throw InputError(name + ": PLY vertices lack an x, y or z property");
  }
  const int face_list = face != nullptr ? index_list(*face, name) : -1;
  const int strip_list = strips != nullptr ? index_list(*strips, name) : -1;

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
      double xyz[3] = {0, 0, 0};
      for (size_t i = 0; i < e.properties.size(); ++i) {
        const Property& p = e.properties[i];
        if (!p.is_list) {
          const double v = in.read(p.type, e.name.c_str());
          if (&e == vertex) {
            for (int k = 0; k < 3; ++k)
              if (xyz_index[k] == int(i)) xyz[k] = v;
          }
          continue;
        }
        const double count = in.read(p.count_type, "a list length");
        if (!(count >= 0) || count > static_cast<double>(in.remaining())) {
          throw InputError(name + ": bad list length in element '" + e.name + "'");
        }
        const bool is_face = &e == face && int(i) == face_list;
        const bool is_strip = &e == strips && int(i) == strip_list;
        for (long long c = 0; c < static_cast<long long>(count); ++c) {
          const double v = in.read(p.type, "a list");
          if (!is_face && !is_strip) continue;
          if (!(v >= (is_strip ? -1 : 0) && v < static_cast<double>(vertex->count)) ||
              v != std::floor(v)) {
            char text[32];  // v as read: it may be 1.5, 1e300 or nan
            const auto [end, ec] = std::to_chars(text, text + sizeof text, v);
            throw InputError(name + ": " + (is_face ? "face " : "triangle strip ") +
                             std::to_string(r) + " references vertex " + std::string(text, end) +
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
      if (&e == vertex) soup.xyz.insert(soup.xyz.end(), xyz, xyz + 3);
      in.end_entry();
    }
  }
  return soup;
}

}  // namespace specdeform::detail
