#include <filesystem>
#include <iostream>
#include <memory>
#include <numbers>

#include "common.h"
#include "specdeform/deform/spectral_deformer.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/mesh_info.h"
#include "specdeform/spectral/basis_cache.h"

namespace specdeform::cli {

void add_demo_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "demo", "bend the built-in bumpy bar and write every stage of the pipeline to a folder");
  struct Args {
    std::string output = "demo";
    int modes = 100;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("-o,--output", args->output, "folder for the results (default: demo)");
  cmd->add_option("-m,--modes", args->modes, "number of frequencies (default 100)")
      ->check(CLI::Range(1, 100000));
  cmd->callback([args] {
    const std::filesystem::path dir = args->output;
    std::filesystem::create_directories(dir);
    const TriangleMesh bar = make_bumpy_bar();
    const MeshInfo info = compute_mesh_info(bar);
    std::cout << "model: bumpy bar, " << info.vertices << " vertices, " << info.faces << " faces\n";

    ManifoldHarmonicsOptions o;
    o.num_modes = args->modes;
    const Stopwatch clock;
    const auto basis = obtain_basis(bar, o, "");
    const ManifoldHarmonics& h = *basis;
    std::cout << "basis: " << h.eigenvalues.size() << " manifold harmonics in " << clock.seconds()
              << " s (residual " << h.max_residual << ", orthonormality "
              << h.max_orthogonality_error << ")\n";
    save_basis(dir / "basis.sdbasis", h, bar);

    // The left end is held, the right end turns 90 degrees about z and comes round (bar-bend).
    Selection selection;
    selection.handles.resize(1);
    for (int i = 0; i < bar.num_vertices(); ++i) {
      if (bar.V(i, 0) < 0.4) selection.fixed.push_back(i);
      if (bar.V(i, 0) > 3.6) selection.handles[0].push_back(i);
    }
    const Eigen::Affine3d bend = Eigen::Translation3d(2.0, 1.6, 0.0) *
                                 Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ()) *
                                 Eigen::Translation3d(-3.6, 0.0, 0.0);
    SpectralDeformer deformer(bar, basis);
    deformer.set_selection(selection);
    const Vertices result = deformer.solve({bend});
    const FrameTimings& t = deformer.frame_timings();
    std::cout << "deformation: " << selection.handles[0].size() << " handle and "
              << selection.fixed.size() << " fixed vertices; selection "
              << deformer.setup_timings().selection * 1e3 << " ms, frame " << t.total * 1e3
              << " ms (reduced solve " << t.reduced_solve * 1e3 << ", inverse transform "
              << t.inverse_transform * 1e3 << ", details " << t.detail * 1e3 << ")\n";
    write_mesh(dir / "1_original.obj", bar);
    write_mesh(dir / "2_smooth.obj", TriangleMesh{deformer.base(), bar.F});
    write_mesh(dir / "3_smooth_deformed.obj", TriangleMesh{deformer.deformed_base(), bar.F});
    write_mesh(dir / "4_deformed.obj", TriangleMesh{result, bar.F});
    std::cout << "wrote " << dir.string()
              << "/{1_original,2_smooth,3_smooth_deformed,4_deformed}.obj and basis.sdbasis\n";
  });
}

}  // namespace specdeform::cli
