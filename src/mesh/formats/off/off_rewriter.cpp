// OFF rewritten: its vertex numbers (and NOFF normals) replaced, every other byte kept (off.h).
#include <algorithm>

#include "mesh/file_layout.h"
#include "mesh/text_rewriter.h"
#include "off.h"

namespace specdeform::detail {

std::string rewrite_off(const MeshFile& file, const Vertices& positions,
                        const Eigen::MatrixX3d& normals) {
  const OffLayout& layout = std::get<OffLayout>(file.layout->format);
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

}  // namespace specdeform::detail
