#include "preview.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>
#include <unordered_set>

#include "specdeform/exceptions.h"

namespace specdeform::server {

namespace {

// The grid cell of every vertex, numbered 0 .. cells-1 in order of first appearance.
std::vector<int> cells_of(const Vertices& V, const Eigen::RowVector3d& lo, double size,
                          int& cells) {
  std::unordered_map<uint64_t, int> index;
  index.reserve(V.rows() / 2);
  std::vector<int> cell(V.rows());
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    uint64_t key = 0;
    for (int k = 0; k < 3; ++k) {
      key = key << 21 | (static_cast<uint64_t>(std::floor((V(v, k) - lo[k]) / size)) & 0x1fffff);
    }
    cell[v] = index.try_emplace(key, static_cast<int>(index.size())).first->second;
  }
  cells = static_cast<int>(index.size());
  return cell;
}

}  // namespace

PreviewMesh make_preview(const TriangleMesh& mesh, int target) {
  if (target < 4) throw InputError("preview: at least 4 vertices");
  const Vertices& V = mesh.V;
  const int n = static_cast<int>(V.rows());
  PreviewMesh out;
  if (n <= target) {
    out.vertices.resize(n);
    std::iota(out.vertices.begin(), out.vertices.end(), 0);
    out.faces = mesh.F;
    return out;
  }
  // A surface of area A has about A / h^2 cells of size h: start there, then correct.
  double area = 0.0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::RowVector3d a = V.row(mesh.F(f, 0)), b = V.row(mesh.F(f, 1)),
                             c = V.row(mesh.F(f, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  const Eigen::RowVector3d lo = V.colwise().minCoeff();
  const double extent = (V.colwise().maxCoeff() - lo).maxCoeff();
  double size = std::max(std::sqrt(area / target), extent / (1 << 20));
  int cells = 0;
  std::vector<int> cell;
  for (int attempt = 0; attempt < 6; ++attempt) {
    cell = cells_of(V, lo, size, cells);
    if (cells <= 1.25 * target && cells >= 0.75 * target) break;
    size *= std::sqrt(static_cast<double>(cells) / target);
  }
  // The vertex nearest to its cell's mean.
  Eigen::MatrixX3d mean = Eigen::MatrixX3d::Zero(cells, 3);
  Eigen::VectorXd count = Eigen::VectorXd::Zero(cells);
  for (int v = 0; v < n; ++v) mean.row(cell[v]) += V.row(v), count[cell[v]] += 1;
  mean.array().colwise() /= count.array();
  std::vector<int> kept(cells, -1);
  std::vector<double> best(cells, INFINITY);
  for (int v = 0; v < n; ++v) {
    const double d = (V.row(v) - mean.row(cell[v])).squaredNorm();
    if (d < best[cell[v]]) best[cell[v]] = d, kept[cell[v]] = v;
  }
  out.vertices = kept;
  std::vector<Eigen::RowVector3i> faces;
  std::unordered_set<uint64_t> seen;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::RowVector3i c(cell[mesh.F(f, 0)], cell[mesh.F(f, 1)], cell[mesh.F(f, 2)]);
    if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) continue;
    std::array<uint64_t, 3> key = {uint64_t(c[0]), uint64_t(c[1]), uint64_t(c[2])};
    std::sort(key.begin(), key.end());
    if (seen.insert(key[0] << 42 | key[1] << 21 | key[2]).second) faces.push_back(c);
  }
  out.faces.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) out.faces.row(static_cast<Eigen::Index>(f)) = faces[f];
  return out;
}

}  // namespace specdeform::server
