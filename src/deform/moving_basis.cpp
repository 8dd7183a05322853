#include "deform/moving_basis.h"

#include <algorithm>
#include <numeric>

#include "mesh/sub_mesh.h"
#include "specdeform/operators/laplacian.h"
#include "spectral/piecewise.h"

namespace specdeform::detail {

std::shared_ptr<const ManifoldHarmonics> moving_basis(const TriangleMesh& mesh,
                                                      const ManifoldHarmonics& basis,
                                                      const Eigen::VectorXi& components,
                                                      const std::vector<int>& piece_of_mode,
                                                      const std::vector<char>& moving) {
  const size_t count = moving.size();
  const Eigen::VectorXd area = vertex_areas(mesh);
  std::vector<double> piece_area(count, 0.0);
  std::vector<int> piece_vertices(count, 0);
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    piece_area[components[v]] += area[v];
    ++piece_vertices[components[v]];
  }
  std::vector<int> pieces, have(count, 0);
  for (size_t c = 0; c < count; ++c)
    if (moving[c]) pieces.push_back(static_cast<int>(c));
  for (const int c : piece_of_mode) ++have[c];
  std::vector<double> areas;
  std::vector<int> vertices;
  for (const int c : pieces) {
    areas.push_back(piece_area[c]);
    vertices.push_back(piece_vertices[c]);
  }
  const ManifoldHarmonicsPolicy policy;
  const int m =
      basis.requested_modes > 0 ? basis.requested_modes : static_cast<int>(basis.basis.cols());
  const std::vector<int> want = piece_modes(areas, vertices, m, policy);
  // The pieces short of their share, solved again together (piecewise, with that share).
  std::vector<char> starved(count, 0), again(mesh.num_vertices(), 0);
  int again_modes = 0, again_pieces = 0;
  for (size_t k = 0; k < pieces.size(); ++k) {
    if (have[pieces[k]] >= want[k] || vertices[k] <= policy.piece_min_modes) continue;
    starved[pieces[k]] = 1;
    again_modes += want[k];
    ++again_pieces;
  }
  for (int v = 0; v < mesh.num_vertices(); ++v) again[v] = starved[components[v]];
  std::vector<int> original;
  ManifoldHarmonics solved;
  if (again_pieces > 0) {
    const TriangleMesh sub = sub_mesh(mesh, again, original);
    ManifoldHarmonicsOptions o;
    o.num_modes = again_pieces == 1 ? std::min(again_modes, sub.num_vertices() - 1) : again_modes;
    o.mass = basis.mass;
    o.laplacian = basis.laplacian;
    o.solver = default_eigensolver(sub.num_vertices(), o.policy);
    solved = compute_manifold_harmonics(sub, o);
  }
  // The columns, ascending: the basis's on the moving pieces not solved again, then the new.
  struct Column {
    double lambda;
    const ManifoldHarmonics* from;
    Eigen::Index j;
  };
  std::vector<Column> columns;
  for (size_t j = 0; j < piece_of_mode.size(); ++j) {
    const int c = piece_of_mode[j];
    if (moving[c] && !starved[c])
      columns.push_back({basis.eigenvalues[j], &basis, Eigen::Index(j)});
  }
  for (Eigen::Index j = 0; j < solved.basis.cols(); ++j)
    columns.push_back({solved.eigenvalues[j], &solved, j});
  std::stable_sort(columns.begin(), columns.end(),
                   [](const Column& a, const Column& b) { return a.lambda < b.lambda; });
  auto out = std::make_shared<ManifoldHarmonics>();
  out->mass = basis.mass;
  out->laplacian = basis.laplacian;
  out->approximate = basis.approximate || solved.approximate;
  out->rayleigh_ritz = basis.rayleigh_ritz && (again_pieces == 0 || solved.rayleigh_ritz);
  out->pieces = static_cast<int>(pieces.size());
  out->requested_modes = m;
  out->eigenvalues.resize(static_cast<Eigen::Index>(columns.size()));
  out->basis = Eigen::MatrixXd::Zero(mesh.num_vertices(), out->eigenvalues.size());
  for (size_t k = 0; k < columns.size(); ++k) {
    const Column& col = columns[k];
    out->eigenvalues[k] = col.lambda;
    if (col.from == &basis) {
      out->basis.col(k) = basis.basis.col(col.j);
    } else {
      for (size_t i = 0; i < original.size(); ++i)
        out->basis(original[i], k) = solved.basis(i, col.j);
    }
  }
  return out;
}

}  // namespace specdeform::detail
