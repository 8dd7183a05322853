#include <algorithm>
#include <iostream>
#include <map>
#include <memory>

#include <nlohmann/json.hpp>

#include "common.h"
#include "specdeform/deform/scene.h"
#include "specdeform/deform/spectral_deformer.h"
#include "specdeform/exceptions.h"

namespace specdeform::cli {

// A base miss beyond this fraction of the diagonal is said on stderr.
constexpr double kLooseMiss = 0.005;

void add_deform_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("deform", "deform a mesh by handles: spectral or spatial solve");
  struct Args {
    std::string mesh, output, basis;
    SceneArgs scene;
    int modes = 100, repeat = 1;
    bool json = false;
    DeformArgs deform;
    ManifoldHarmonicsOptions harmonics;
    WriteOptions write;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("MESH", args->mesh, "mesh file (optional with a --scene that names one)");
  cmd->add_option("-o,--output", args->output, "deformed mesh to write")->required();
  args->scene.add_to(*cmd);
  cmd->add_option("-m,--modes", args->modes, "manifold harmonics used (default 100)")
      ->check(CLI::Range(1, 1000000));
  args->deform.add_to(*cmd);
  cmd->add_flag("--float32", args->deform.options.float32_basis,
                "single-precision basis in the frame");
  cmd->add_option("--basis", args->basis,
                  "basis cache: read if it exists (and matches the mesh), written otherwise");
  cmd->add_option("--repeat", args->repeat,
                  "solve the frame N times, report medians (default 1; one solve frees the basis "
                  "before the details' factorisation, N > 1 keeps both in memory)")
      ->check(CLI::Range(1, 100000));
  cmd->add_flag("--json", args->json, "print one JSON object with timings and errors");
  add_harmonics_options(*cmd, args->harmonics);
  add_write_options(*cmd, args->write);
  cmd->callback([args, cmd] {
    check_mesh_output(args->output);
    nlohmann::ordered_json timings;
    Stopwatch clock;
    // The scene's settings override the defaults; options given on the command line win.
    const LoadedScene loaded_scene = load_scene(args->mesh, args->scene, args->deform.options);
    const LoadedMesh& loaded = loaded_scene.mesh;
    const Scene& scene = loaded_scene.scene;
    const Selection& selection = loaded_scene.selection;
    DeformOptions options = args->deform.merged(*cmd, scene.options);
    options.float32_basis = args->deform.options.float32_basis;
    options.single_solve = args->repeat == 1;  // the basis released before the details
    options.validate();
    int modes = args->modes;
    if (cmd->count("--modes") == 0 && scene.modes) modes = *scene.modes;
    modes = modes_for(modes, cmd->count("--modes") > 0 || scene.modes.has_value(),
                      loaded.mesh.num_vertices());

    // Every check of the selection before the basis, which may take long.
    const ConstrainedSet constrained =
        constrained_set(selection, loaded.mesh, options.unconstrained, loaded.info.vertex_to_file,
                        loaded_scene.name);

    timings["read"] = clock.seconds();
    std::shared_ptr<const ManifoldHarmonics> basis;
    bool loaded_basis = false;
    if (options.solver == DeformSolver::Spectral) {
      ManifoldHarmonicsOptions h = args->harmonics;
      h.num_modes = modes;
      if (cmd->count("--eigensolver") == 0) {
        h.solver = default_eigensolver(loaded.mesh.num_vertices(), h.policy);
      }
      clock = Stopwatch();
      basis = obtain_basis(loaded.mesh, h, args->basis, &loaded_basis);
      timings["basis"] = clock.seconds();
      timings["basis_stages"] = stages_json(basis->stages);
    } else {
      timings["basis"] = 0.0;
    }
    clock = Stopwatch();
    const bool approximate = basis && basis->approximate;
    SpectralDeformer deformer(loaded.mesh, std::move(basis), options);
    deformer.set_selection(selection);
    timings["setup"] = clock.seconds();  // the deformer's, reduced_system and the details' below
    Vertices result;
    const FrameTimings frame = median_frame(deformer, scene.transforms, args->repeat, &result);
    if (!result.allFinite()) throw SolverError("the deformation produced non-finite positions");
    if (options.constraints == ConstraintMode::Soft && deformer.base_miss().max > kLooseMiss) {
      std::cerr << "note: the smooth base misses its handles by " << 100 * deformer.base_miss().max
                << "% of the diagonal: soft constraints of weight " << options.constraint_weight
                << " hold them this loosely (a larger --weight, or --constraints hard, holds "
                   "them closer)\n";
    }
    clock = Stopwatch();
    write_result(args->output, loaded, result, args->write);
    timings["write"] = clock.seconds();
    const SetupTimings& s = deformer.setup_timings();
    const ConstraintError& miss = deformer.base_miss();
    const ArapReport& arap = deformer.arap_report();
    timings["reduced_system"] = s.reduced_system;
    timings["detail_factorization"] = s.detail_factorization;
    timings["selection"] = s.selection;
    timings["frame"] = {{"reduced_solve", frame.reduced_solve},
                        {"inverse_transform", frame.inverse_transform},
                        {"detail", frame.detail},
                        {"total", frame.total}};
    if (args->json) {
      nlohmann::ordered_json j;
      j["vertices"] = loaded.mesh.num_vertices();
      j["modes"] = options.solver == DeformSolver::Spectral ? modes : 0;
      j["basis_cached"] = loaded_basis;
      j["basis_approximate"] = approximate;
      j["constrained_vertices"] = constrained.first_free;
      j["free_pieces"] = constrained.free_pieces;
      j["unconstrained"] = name(options.unconstrained);
      j["constrained_piece_modes"] = deformer.constrained_piece_modes();
      j["energy"] = name(options.energy);
      if (options.energy == DeformEnergy::Arap) {
        j["iterations"] = arap.iterations;
        j["quasi_newton_steps"] = arap.accelerated;
        j["relative_energy_change"] = arap.relative_change;
        j["tolerance"] = options.arap.tolerance;
        j["converged"] = arap.converged;
        j["clusters"] = deformer.rotation_clusters();
      }
      j["detail_fold_zone"] = deformer.detail_fold_zone();
      j["timings"] = timings;
      j["base_miss"] = {{"max", miss.max}, {"rms", miss.rms}};
      j["output"] = args->output;
      std::cout << json_text(j) << "\n";
    } else {
      std::cout << "wrote " << args->output << ": frame " << frame.total * 1e3
                << " ms, the smooth base misses its targets by max " << miss.max << " rms "
                << miss.rms << " (of the bounding-box diagonal)";
      if (options.energy == DeformEnergy::Arap) {
        std::cout << "; ARAP " << arap.iterations << " iterations, last relative energy change "
                  << arap.relative_change << (arap.converged ? "" : " (not converged)");
      }
      if (deformer.detail_fold_zone() > 0) {
        std::cout << "; the smooth base folded: details added as displacements on "
                  << deformer.detail_fold_zone() << " faces";
      }
      if (constrained.free_pieces > 0) {
        std::cout << "; " << constrained.free_pieces << " pieces without handle or fixed vertex "
                  << (options.unconstrained == UnconstrainedPieces::Follow
                          ? "moved with the surface around them"
                          : "held in place");
      }
      std::cout << "\n";
    }
  });
}

}  // namespace specdeform::cli
