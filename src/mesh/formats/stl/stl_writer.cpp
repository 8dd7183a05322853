// STL written afresh: binary, facet normals of the new shape (stl.h).
#include <Eigen/Geometry>

#include "mesh/float_cast.h"
#include "mesh/formats/converted.h"
#include "stl.h"

namespace specdeform::detail {

std::string stl_bytes(const FileAttributes& a, const Vertices& X) {
  std::string s(80, ' ');
  s.replace(0, 22, "binary STL, specdeform");
  append_le(s, static_cast<uint32_t>(count_triangles(a)));
  for_each_triangle(a, [&](int, int i, int j, int k) {
    const Eigen::Vector3d p = X.row(a.corners[i]), q = X.row(a.corners[j]), r = X.row(a.corners[k]);
    const Eigen::Vector3d n = (q - p).cross(r - p);
    const Eigen::Vector3d unit = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : n;
    for (int d = 0; d < 3; ++d) append_le(s, static_cast<float>(unit[d]));
    for (const Eigen::Vector3d* v : {&p, &q, &r})
      for (int d = 0; d < 3; ++d) append_le(s, to_float((*v)[d], "a position"));
    append_le(s, uint16_t{0});
  });
  return s;
}

}  // namespace specdeform::detail
