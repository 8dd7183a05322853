#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "common.h"
#include "specdeform/exceptions.h"
#include "specdeform/spectral/basis_cache.h"

namespace specdeform::cli {

void add_basis_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("basis", "compute the first m manifold harmonics of a mesh");
  struct Args {
    std::string mesh, output;
    bool json = false, float32 = false;
    ManifoldHarmonicsOptions options;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("MESH", args->mesh, "mesh file")->required();
  cmd->add_option("-m,--modes", args->options.num_modes, "number of eigenpairs (default 100)")
      ->check(kPositive);
  cmd->add_option("-o,--output", args->output, "basis cache file to write");
  cmd->add_flag("--float32", args->float32, "store the basis in single precision");
  cmd->add_flag("--json", args->json, "print one JSON object on stdout");
  add_harmonics_options(*cmd, args->options);
  cmd->callback([args, cmd] {
    const LoadedMesh loaded = load_geometry(args->mesh);
    ManifoldHarmonicsOptions o = args->options;
    o.num_modes = modes_for(o.num_modes, cmd->count("--modes") > 0, loaded.mesh.num_vertices());
    o.progress = progress_bar("manifold harmonics");
    const Stopwatch clock;
    const ManifoldHarmonics h = compute_manifold_harmonics(loaded.mesh, o);
    const double seconds = clock.seconds();
    const bool converged = h.status == SolveStatus::Converged;
    if (!args->output.empty() && converged) {
      save_basis(args->output, h, loaded.mesh,
                 args->float32 ? BasisPrecision::Float32 : BasisPrecision::Float64);
    }
    if (!converged) {
      throw SolverError("manifold harmonics did not converge: " + residual_summary(h));
    }
    if (args->json) {
      nlohmann::ordered_json j;
      j["vertices"] = loaded.mesh.num_vertices();
      j["modes"] = h.eigenvalues.size();
      j["pieces"] = h.pieces;  // solved one by one when several: modes may exceed -m
      j["laplacian"] = name(h.laplacian);
      j["seconds"] = seconds;
      j["converged"] = converged;
      j["approximate"] = h.approximate;
      if (h.approximate) j["coarse_functions"] = h.coarse_functions;
      j["max_residual"] = h.max_residual;
      j["threshold"] = h.threshold;
      j["rounding_floor"] = h.rounding_floor;
      j["max_orthogonality_error"] = h.max_orthogonality_error;
      j["cluster_truncated"] = h.cluster_truncated;
      j["bands"] = h.bands;
      j["restarts"] = h.restarts;
      j["solves"] = h.solves;
      j["stages"] = stages_json(h.stages);  // where "seconds" went, in order
      j["eigenvalues"] = std::vector<double>(h.eigenvalues.begin(), h.eigenvalues.end());
      j["residuals"] = std::vector<double>(h.residuals.begin(), h.residuals.end());
      std::cout << json_text(j) << "\n";
    } else {
      std::cout << h.eigenvalues.size()
                << (h.approximate ? " approximate (multilevel) eigenpairs of " : " eigenpairs of ")
                << loaded.mesh.num_vertices() << " vertices"
                << (h.pieces > 1 ? " (" + std::to_string(h.pieces) + " pieces, each solved alone)"
                                 : std::string())
                << " in " << seconds << " s (residual " << h.max_residual << ", orthonormality "
                << h.max_orthogonality_error << ")\n"
                << "eigenvalues " << h.eigenvalues[0] << " ... "
                << h.eigenvalues[h.eigenvalues.size() - 1] << "\n";
      if (!args->output.empty()) std::cout << "wrote " << args->output << "\n";
    }
  });
}

}  // namespace specdeform::cli
