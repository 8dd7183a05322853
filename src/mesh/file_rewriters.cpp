#include "file_rewriters.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include "float_cast.h"
#include "text_rewriter.h"

namespace specdeform::detail {

namespace {

template <typename Layout>
const Layout& layout_of(const MeshFile& file) {
  return std::get<Layout>(file.layout->format);
}

}  // namespace

std::string rewrite_obj(const MeshFile& file, const Vertices& positions,
                        const Eigen::MatrixX3d& normals) {
  const ObjLayout& layout = layout_of<ObjLayout>(file);
  const std::vector<size_t> none;
  const std::vector<size_t>& vn = normals.rows() > 0 ? layout.vn : none;
  const NumberText style = TextRewriter(file.layout->bytes).precision(layout.v, 3);
  return rewrite_text(file.layout->bytes, [&](TextRewriter& out, size_t from, size_t to) {
    // The v and vn lines in [from, to), in file order.
    const auto first = [&](const std::vector<size_t>& lines, size_t offset) {
      return size_t(std::lower_bound(lines.begin(), lines.end(), offset) - lines.begin());
    };
    size_t v = first(layout.v, from), n = first(vn, from);
    const size_t v_end = first(layout.v, to), n_end = first(vn, to);
    while (v < v_end || n < n_end) {
      if (n >= n_end || (v < v_end && layout.v[v] < vn[n])) {
        out.seek(layout.v[v]);
        for (int k = 0; k < 3; ++k) out.replace(positions(Eigen::Index(v), k), style);
        ++v;
      } else {
        out.seek(vn[n]);
        for (int k = 0; k < 3; ++k) out.replace(normals(Eigen::Index(n), k), NumberText::Float);
        ++n;
      }
    }
  });
}

std::string rewrite_off(const MeshFile& file, const Vertices& positions,
                        const Eigen::MatrixX3d& normals) {
  const OffLayout& layout = layout_of<OffLayout>(file);
  const NumberText style = TextRewriter(file.layout->bytes).precision(layout.vertex, 3);
  return rewrite_text(file.layout->bytes, [&](TextRewriter& out, size_t from, size_t to) {
    const auto at = [&](size_t offset) {
      return size_t(std::lower_bound(layout.vertex.begin(), layout.vertex.end(), offset) -
                    layout.vertex.begin());
    };
    for (size_t i = at(from), end = at(to); i < end; ++i) {
      out.seek(layout.vertex[i]);
      for (int k = 0; k < 3; ++k) out.replace(positions(Eigen::Index(i), k), style);
      if (layout.normals && normals.rows() > 0) {
        for (int k = 0; k < 3; ++k) out.replace(normals(Eigen::Index(i), k), NumberText::Float);
      }
    }
  });
}

namespace {

NumberText text_style(PlyScalar s) {
  return s == PlyScalar::F32   ? NumberText::Float
         : s == PlyScalar::F64 ? NumberText::Double
                               : NumberText::Integer;
}

// A binary value of type `s` at `at`: read as a double, or written from one (rounded for integer
// types). Only a value that differs is written, so that an unchanged one keeps its bytes (-0.0,
// NaN payloads).
class BinaryValue {
 public:
  BinaryValue(std::string& bytes, bool big_endian) : bytes_(bytes), big_(big_endian) {}

  double get(size_t at, PlyScalar s) const { return ply_binary_value(bytes_.data() + at, s, big_); }

  void set(size_t at, PlyScalar s, double v) {
    switch (s) {
      case PlyScalar::I8:
        return put<int8_t>(at, s, v);
      case PlyScalar::U8:
        return put<uint8_t>(at, s, v);
      case PlyScalar::I16:
        return put<int16_t>(at, s, v);
      case PlyScalar::U16:
        return put<uint16_t>(at, s, v);
      case PlyScalar::I32:
        return put<int32_t>(at, s, v);
      case PlyScalar::U32:
        return put<uint32_t>(at, s, v);
      case PlyScalar::F32:
        return put<float>(at, s, v);
      case PlyScalar::F64:
        return put<double>(at, s, v);
    }
  }

 private:
  template <typename T>
  void put(size_t at, PlyScalar s, double v) {
    const T value = checked_cast<T>(v, "a PLY value");
    const double stored = get(at, s);
    if (static_cast<double>(value) == stored || (std::isnan(v) && std::isnan(stored))) return;
    unsigned char b[sizeof(T)];
    std::memcpy(b, &value, sizeof value);
    if (big_ != (std::endian::native == std::endian::big)) std::reverse(b, b + sizeof b);
    std::memcpy(bytes_.data() + at, b, sizeof b);
  }

