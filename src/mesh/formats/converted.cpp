#include "converted.h"

#include <algorithm>
#include <cmath>

namespace specdeform::detail {

void append_parts(std::vector<std::string>& to, std::vector<std::string>&& parts) {
  for (std::string& p : parts) to.push_back(std::move(p));
}

std::vector<int> per_vertex(const FileAttributes& a, const std::vector<int>& rows, int vertices) {
  if (rows.empty()) return {};
  std::vector<int> out(vertices, -1);
  for (size_t c = 0; c < a.corners.size(); ++c) {
    int& row = out[a.corners[c]];
    if (rows[c] < 0) continue;
    if (row >= 0 && row != rows[c]) return {};
    row = rows[c];
  }
  return out;
}

int count_triangles(const FileAttributes& a) {
  int count = 0;
  for (int p = 0; p < a.num_polygons(); ++p)
    count += std::max(0, a.offsets[p + 1] - a.offsets[p] - 2);
  return count;
}

bool has_polygons(const FileAttributes& a) {
  for (int p = 0; p < a.num_polygons(); ++p)
    if (a.offsets[p + 1] - a.offsets[p] != 3) return true;
  return false;
}

uint8_t to_byte(float c) {
  return static_cast<uint8_t>(std::lround(std::clamp(c, 0.f, 1.f) * 255));
}

}  // namespace specdeform::detail
