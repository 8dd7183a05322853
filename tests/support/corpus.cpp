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

namespace {

// A vertex q on the first edge a-b of every `every`-th triangle (a, b, c) of `mesh`, with the
// zero-area face (a, b, q): in turn the triangle split at q (a T-junction), or kept whole (q is
// then touched by the zero-area face alone: a vertex of zero area).
void add_t_junctions(MessyMesh& m, int every) {
  TriangleMesh& mesh = m.mesh;
  const int faces = mesh.num_faces();
  for (int f = 0; f < faces; f += every) {
    const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
    const int q = mesh.num_vertices();
    mesh.V.conservativeResize(q + 1, 3);
    mesh.V.row(q) = 0.5 * (mesh.V.row(a) + mesh.V.row(b));
    const bool split = m.t_junctions.size() % 2 == 0;
    mesh.F.conservativeResize(mesh.num_faces() + (split ? 2 : 1), 3);
    if (split) {
      mesh.F.row(f) << a, q, c;
      mesh.F.row(mesh.num_faces() - 2) << q, b, c;
    }
    mesh.F.row(mesh.num_faces() - 1) << a, b, q;  // zero area
    m.t_junctions.push_back({a, q, b});
  }
}

std::vector<MessyMesh> make_messy() {
  std::vector<MessyMesh> out;
  {
    MessyMesh m{"t_junctions_and_dust", make_bumpy_plane({1.0, 16, 2, 0.05}), {}};
    add_t_junctions(m, 7);
    TriangleMesh dust;
    dust.V.resize(5, 3);
    for (int k = 0; k < 5; ++k) dust.V.row(k) << 1.2 + 0.05 * k, 0.5, 0.1;
    dust.F.resize(3, 3);
    dust.F << 0, 1, 2, 1, 2, 3, 2, 3, 4;
    m.mesh = concatenate(m.mesh, dust);
    out.push_back(std::move(m));
  }
  {
    TriangleMesh sphere = make_icosphere(2);
    for (int f = 0; f < sphere.num_faces(); ++f)
      if (sphere.V.row(sphere.F(f, 0)).z() > 0.0) std::swap(sphere.F(f, 1), sphere.F(f, 2));
    const int fin = sphere.num_vertices();
    sphere.V.conservativeResize(fin + 1, 3);
    sphere.V.row(fin) = 1.6 * (0.5 * (sphere.V.row(sphere.F(0, 0)) + sphere.V.row(sphere.F(0, 1))));
    sphere.F.conservativeResize(sphere.num_faces() + 1, 3);
    sphere.F.row(sphere.num_faces() - 1) << sphere.F(0, 0), sphere.F(0, 1), fin;
    // A second sphere touching the first at its lowest vertex: they share it (a pinch).
    TriangleMesh other = make_icosphere(1, 0.5);
    Eigen::Index low, top;
    sphere.V.col(2).minCoeff(&low);
    other.V.col(2).maxCoeff(&top);
    other.V.rowwise() += sphere.V.row(low) - other.V.row(top);
    TriangleMesh joined = concatenate(sphere, other);
    const int shift = sphere.num_vertices(), merged = shift + static_cast<int>(top);
    for (int f = sphere.num_faces(); f < joined.num_faces(); ++f) {
      for (int k = 0; k < 3; ++k) {
        int& v = joined.F(f, k);
        v = v == merged ? static_cast<int>(low) : v > merged ? v - 1 : v;
      }
    }
    joined.V.block(merged, 0, joined.V.rows() - merged - 1, 3) =
        joined.V.bottomRows(joined.V.rows() - merged - 1).eval();
    joined.V.conservativeResize(joined.V.rows() - 1, 3);
    MessyMesh m{"misoriented_fin_pinch", joined, {}};
    add_t_junctions(m, 29);
    out.push_back(std::move(m));
  }
  {
    BumpyBarOptions bar;
    bar.cells_per_unit = 6;
    MessyMesh m{"confetti", make_bumpy_bar(bar), {}};
    add_t_junctions(m, 31);
    for (int k = 0; k < 60; ++k) {
      TriangleMesh speck;
      const bool tetrahedron = k % 2 == 0;
      speck.V.resize(tetrahedron ? 4 : 3, 3);
      speck.V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
      if (tetrahedron) speck.V.row(3) << 0, 0, 1;
      speck.V *= 0.01 * (1 + k % 5);
      speck.V.rowwise() += Eigen::RowVector3d(0.07 * k, 0.6 + 0.1 * (k % 3), 0.05 * (k % 7));
      speck.F.resize(tetrahedron ? 4 : 1, 3);
      if (tetrahedron) {
        speck.F << 0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2;
      } else {
        speck.F << 0, 1, 2;
      }
      m.mesh = concatenate(m.mesh, speck);
    }
    out.push_back(std::move(m));
  }
  {
    // Two vertices at one place, as Blender's doubles: a vertex copied, the copy taking its place
    // in one of its faces and joined to it by a zero-area face (a zero-length edge).
    TriangleMesh grid = make_bumpy_plane({1.0, 10, 1, 0.03});
    const int copy = grid.num_vertices(), a = grid.F(0, 0);
    grid.V.conservativeResize(copy + 1, 3);
    grid.V.row(copy) = grid.V.row(a);
    for (int f = 1; f < grid.num_faces(); ++f) {
      const auto corner = std::find(grid.F.row(f).begin(), grid.F.row(f).end(), a);
      if (corner == grid.F.row(f).end()) continue;
      *corner = copy;
      break;
    }
    grid.F.conservativeResize(grid.num_faces() + 1, 3);
    grid.F.row(grid.num_faces() - 1) << a, grid.F(0, 1), copy;
    MessyMesh m{"caps_and_needles", grid, {}};
    add_t_junctions(m, 3);
    // Each T-junction's vertex nudged off its edge by a hair: a cap, not a zero-area face.
    for (const auto& [a, q, b] : m.t_junctions)
      m.mesh.V(q, 2) += 1e-9 * (m.mesh.V.row(a) - m.mesh.V.row(b)).norm();
    out.push_back(std::move(m));
  }
  return out;
}

}  // namespace

const std::vector<MessyMesh>& messy() {
  static const std::vector<MessyMesh> m = make_messy();
  return m;
}

const std::vector<CorpusMesh>& corpus() {
  static const std::vector<CorpusMesh> c = make_corpus();
  return c;
}

std::filesystem::path shared_dir() {
  const std::filesystem::path p = SPECDEFORM_SHARED_DIR;
  return std::filesystem::exists(p / "meshes") ? p : std::filesystem::path();
}

}  // namespace specdeform::test
