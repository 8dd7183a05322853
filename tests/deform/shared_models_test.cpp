// Every model of ../shared/meshes/models, and each with extra pieces of the kinds real assets
// carry (a small separate sphere, a stray triangle), through the pipeline: the mesh read and
// described, its basis, an identity deformation and the benchmarks' scene, with the invariants
// a user relies on. Skipped where ../shared is absent.
#include <gtest/gtest.h>

#include <filesystem>

#include "specdeform/deform/deformation_quality.h"
#include "specdeform/deform/scene.h"
#include "specdeform/deform/spectral_deformer.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/io.h"
#include "specdeform/mesh/mesh_info.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

std::vector<std::filesystem::path> shared_models() {
  std::vector<std::filesystem::path> out;
  const auto shared = test::shared_dir();
  if (shared.empty()) return out;
  for (const auto& entry : std::filesystem::directory_iterator(shared / "meshes" / "models")) {
    const auto extension = entry.path().extension();
    if (extension == ".obj" || extension == ".off") out.push_back(entry.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The model with a small sphere beside it and a stray triangle above it, both far smaller
// than its features: their low-pass bases collapse to points.
TriangleMesh with_debris(const TriangleMesh& mesh) {
  const double diagonal = bounding_box_diagonal(mesh.V);
  const Eigen::RowVector3d corner = mesh.V.colwise().maxCoeff();
  TriangleMesh eye = make_icosphere(1, 0.01 * diagonal);
  eye.V.rowwise() += corner + Eigen::RowVector3d(0.05 * diagonal, 0, 0);
  TriangleMesh stray;
  stray.V = Eigen::Matrix3d::Identity() * (0.005 * diagonal);
  stray.V.rowwise() += corner + Eigen::RowVector3d(0, 0.05 * diagonal, 0);
  stray.F.resize(1, 3);
  stray.F << 0, 1, 2;
  return test::concatenate(test::concatenate(mesh, eye), stray);
}

struct Outcome {
  double identity = 0.0;  // largest distance to the input, over the diagonal
  int folds = 0, reference_folds = 0;
  bool pieces_unmoved = true;
};

// The benchmarks' scene on the first piece (the model), the other pieces free.
Outcome run(const TriangleMesh& mesh) {
  const std::shared_ptr<const ManifoldHarmonics> basis =
      std::make_shared<ManifoldHarmonics>(compute_manifold_harmonics(mesh, {.num_modes = 100}));
  EXPECT_EQ(basis->status, SolveStatus::Converged);
  const Scene scene = benchmark_scene(mesh);
  int count = 0;
  const Eigen::VectorXi piece = vertex_components(mesh, &count);
  Selection selection = scene.selection;
  const auto on_model = [&](std::vector<int>& v) {
    std::erase_if(v, [&](int i) { return piece[i] != piece[0]; });
  };
  on_model(selection.handles[0]);
  on_model(selection.fixed);
  Outcome out;
  DeformOptions keep;  // the debris held, so that its vertices must come back unchanged
  keep.unconstrained = UnconstrainedPieces::Keep;
  SpectralDeformer deformer(mesh, basis, keep);
  deformer.set_selection(selection);
  out.identity = point_distances(deformer.solve({Eigen::Affine3d::Identity()}), mesh.V).max /
                 bounding_box_diagonal(mesh.V);
  const Vertices result = deformer.solve(scene.transforms);
  for (int v = 0; v < mesh.num_vertices(); ++v)
    out.pieces_unmoved &= piece[v] == piece[0] || result.row(v) == mesh.V.row(v);
  out.folds = inverted_faces(mesh, result);
  DeformOptions hard;  // the paper's eq. 14 on the detailed mesh
  hard.energy = DeformEnergy::Linear;
  hard.solver = DeformSolver::Spatial;
  hard.constraints = ConstraintMode::Hard;
  hard.detail = DetailMethod::None;
  hard.unconstrained = UnconstrainedPieces::Keep;
  SpectralDeformer reference(mesh, nullptr, hard);
  reference.set_selection(selection);
  out.reference_folds = inverted_faces(mesh, reference.solve(scene.transforms));
  return out;
}

TEST(SharedModels, ThroughThePipeline) {
  const auto models = shared_models();
  if (models.empty()) GTEST_SKIP() << "../shared is absent";
  for (const auto& path : models) {
    const LoadedMesh loaded = read_mesh(path);
    const MeshInfo info = compute_mesh_info(loaded.mesh);
    EXPECT_GT(info.area, 0.0) << path;
    for (const bool debris : {false, true}) {
      const TriangleMesh mesh = debris ? with_debris(loaded.mesh) : loaded.mesh;
      const Outcome o = run(mesh);
      const std::string name = path.filename().string() + (debris ? " with debris" : "");
      std::cout << name << ": identity " << o.identity << ", folds " << o.folds
                << " (hard spatial solve " << o.reference_folds << ")\n";
      EXPECT_LT(o.identity, 1e-6) << name;
      EXPECT_LE(o.folds, o.reference_folds) << name;
      EXPECT_TRUE(o.pieces_unmoved) << name;
    }
  }
}

}  // namespace
}  // namespace specdeform
