// The folds at a turning handle's border (issue 26, point 3): each mesh's turning scene solved by
// the default pipeline, its variants and the reference, with the inverted faces of each
// (deformation_quality.h) and, for the spectral runs, the folds of the smooth base itself (against
// its rest shape) and its handle miss (the largest |s'_i - T s_i| over the diagonal). The scene:
// the benchmarks' handle (5% of the diagonal around the topmost vertex along the longest axis, the
// lowest 10% fixed), turned by 75 degrees about the shortest axis through its centroid and moved by
// 0.12 diagonals along the second-longest.
//   handle_folds [MESH...]        (default: the shared models)
#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include "specdeform/deform/deformation_quality.h"
#include "specdeform/deform/scene.h"
#include "specdeform/deform/spectral_deformer.h"
#include "specdeform/mesh/io.h"

using namespace specdeform;

namespace {

struct Variant {
  std::string name;
  DeformOptions options;
  int modes = 100;
};

std::vector<Variant> variants() {
  std::vector<Variant> out;
  out.push_back({"default", {}});
  DeformOptions o;
  o.detail = DetailMethod::Displacement;
  out.push_back({"displacement", o});
  o.detail = DetailMethod::Frames;
  out.push_back({"frames", o});
  out.push_back({"m = 300", {}, 300});
  o = {};
  o.arap.clusters = 1000;
  out.push_back({"clusters 1000", o});
  o = {};
  o.constraint_weight = 1e3;
  out.push_back({"w 1e3", o});
  o = {};
  o.energy = DeformEnergy::Linear;
  o.solver = DeformSolver::Spatial;
  o.constraints = ConstraintMode::Hard;
  o.detail = DetailMethod::None;
  out.push_back({"spatial hard linear", o});
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::filesystem::path> meshes(argv + 1, argv + argc);
  if (meshes.empty()) {
    for (const char* name : {"armadillo.obj", "camelhead.off", "stanford-bunny.obj", "beetle.off",
                             "lion.off", "elephant.obj", "homer.obj", "cheburashka.off"})
      meshes.push_back(std::filesystem::path(SPECDEFORM_SHARED_DIR) / "meshes/models" / name);
  }
  const std::vector<Variant> runs = variants();
  std::cout << "| mesh |";
  for (const Variant& v : runs) std::cout << " " << v.name << " |";
  std::cout << "\n|---|";
  for (size_t i = 0; i < runs.size(); ++i) std::cout << "---|";
  std::cout << "\n";
  for (const auto& path : meshes) {
    const TriangleMesh mesh = read_mesh(path.string()).mesh;
    Scene scene = benchmark_scene(mesh);
    const Eigen::Vector3d extent = mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff();
    int axes[3] = {0, 1, 2};
    std::sort(axes, axes + 3, [&](int a, int b) { return extent[a] > extent[b]; });
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const int v : scene.selection.handles[0]) centroid += mesh.V.row(v).transpose();
    centroid /= static_cast<double>(scene.selection.handles[0].size());
    Eigen::Vector3d move = Eigen::Vector3d::Zero();
    move[axes[1]] = 0.12 * extent.norm();
    const Eigen::Affine3d T =
        Eigen::Translation3d(move + centroid) *
        Eigen::AngleAxisd(75.0 * std::numbers::pi / 180.0, Eigen::Vector3d::Unit(axes[2])) *
        Eigen::Translation3d(-centroid);
    std::cout << "| " << path.filename().string() << " |" << std::flush;
    std::shared_ptr<const ManifoldHarmonics> basis;
    int basis_modes = 0;
    for (const Variant& v : runs) {
      if (v.options.solver == DeformSolver::Spectral && basis_modes != v.modes) {
        basis = std::make_shared<const ManifoldHarmonics>(
            compute_manifold_harmonics(mesh, {.num_modes = v.modes}));
        basis_modes = v.modes;
      }
      SpectralDeformer deformer(mesh, v.options.solver == DeformSolver::Spectral ? basis : nullptr,
                                v.options);
      deformer.set_selection(scene.selection);
      const Vertices result = deformer.solve({T});
      std::cout << " " << inverted_faces(mesh, result);
      if (v.options.solver == DeformSolver::Spectral) {
        double miss = 0.0;
        for (const int i : scene.selection.handles[0])
          miss = std::max(miss, (deformer.deformed_base().row(i).transpose() -
                                 T * deformer.base().row(i).transpose())
                                    .norm());
        std::cout << " (base "
                  << inverted_faces(TriangleMesh{deformer.base(), mesh.F}, deformer.deformed_base())
                  << ", miss " << std::setprecision(2) << 100 * miss / extent.norm() << "%)";
      }
      std::cout << " |" << std::flush;
    }
    std::cout << "\n";
  }
}
