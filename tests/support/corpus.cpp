#include "support/corpus.h"

#include <algorithm>

#include "specdeform/mesh/generate.h"

namespace specdeform::test {

TriangleMesh concatenate(const TriangleMesh& a, const TriangleMesh& b) {
  TriangleMesh out;
  out.V.resize(a.V.rows() + b.V.rows(), 3);
  out.V << a.V, b.V;
  out.F.resize(a.F.rows() + b.F.rows(), 3);
  out.F << a.F, (b.F.array() + static_cast<int>(a.V.rows())).matrix();
  return out;
}

PieceScene first_piece_scene(const TriangleMesh& mesh, const Eigen::VectorXi& label) {
  std::vector<int> piece;
  for (int v = 0; v < mesh.num_vertices(); ++v)
    if (label[v] == 0) piece.push_back(v);
  std::sort(piece.begin(), piece.end(), [&](int a, int b) { return mesh.V(a, 2) < mesh.V(b, 2); });
  const size_t tenth = std::max<size_t>(1, piece.size() / 10);
  const double diagonal = bounding_box_diagonal(mesh.V);
  return {{{{piece.end() - tenth, piece.end()}}, {piece.begin(), piece.begin() + tenth}},
          Eigen::Translation3d(0.0, 0.05 * diagonal, 0.1 * diagonal) *
              Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitX())};
}

namespace {

std::vector<CorpusMesh> make_corpus() {
  std::vector<CorpusMesh> c;
  c.push_back({"icosphere3", Category::Closed, make_icosphere(3)});
  c.push_back({"torus", Category::Closed, make_torus(1.0, 0.35, 36, 12)});
  BumpyBarOptions bar;
  bar.cells_per_unit = 6;
  c.push_back({"bumpy_bar", Category::Closed, make_bumpy_bar(bar)});
  BumpyPlaneOptions plane;
  plane.resolution = 30;
  plane.bumps = 3;
  c.push_back({"bumpy_plane", Category::Boundary, make_bumpy_plane(plane)});
  TriangleMesh shifted = make_icosphere(2);
  shifted.V.col(0).array() += 3.0;
  c.push_back({"two_spheres", Category::Components, concatenate(make_icosphere(2), shifted), 2});
  // Pieces whose low-pass base collapses at m = 100 (only their constant mode): a small sphere
  // beside a torus (an eye), a stray triangle beside a bar, a lid with a knob on a sphere.
  TriangleMesh eye = make_icosphere(1, 0.05);
  eye.V.col(0).array() += 1.5;
  c.push_back(
      {"torus_and_eye", Category::Components, concatenate(make_torus(1.0, 0.35, 36, 12), eye), 2});
  TriangleMesh stray;
  stray.V.resize(3, 3);
  stray.V << 4.3, 0.0, 0.0, 4.305, 0.002, 0.0, 4.302, 0.005, 0.001;
  stray.F.resize(1, 3);
  stray.F << 0, 1, 2;
  c.push_back(
      {"bar_and_stray_triangle", Category::Components, concatenate(make_bumpy_bar(bar), stray), 2});
  TriangleMesh lid = make_icosphere(2, 0.6), knob = make_icosphere(1, 0.1);
  lid.V.col(2) *= 0.25;
  lid.V.col(2).array() += 1.15;
  knob.V.col(2).array() += 1.35;
  c.push_back({"sphere_lid_and_knob", Category::Components,
               concatenate(concatenate(make_icosphere(3), lid), knob), 3});
  // Awkward: a zero-area triangle on three collinear boundary vertices, and a fin on the edge
  // (0, 1), which then has three faces (non-manifold).
  TriangleMesh sliver = make_bumpy_plane({1.0, 12, 1, 0.0});
  const int fin = static_cast<int>(sliver.V.rows());
  sliver.V.conservativeResize(fin + 1, 3);
  sliver.V.row(fin) = 0.5 * (sliver.V.row(0) + sliver.V.row(1)) + Eigen::RowVector3d(0, 0, 0.05);
  sliver.F.conservativeResize(sliver.F.rows() + 2, 3);
  sliver.F.row(sliver.F.rows() - 2) << 0, 1, 2;
  sliver.F.row(sliver.F.rows() - 1) << 1, 0, fin;
  c.push_back({"sliver_and_fin", Category::Awkward, sliver});
  return c;
}

}  // namespace

const std::vector<CorpusMesh>& corpus() {
  static const std::vector<CorpusMesh> c = make_corpus();
  return c;
}

std::filesystem::path shared_dir() {
  const std::filesystem::path p = SPECDEFORM_SHARED_DIR;
  return std::filesystem::exists(p / "meshes") ? p : std::filesystem::path();
}

}  // namespace specdeform::test
