// specdeform compare: one scene solved by each of our energies and by the peers, in one run:
// quality (cross-sections of closed bars, distance to the converged nonlinear solution, handle
// miss, inverted faces) against time. The peers: the paper's linear energy solved over all vertices
// with hard constraints (eq. 14), and CGAL's SR-ARAP, after as many iterations as fit in our
// ARAP frame (equal time) and converged.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "common.h"
#include "specdeform/deform/deformation_quality.h"
#include "specdeform/deform/spectral_deformer.h"
#include "specdeform/mesh/mesh_info.h"
#include "sr_arap_peer.h"

namespace specdeform::cli {

namespace {

struct Method {
  std::string name;
  Vertices result, base;  // base: the deformed smooth base (ours), or empty
  double frame_ms = 0.0, setup_ms = 0.0;
  int iterations = 0;
  bool converged = true;
};

std::string number(double v, int digits = 3) {
  std::ostringstream s;
  s << std::setprecision(digits) << v;
  return s.str();
}

// Three significant digits, whole milliseconds from 100 on (no 2.63e+04).
std::string milliseconds(double ms) {
  return ms < 100.0 ? number(ms) : std::to_string(std::lround(ms));
}

// A fraction of the diagonal in percent, two decimals (1e-17 reads 0.00).
std::string percent(double fraction) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(2) << 100.0 * fraction;
  return s.str();
}

// The longest axis of the bounding box.
int longest_axis(const Vertices& V) {
  Eigen::Index axis = 0;
  (V.colwise().maxCoeff() - V.colwise().minCoeff()).maxCoeff(&axis);
  return static_cast<int>(axis);
}

}  // namespace

