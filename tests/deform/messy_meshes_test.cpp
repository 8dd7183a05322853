// The pipeline on meshes as tools write them (support/corpus.h's messy(): zero-area faces and
// vertices, T-junctions, zero-length edges, caps, non-manifold fins, pinches, misoriented
// triangles, many small pieces): the basis converges, the rest is an exact fixed point of every
// solver, energy, detail method and Laplacian, every bend is finite, and the transfer's reaches
// its handles and carries each vertex on an edge (a T-junction, a vertex of zero area) along it.
#include <gtest/gtest.h>

#include <string>

#include "specdeform/deform/spectral_deformer.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

// Along the longest axis, the highest tenth is the handle and the lowest tenth fixed.
Selection tenths(const TriangleMesh& mesh) {
  Eigen::Index axis;
  (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).maxCoeff(&axis);
  std::vector<int> order(mesh.num_vertices());
  for (int i = 0; i < mesh.num_vertices(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return mesh.V(a, axis) < mesh.V(b, axis); });
  const size_t tenth = order.size() / 10;
  return {{{order.end() - tenth, order.end()}}, {order.begin(), order.begin() + tenth}};
}

struct Setting {
  LaplacianType laplacian;
  DeformSolver solver;
  DeformEnergy energy;
  DetailMethod detail;
};

std::string label(const std::string& mesh, const Setting& s) {
  return mesh + " " + std::string(name(s.laplacian)) + " " + std::string(name(s.solver)) + " " +
         std::string(name(s.energy)) + " " + std::string(name(s.detail));
}

std::vector<Setting> settings() {
  std::vector<Setting> out;
  for (LaplacianType laplacian : {LaplacianType::Cotan, LaplacianType::IntrinsicDelaunay})
    for (DetailMethod detail :
         {DetailMethod::Transfer, DetailMethod::Displacement, DetailMethod::Frames})
      out.push_back({laplacian, DeformSolver::Spectral, DeformEnergy::Arap, detail});
  out.push_back(
      {LaplacianType::Cotan, DeformSolver::Spectral, DeformEnergy::Linear, DetailMethod::Transfer});
  out.push_back(
      {LaplacianType::Cotan, DeformSolver::Spatial, DeformEnergy::Arap, DetailMethod::Transfer});
  out.push_back(
      {LaplacianType::Cotan, DeformSolver::Spatial, DeformEnergy::Linear, DetailMethod::Frames});
  return out;
}

TEST(MessyMeshes, TheRestIsAnExactFixedPointAndABendReachesItsHandles) {
  for (const test::MessyMesh& m : test::messy()) {
    const TriangleMesh& mesh = m.mesh;
    const double diagonal = bounding_box_diagonal(mesh.V);
    const Selection selection = tenths(mesh);
    const Eigen::Affine3d bend = Eigen::Translation3d(0.1 * diagonal, 0.0, 0.0) *
                                 Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY());
    for (LaplacianType laplacian : {LaplacianType::Cotan, LaplacianType::IntrinsicDelaunay}) {
      ManifoldHarmonicsOptions o;
      o.num_modes = 40;
      o.laplacian = laplacian;
      const auto basis =
          std::make_shared<const ManifoldHarmonics>(compute_manifold_harmonics(mesh, o));
      EXPECT_EQ(basis->status, SolveStatus::Converged) << m.name << " " << residual_summary(*basis);
      ASSERT_TRUE(basis->basis.allFinite()) << m.name;
      for (const Setting& s : settings()) {
        if (s.laplacian != laplacian) continue;
        DeformOptions options;
        options.solver = s.solver;
        options.energy = s.energy;
        options.detail = s.detail;
        SpectralDeformer deformer(mesh, basis, options);
        deformer.set_selection(selection);
        const Vertices rest = deformer.solve({Eigen::Affine3d::Identity()});
        EXPECT_TRUE(rest == mesh.V) << label(m.name, s) << ": moved by "
                                    << (rest - mesh.V).cwiseAbs().maxCoeff() / diagonal;
        const Vertices bent = deformer.solve({bend});
        ASSERT_TRUE(bent.allFinite()) << label(m.name, s);
        double miss = 0.0;
        for (const int v : selection.handles[0])
          miss =
              std::max(miss, (bent.row(v).transpose() - bend * mesh.V.row(v).transpose()).norm());
        if (s.detail != DetailMethod::Transfer) continue;  // the others meet them as the base does
        EXPECT_LT(miss, 0.01 * diagonal) << label(m.name, s);
        for (const auto& [a, q, b] : m.t_junctions) {
          const Eigen::RowVector3d mid = 0.5 * (bent.row(a) + bent.row(b));
          EXPECT_LT((bent.row(q) - mid).norm(), 1e-3 * diagonal) << label(m.name, s) << " " << q;
        }
      }
    }
  }
}

}  // namespace
}  // namespace specdeform
