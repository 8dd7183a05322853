#include <iostream>
#include <memory>

#include "common.h"
#include "specdeform/operators/laplacian.h"
#include "specdeform/spectral/spectral_transform.h"

namespace specdeform::cli {

void add_smooth_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "smooth", "low-pass a mesh: reconstruct it from its first m frequencies (paper Fig. 2)");
  struct Args {
    std::string mesh, output, basis;
    ManifoldHarmonicsOptions options;
    WriteOptions write;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("MESH", args->mesh, "mesh file")->required();
  cmd->add_option("-o,--output", args->output, "smoothed mesh to write")->required();
  cmd->add_option("-m,--modes", args->options.num_modes, "frequencies kept (default 100)")
      ->check(kPositive);
  cmd->add_option("--basis", args->basis,
                  "basis cache: read if it exists (and matches the mesh), written otherwise");
  add_harmonics_options(*cmd, args->options);
  add_write_options(*cmd, args->write);
  cmd->callback([args, cmd] {
    check_mesh_output(args->output);
    const LoadedMesh loaded = load_mesh(args->mesh);
    ManifoldHarmonicsOptions o = args->options;
    o.num_modes = modes_for(o.num_modes, cmd->count("--modes") > 0, loaded.mesh.num_vertices());
    const auto basis = obtain_basis(loaded.mesh, o, args->basis);
    const ManifoldHarmonics& h = *basis;
    const auto M = mass_matrix(loaded.mesh, h.mass, h.laplacian);
    const Eigen::MatrixXd smooth =
        harmonics_inverse(h.basis, harmonics_forward(h.basis, M, loaded.mesh.V));
    write_result(args->output, loaded, smooth, args->write);
    std::cout << "wrote " << args->output << " (" << h.basis.cols() << " frequencies)\n";
  });
}

}  // namespace specdeform::cli