void add_compare_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "compare", "one scene by each energy and by CGAL's SR-ARAP: quality against time");
  struct Args {
    std::string mesh, output, basis;
    SceneArgs scene;
    DeformArgs deform;
    TableOutputs tables;
    ManifoldHarmonicsOptions harmonics;
    int modes = 100, repeat = 5, peer_iterations = 5000;
    double peer_seconds = 120.0;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("MESH", args->mesh, "mesh file (optional with a --scene that names one)");
  args->scene.add_to(*cmd);
  args->deform.add_to(*cmd);
  cmd->add_option("-m,--modes", args->modes, "manifold harmonics used (default 100)")
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--basis", args->basis, "basis cache, as for deform");
  cmd->add_option("--repeat", args->repeat, "frames per median (default 5)")
      ->check(CLI::Range(1, 10000));
  cmd->add_option("--peer-iterations", args->peer_iterations,
                  "SR-ARAP: at most this many iterations to converge (default 5000)")
      ->check(CLI::Range(1, 10000000));
  cmd->add_option("--peer-seconds", args->peer_seconds,
                  "SR-ARAP: at most this long to converge (default 120)")
      ->check(kPositive);
  cmd->add_option("-o,--output", args->output, "folder for the results as meshes (optional)");
  args->tables.add_to(*cmd);
  add_harmonics_options(*cmd, args->harmonics);
  cmd->callback([args, cmd] {
    const LoadedScene loaded = load_scene(args->mesh, args->scene, args->deform.options);
    const TriangleMesh& mesh = loaded.mesh.mesh;
    DeformOptions options = args->deform.merged(*cmd, loaded.scene.options);
    options.validate();
    const std::vector<Eigen::Affine3d>& transforms = loaded.scene.transforms;
    const ConstrainedSet set = constrained_set(loaded.selection, mesh, options.unconstrained,
                                               loaded.mesh.info.vertex_to_file, loaded.name);
    ManifoldHarmonicsOptions h = args->harmonics;
    h.num_modes =
        loaded.scene.modes && cmd->count("--modes") == 0 ? *loaded.scene.modes : args->modes;
    const auto basis = obtain_basis(mesh, h, args->basis);
    const double diagonal = bounding_box_diagonal(mesh.V);

    std::vector<Method> methods;
    const auto ours = [&](const std::string& name, DeformOptions o) {
      std::cerr << "compare: " << name << "\n";
      // The spatial solve deforms the detailed mesh itself (eq. 14), the others its base.
      SpectralDeformer deformer(mesh, o.solver == DeformSolver::Spectral ? basis : nullptr, o);
      deformer.set_selection(loaded.selection);
      Method m;
      m.name = name;
      m.frame_ms = 1e3 * median_frame(deformer, transforms, args->repeat, &m.result).total;
      m.setup_ms = 1e3 * (deformer.setup_timings().reduced_system +
                          deformer.setup_timings().detail_factorization);
      m.base = deformer.deformed_base();
      m.iterations = deformer.arap_report().iterations;
      m.converged = deformer.arap_report().converged;
      methods.push_back(std::move(m));
      // How far the smooth base is from its own targets (those of the details are met exactly
      // by the transfer's anchors).
      return deformer.base_miss().max;
    };
    DeformOptions o = options;
    o.energy = DeformEnergy::Linear;
    std::vector<double> base_miss;
    base_miss.push_back(ours("linear, spectral", o));
    o.energy = DeformEnergy::Arap;
    base_miss.push_back(ours("ARAP, spectral", o));
    o = options;
    o.energy = DeformEnergy::Linear;
    o.solver = DeformSolver::Spatial;
    o.constraints = ConstraintMode::Hard;
    o.detail = DetailMethod::None;
    base_miss.push_back(ours("linear, all vertices, hard (eq. 14)", o));
    const double arap_frame_ms = methods[1].frame_ms;

    // SR-ARAP on the detailed mesh, hard constraints at the detailed targets.
    std::cerr << "compare: SR-ARAP (CGAL)\n";
    SrArapPeer peer(mesh, set, constraint_targets(set, mesh.V, transforms));
    const auto timed = [&](int iterations) {
      peer.reset();
      const Stopwatch clock;
      Method m;
      m.result = peer.iterate(iterations);
      m.frame_ms = 1e3 * clock.seconds();
      m.setup_ms = 1e3 * peer.setup_seconds();
      m.iterations = iterations;
      return m;
    };
    const Method probe = timed(20);
    const int equal_time = std::max(1, static_cast<int>(20 * arap_frame_ms / probe.frame_ms));
    Method equal = timed(equal_time);
    equal.name = "SR-ARAP (CGAL), equal time";
    equal.converged = false;
    // Converged: chunks of iterations until one moves no vertex by more than 1e-5 of the
    // diagonal (or the caps).
    peer.reset();
    Method converged;
    converged.name = "SR-ARAP (CGAL), converged";
    converged.setup_ms = 1e3 * peer.setup_seconds();
    converged.converged = false;
    const Stopwatch clock;
    converged.result = mesh.V;
    constexpr int kChunk = 50;
    while (converged.iterations < args->peer_iterations && clock.seconds() < args->peer_seconds) {
      Vertices next = peer.iterate(kChunk);
      converged.iterations += kChunk;
      const double change = point_distances(next, converged.result).max / diagonal;
      converged.result = std::move(next);
      if (change < 1e-5) {
        converged.converged = true;
        break;
      }
    }
    converged.frame_ms = 1e3 * clock.seconds();
    methods.push_back(std::move(equal));
    methods.push_back(std::move(converged));
    base_miss.resize(methods.size(), 0.0);

    const int axis = longest_axis(mesh.V);
    // Cross-sections are those of a closed bar; an open surface (the bumpy plane) has none.
    const bool closed = compute_mesh_info(mesh).boundary_edges == 0;
    const Vertices& reference = methods.back().result;
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    std::string table =
        "| method | frame (ms) | setup (ms) | iterations | smallest ring radius / original | vs "
        "converged SR-ARAP: RMS (% of diagonal) | max (%) | base handle miss (%) | inverted faces "
        "|\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (size_t i = 0; i < methods.size(); ++i) {
      const Method& m = methods[i];
      const std::vector<double> rings =
          closed ? cross_section_ratios(mesh.V, m.result, axis) : std::vector<double>();
      const double ring = rings.empty() ? 1.0 : *std::min_element(rings.begin(), rings.end());
      const PointDistances d = point_distances(m.result, reference);
      const int inverted = inverted_faces(mesh, m.result);
      rows.push_back({{"method", m.name},
                      {"frame_ms", m.frame_ms},
                      {"setup_ms", m.setup_ms},
                      {"iterations", m.iterations},
                      {"converged", m.converged},
                      {"smallest_cross_section",
                       rings.empty() ? nlohmann::ordered_json() : nlohmann::ordered_json(ring)},
                      {"rms_to_sr_arap", d.rms / diagonal},
                      {"max_to_sr_arap", d.max / diagonal},
                      {"base_handle_miss", base_miss[i]},
                      {"inverted_faces", inverted}});
      table +=
          "| " + m.name + " | " + milliseconds(m.frame_ms) + " | " + milliseconds(m.setup_ms) +
          " | " +
          (m.iterations > 0 ? std::to_string(m.iterations) + (m.converged ? "" : " (cap)") : "-") +
          " | " + (rings.empty() ? "-" : number(ring)) + " | " + percent(d.rms / diagonal) + " | " +
          percent(d.max / diagonal) + " | " + percent(base_miss[i]) + " | " +
          std::to_string(inverted) + " |\n";
      if (!args->output.empty()) {
        std::filesystem::create_directories(args->output);
        std::string file = m.name;
        std::replace_if(
            file.begin(), file.end(), [](char c) { return !std::isalnum(c); }, '_');
        write_result(
            std::filesystem::path(args->output) /
                (file + std::filesystem::path(loaded.mesh.file->name).extension().string()),
            loaded.mesh, m.result);
      }
    }
    args->tables.write(rows, table);
  });
}

}  // namespace specdeform::cli