  std::string& bytes_;
  bool big_;
};

}  // namespace

std::string rewrite_ply(const MeshFile& file, const Vertices& positions,
                        const Eigen::MatrixX3d& normals) {
  const PlyLayout& layout = layout_of<PlyLayout>(file);
  const PlyElement& vertex = layout.elements[layout.vertex_element];
  const bool write_normals = layout.normal[0] >= 0 && normals.rows() > 0;
  // The value property p of vertex i gets, if any.
  const auto value = [&](Eigen::Index i, int p, double& v, NumberText& style) {
    for (int k = 0; k < 3; ++k) {
      if (p == layout.xyz[k]) {
        v = positions(i, k);
        style = text_style(vertex.properties[p].type);
        return true;
      }
      if (write_normals && p == layout.normal[k]) {
        v = normals(i, k);
        style = vertex.properties[p].type == PlyScalar::F64 ? NumberText::Double
                                                            : text_style(vertex.properties[p].type);
        return true;
      }
    }
    return false;
  };
  if (layout.encoding == PlyEncoding::Ascii) {
    TextRewriter out(file.layout->bytes);
    for (size_t i = 0; i < layout.vertex.size(); ++i) {
      out.seek(layout.vertex[i]);
      for (int p = 0; p < int(vertex.properties.size()); ++p) {
        const PlyProperty& property = vertex.properties[p];
        double v;
        NumberText style;
        if (property.is_list) {
          const double count = read_number(out.peek());
          out.keep(1 + (count >= 0 ? static_cast<long long>(count) : 0));
        } else if (value(Eigen::Index(i), p, v, style)) {
          out.replace(v, style);
        } else {
          out.keep(1);
        }
      }
    }
    return out.finish();
  }
  std::string bytes = file.layout->bytes;
  BinaryValue binary(bytes, layout.encoding == PlyEncoding::Big);
  for (size_t i = 0; i < layout.vertex.size(); ++i) {
    size_t at = layout.vertex[i];
    for (int p = 0; p < int(vertex.properties.size()); ++p) {
      const PlyProperty& property = vertex.properties[p];
      double v;
      NumberText style;
      if (property.is_list) {
        const double count = binary.get(at, property.count_type);
        at += ply_scalar_size(property.count_type) + size_t(count) * ply_scalar_size(property.type);
        continue;
      }
      if (value(Eigen::Index(i), p, v, style)) binary.set(at, property.type, v);
      at += ply_scalar_size(property.type);
    }
  }
  return bytes;
}

std::string rewrite_stl(const MeshFile& file, const Vertices& positions,
                        const Eigen::MatrixX3d& normals) {
  const StlLayout& layout = layout_of<StlLayout>(file);
  const FileAttributes& a = file.attributes;
  if (layout.ascii) {
    // Each facet's normal and its corners, in the order they stand in the file (a "normal" may
    // follow its loop).
    std::vector<std::pair<size_t, Eigen::Vector3d>> numbers;
    for (int f = 0; f < a.num_polygons(); ++f) {
      numbers.emplace_back(layout.facet_normal[f], normals.row(f).transpose());
      for (int c = a.offsets[f]; c < a.offsets[f + 1]; ++c) {
        numbers.emplace_back(layout.corner[c], positions.row(a.corners[c]).transpose());
      }
    }
    std::sort(numbers.begin(), numbers.end(),
              [](const auto& x, const auto& y) { return x.first < y.first; });
    TextRewriter out(file.layout->bytes);
    for (const auto& [offset, value] : numbers) {
      out.seek(offset);
      for (int k = 0; k < 3; ++k) out.replace(value[k], NumberText::Float);
    }
    return out.finish();
  }
  std::string bytes = file.layout->bytes;
  BinaryValue binary(bytes, false);
  for (int f = 0; f < a.num_polygons(); ++f) {
    const size_t record = 84 + 50 * size_t(f);
    for (int k = 0; k < 3; ++k) binary.set(record + 4 * k, PlyScalar::F32, normals(f, k));
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k)
        binary.set(record + 12 * (c + 1) + 4 * k, PlyScalar::F32,
                   positions(a.corners[a.offsets[f] + c], k));
  }
  return bytes;
}

}  // namespace specdeform::detail
