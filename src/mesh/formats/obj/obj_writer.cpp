// OBJ written afresh, with an MTL beside it (obj.h).
#include "mesh/float_cast.h"
#include "mesh/formats/converted.h"
#include "obj.h"

namespace specdeform::detail {

Encoded encode_obj(const FileAttributes& a, const Vertices& X, const Eigen::MatrixX3d& normals,
                   const Target& target, const MeshFile* file) {
  Encoded out;
  std::vector<std::string>& parts = out.parts;
  parts.push_back("# written by specdeform\n");
  if (!a.materials.empty()) {
    // The MTL beside it: each material's Kd and base colour image (a glTF's own written out).
    std::string mtl = "# written by specdeform\n";
    for (size_t m = 0; m < a.materials.size(); ++m) {
      const Material& mat = a.materials[m];
      const std::string name = mat.name.empty() ? "material_" + std::to_string(m) : mat.name;
      mtl += "newmtl " + name + "\nKd";
      for (int k = 0; k < 3; ++k) {
        mtl += ' ';
        append_number(mtl, mat.base_color[k]);
      }
      mtl += '\n';
      std::string texture = mat.gltf_image >= 0 ? std::string() : mat.texture;
      if (mat.gltf_image >= 0 && file != nullptr) {
        if (auto image = file->texture(static_cast<int>(m))) {
          const std::string ext = image->second == "image/jpeg" ? ".jpg" : ".png";
          texture = target.stem + "-" + std::to_string(m) + ext;
          out.companions.push_back({texture, std::move(image->first)});
        }
      }
      if (!texture.empty()) mtl += "map_Kd " + texture + "\n";
      if (!texture.empty() && mat.gltf_image < 0) out.kept.push_back(texture);
    }
    out.companions.push_back({target.stem + ".mtl", std::move(mtl)});
    parts.push_back("mtllib " + target.stem + ".mtl\n");
  }
  const bool colours = a.colours.rows() > 0;
  append_parts(parts, lines_in_halves(int(X.rows()), colours ? 96 : 64, [&](std::string& s, int i) {
                 s += 'v';
                 for (int k = 0; k < 3; ++k) {
                   s += ' ';
                   append_number(s, X(i, k));
                 }
                 for (int k = 0; colours && k < 3; ++k) {
                   s += ' ';
                   append_number(s, a.colours(i, k));
                 }
                 s += '\n';
               }));
  std::string attributes;
  const bool uv = !a.corner_uv.empty(), normal = !a.corner_normal.empty() && normals.rows() > 0;
  for (Eigen::Index t = 0; uv && t < a.uv.rows(); ++t) {
    attributes += "vt ";
    append_number(attributes, a.uv(t, 0));
    attributes += ' ';
    append_number(attributes, a.uv(t, 1));
    attributes += '\n';
  }
  for (Eigen::Index n = 0; normal && n < normals.rows(); ++n) {
    attributes += "vn";
    for (int k = 0; k < 3; ++k) {
      attributes += ' ';
      append_number(attributes, to_float(normals(n, k), "a normal"));
    }
    attributes += '\n';
  }
  parts.push_back(std::move(attributes));
  // Faces, a usemtl where the material changes.
  const size_t face_bytes = 3 * (std::to_string(X.rows()).size() + 1) * (1 + uv + normal) + 4;
  const bool materials = !a.materials.empty();
  const auto face = [&](std::string& s, int p) {
    if (materials && (p == 0 || a.polygon_material[p] != a.polygon_material[p - 1])) {
      const int m = a.polygon_material[p];
      s += "usemtl ";
      s += m < 0                         ? std::string("none")
           : a.materials[m].name.empty() ? "material_" + std::to_string(m)
                                         : a.materials[m].name;
      s += '\n';
    }
    s += 'f';
    for (int c = a.offsets[p]; c < a.offsets[p + 1]; ++c) {
      s += ' ';
      append_number(s, a.corners[c] + 1);
      const int t = uv ? a.corner_uv[c] : -1, n = normal ? a.corner_normal[c] : -1;
      if (t >= 0 || n >= 0) s += '/';
      if (t >= 0) append_number(s, t + 1);
      if (n >= 0) {
        s += '/';
        append_number(s, n + 1);
      }
    }
    s += '\n';
  };
  if (materials) {  // the material's state runs from face to face: one thread
    std::string faces;
    for (int p = 0; p < a.num_polygons(); ++p) face(faces, p);
    parts.push_back(std::move(faces));
  } else {
    append_parts(parts, lines_in_halves(a.num_polygons(), face_bytes, face));
  }
  return out;
}

}  // namespace specdeform::detail
