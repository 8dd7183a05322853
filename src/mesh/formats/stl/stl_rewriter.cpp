// STL rewritten: corners and facet normals replaced, every other byte kept (stl.h).
#include <algorithm>

#include "mesh/file_layout.h"
#include "mesh/formats/binary_value.h"
#include "mesh/text_rewriter.h"
#include "stl.h"

namespace specdeform::detail {

std::string rewrite_stl(const MeshFile& file, const Vertices& positions,
                        const Eigen::MatrixX3d& normals) {
  const StlLayout& layout = std::get<StlLayout>(file.layout->format);
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
