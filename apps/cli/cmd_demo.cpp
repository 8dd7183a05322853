#include <filesystem>
#include <iostream>
#include <memory>

#include "common.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/mesh_info.h"
#include "specdeform/operators/mass_matrix.h"
#include "specdeform/spectral/basis_cache.h"
#include "specdeform/spectral/spectral_transform.h"

namespace specdeform::cli {

void add_demo_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "demo", "run the pipeline on the built-in bumpy bar and write every stage to a folder");
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
    write_mesh(dir / "original.obj", bar);
    const MeshInfo info = compute_mesh_info(bar);
    std::cout << "model: bumpy bar, " << info.vertices << " vertices, " << info.faces << " faces\n";

    ManifoldHarmonicsOptions o;
    o.num_modes = args->modes;
    const Stopwatch clock;
    const ManifoldHarmonics h = obtain_basis(bar, o, "");
    std::cout << "basis: " << h.eigenvalues.size() << " manifold harmonics in " << clock.seconds()
              << " s (residual " << h.max_residual << ", orthonormality "
              << h.max_orthogonality_error << ")\n";
    save_basis(dir / "basis.sdbasis", h, bar);

    const auto M = mass_matrix(bar, h.mass);
    const Eigen::MatrixXd smooth = harmonics_inverse(h.basis, harmonics_forward(h.basis, M, bar.V));
    write_mesh(dir / "smooth.obj", TriangleMesh{smooth, bar.F});
    std::cout << "wrote " << (dir / "original.obj").string() << ", "
              << (dir / "smooth.obj").string() << " and " << (dir / "basis.sdbasis").string()
              << "\n";
  });
}

}  // namespace specdeform::cli
