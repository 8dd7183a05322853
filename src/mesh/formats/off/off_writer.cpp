// OFF written afresh (off.h).
#include "mesh/float_cast.h"
#include "mesh/formats/converted.h"
#include "off.h"

namespace specdeform::detail {

std::vector<std::string> off_parts(const FileAttributes& a, const Vertices& X,
                                   const Eigen::MatrixX3d& normals,
                                   const std::vector<int>& vertex_normal) {
  const bool colours = a.colours.rows() > 0, normal = !vertex_normal.empty();
  std::string header = std::string(colours ? "C" : "") + (normal ? "N" : "") + "OFF\n";
  append_number(header, int(X.rows()));
  header += ' ';
  append_number(header, a.num_polygons());
  header += " 0\n";
  std::vector<std::string> parts{std::move(header)};
  append_parts(parts, lines_in_halves(int(X.rows()), 64, [&](std::string& s, int i) {
                 for (int k = 0; k < 3; ++k) {
                   if (k > 0) s += ' ';
                   append_number(s, X(i, k));
                 }
                 for (int k = 0; normal && k < 3; ++k) {
                   s += ' ';
                   append_number(s, vertex_normal[i] < 0
                                        ? 0.f
                                        : to_float(normals(vertex_normal[i], k), "a normal"));
                 }
                 for (int k = 0; colours && k < 4; ++k) {
                   s += ' ';
                   append_number(s, int(to_byte(a.colours(i, k))));
                 }
                 s += '\n';
               }));
  const size_t face_bytes = 3 * std::to_string(X.rows()).size() + 6;
  append_parts(parts, lines_in_halves(a.num_polygons(), face_bytes, [&](std::string& s, int p) {
                 append_number(s, a.offsets[p + 1] - a.offsets[p]);
                 for (int c = a.offsets[p]; c < a.offsets[p + 1]; ++c) {
                   s += ' ';
                   append_number(s, a.corners[c]);
                 }
                 s += '\n';
               }));
  return parts;
}

}  // namespace specdeform::detail
