// specdeform bench: the measurements of the paper's Table 1 (and Fig. 5 with several -m),
// against the spatial solver of the same energy, from scratch (the paper's last column) and
// prefactored (one back-substitution per frame, the honest competitor).
#include <sys/resource.h>

#include <algorithm>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "common.h"
#include "specdeform/deform/scene.h"
#include "specdeform/deform/spectral_deformer.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/subdivide.h"

namespace specdeform::cli {

namespace {

double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;
}

nlohmann::ordered_json bench_mesh(const std::string& name, const TriangleMesh& mesh, int modes,
                                  int repeat, const ManifoldHarmonicsOptions& harmonics,
                                  const DeformOptions& options) {
  const Scene scene = benchmark_scene(mesh);
  nlohmann::ordered_json j;
  j["mesh"] = name;
  j["vertices"] = mesh.num_vertices();
  j["faces"] = mesh.num_faces();
  j["modes"] = modes;
  j["energy"] = specdeform::name(options.energy);
  j["handle_vertices"] = scene.selection.handles[0].size();
  j["fixed_vertices"] = scene.selection.fixed.size();

  ManifoldHarmonicsOptions o = harmonics;
  o.num_modes = modes;
  Stopwatch clock;
  ManifoldHarmonics basis = compute_manifold_harmonics(mesh, o);
  j["PT1_basis"] = clock.seconds();
  j["basis_stages"] = stages_json(basis.stages);
  if (basis.status != SolveStatus::Converged) throw SolverError(name + ": basis did not converge");

  clock = Stopwatch();
  SpectralDeformer d(mesh, std::move(basis), options);
  const double analysis = d.setup_timings().detail_factorization;  // once per mesh
  d.set_selection(scene.selection);
  const SetupTimings& setup = d.setup_timings();
  j["PT2_reduced_system"] = setup.reduced_system + (setup.selection - setup.detail_factorization);
  j["PT3_detail_factorization"] = analysis + setup.detail_factorization;
  const FrameTimings f = median_frame(d, scene.transforms, repeat);
  j["RT1_reduced_solve"] = f.reduced_solve;
  j["inverse_transform"] = f.inverse_transform;
  j["RT2_detail"] = f.detail;
  j["frame"] = f.total;
  j["iterations"] = d.arap_report().iterations;
  d.solve(scene.transforms);
  j["base_miss_max"] = d.base_miss().max;

  // The spatial solve of the same energy on the detailed mesh (eq. 14): from scratch (its
  // factorisation included, as the paper's last column) and prefactored.
  DeformOptions spatial;
  spatial.solver = DeformSolver::Spatial;
  spatial.detail = DetailMethod::None;
  spatial.constraints = ConstraintMode::Hard;
  clock = Stopwatch();
  SpectralDeformer reference(mesh, ManifoldHarmonics{}, spatial);
  reference.set_selection(scene.selection);
  reference.solve(scene.transforms);
  j["spatial_from_scratch"] = clock.seconds();
  j["spatial_prefactored_frame"] = median_frame(reference, scene.transforms, repeat).total;
  j["peak_rss_MB"] = peak_rss_mb();
  return j;
}

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

std::string markdown(const nlohmann::ordered_json& rows) {
  std::string s =
      "| mesh | vertices | m | PT1 basis (s) | PT2 reduced (ms) | PT3 detail factor (ms) | "
      "RT1 reduced solve (ms) | inverse transform (ms) | RT2 detail (ms) | frame (ms) | "
      "spatial prefactored frame (ms) | spatial from scratch (s) | peak RSS (MB) |\n"
      "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const auto& r : rows) {
    s += "| " + r["mesh"].get<std::string>() + " | " + std::to_string(r["vertices"].get<int>()) +
         " | " + std::to_string(r["modes"].get<int>()) + " | " +
         fixed(r["PT1_basis"].get<double>(), 2) + " | " +
         fixed(1e3 * r["PT2_reduced_system"].get<double>(), 1) + " | " +
         fixed(1e3 * r["PT3_detail_factorization"].get<double>(), 1) + " | " +
         fixed(1e3 * r["RT1_reduced_solve"].get<double>(), 2) + " | " +
         fixed(1e3 * r["inverse_transform"].get<double>(), 2) + " | " +
         fixed(1e3 * r["RT2_detail"].get<double>(), 2) + " | " +
         fixed(1e3 * r["frame"].get<double>(), 2) + " | " +
         fixed(1e3 * r["spatial_prefactored_frame"].get<double>(), 2) + " | " +
         fixed(r["spatial_from_scratch"].get<double>(), 3) + " | " +
         fixed(r["peak_rss_MB"].get<double>(), 0) + " |\n";
  }
  return s;
}

}  // namespace

void add_bench_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "bench", "measure the paper's Table 1 on meshes, against the spatial solver, in one run");
  struct Args {
    std::vector<std::string> meshes;
    std::vector<int> subdivide{0};
    std::vector<int> modes{100};
    int repeat = 21;
    bool quick = false;
    TableOutputs tables;
    ManifoldHarmonicsOptions harmonics;
    DeformArgs deform;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("MESHES", args->meshes, "meshes to measure (default: generated bumpy bars)");
  cmd->add_option("--subdivide", args->subdivide,
                  "also measure each mesh Loop-subdivided this many times (e.g. 0 1 2)")
      ->check(CLI::Range(0, 3));
  cmd->add_option("-m,--modes", args->modes,
                  "manifold harmonics, one row per value (default 100; e.g. 50 100 200 500 1000 "
                  "for the paper's Fig. 5)")
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--repeat", args->repeat, "frames per median (default 21)")
      ->check(CLI::Range(1, 100000));
  cmd->add_flag("--quick", args->quick, "small generated meshes, a few seconds (for tests)");
  args->tables.add_to(*cmd);
  args->deform.add_to(*cmd);
  add_harmonics_options(*cmd, args->harmonics);
  cmd->callback([args, cmd] {
    const DeformOptions options = args->deform.merged(*cmd, DeformOptions{});
    options.validate();
    std::vector<std::pair<std::string, TriangleMesh>> meshes;
    for (const std::string& path : args->meshes) {
      meshes.emplace_back(std::filesystem::path(path).stem().string(), load_geometry(path).mesh);
    }
    if (meshes.empty()) {
      for (const int cells : args->quick ? std::vector<int>{6, 10} : std::vector<int>{16, 32, 49}) {
        BumpyBarOptions o;
        o.cells_per_unit = cells;
        meshes.emplace_back("bumpy-bar-" + std::to_string(cells), make_bumpy_bar(o));
      }
    }
    const int repeat = args->quick ? std::min(args->repeat, 3) : args->repeat;
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    for (const auto& [name, mesh] : meshes) {
      for (const int levels : args->subdivide) {
        const std::string label =
            levels == 0 ? name : name + " (subdivided " + std::to_string(levels) + "x)";
        const TriangleMesh measured = levels == 0 ? mesh : subdivide(mesh, levels);
        for (const int m : args->modes) {
          const int modes = args->quick ? std::min(m, 40) : m;
          std::cerr << "bench: " << label << ", m = " << modes << "\n";
          rows.push_back(bench_mesh(label, measured, modes, repeat, args->harmonics, options));
        }
      }
    }
    const std::string table = markdown(rows);
    args->tables.write(rows, table);
  });
}

}  // namespace specdeform::cli
