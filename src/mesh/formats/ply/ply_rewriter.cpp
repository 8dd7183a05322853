// PLY rewritten: x y z (and nx ny nz) replaced in their own types, every other byte kept (ply.h).
#include "mesh/file_layout.h"
#include "mesh/formats/binary_value.h"
#include "mesh/text_rewriter.h"
#include "ply.h"

namespace specdeform::detail {

namespace {

NumberText text_style(PlyScalar s) {
  return s == PlyScalar::F32   ? NumberText::Float
         : s == PlyScalar::F64 ? NumberText::Double
                               : NumberText::Integer;
}

}  // namespace

std::string rewrite_ply(const MeshFile& file, const Vertices& positions,
                        const Eigen::MatrixX3d& normals) {
  const PlyLayout& layout = std::get<PlyLayout>(file.layout->format);
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

}  // namespace specdeform::detail
