// OBJ rewritten: its v and vn numbers replaced, every other byte kept (obj.h).
#include <algorithm>

#include "mesh/file_layout.h"
#include "mesh/text_rewriter.h"
#include "obj.h"

namespace specdeform::detail {

std::string rewrite_obj(const MeshFile& file, const Vertices& positions,
                        const Eigen::MatrixX3d& normals) {
  const ObjLayout& layout = std::get<ObjLayout>(file.layout->format);
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

}  // namespace specdeform::detail
