// PLY written afresh: binary little endian, double positions (ply.h).
#include "mesh/float_cast.h"
#include "mesh/formats/converted.h"
#include "ply.h"
#include "specdeform/exceptions.h"

namespace specdeform::detail {

std::string ply_bytes(const FileAttributes& a, const Vertices& X, const Eigen::MatrixX3d& normals,
                      const std::vector<int>& vertex_normal) {
  const bool colours = a.colours.rows() > 0, normal = !vertex_normal.empty();
  const bool uv = !a.corner_uv.empty();
  std::string s = "ply\nformat binary_little_endian 1.0\ncomment written by specdeform\n";
  s += "element vertex " + std::to_string(X.rows()) + "\n";
  s += "property double x\nproperty double y\nproperty double z\n";
  if (normal) s += "property float nx\nproperty float ny\nproperty float nz\n";
  if (colours)
    s += "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n";
  s += "element face " + std::to_string(a.num_polygons()) + "\n";
  s += "property list uchar int vertex_indices\n";
  if (uv) s += "property list uchar float texcoord\n";
  s += "end_header\n";
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    for (int k = 0; k < 3; ++k) append_le(s, X(i, k));
    for (int k = 0; normal && k < 3; ++k) {
      append_le(s, vertex_normal[i] < 0 ? 0.f : to_float(normals(vertex_normal[i], k), "a normal"));
    }
    for (int k = 0; colours && k < 4; ++k) append_le(s, to_byte(a.colours(i, k)));
  }
  for (int p = 0; p < a.num_polygons(); ++p) {
    const int k = a.offsets[p + 1] - a.offsets[p];
    if (k > 255)
      throw InputError("a polygon of " + std::to_string(k) + " corners does not fit PLY's list");
    append_le(s, static_cast<uint8_t>(k));
    for (int c = a.offsets[p]; c < a.offsets[p + 1]; ++c) append_le(s, int32_t{a.corners[c]});
    if (!uv) continue;
    append_le(s, static_cast<uint8_t>(2 * k));
    for (int c = a.offsets[p]; c < a.offsets[p + 1]; ++c) {
      const int t = a.corner_uv[c];
      append_le(s, t < 0 ? 0.f : to_float(a.uv(t, 0), "a texture coordinate"));
      append_le(s, t < 0 ? 0.f : to_float(a.uv(t, 1), "a texture coordinate"));
    }
  }
  return s;
}

}  // namespace specdeform::detail
