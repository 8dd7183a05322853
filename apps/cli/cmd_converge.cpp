// specdeform converge: the paper's Fig. 6 experiment. One scene deformed with m = m_1 < ... < m_k
// frequencies (one basis of m_k pairs, truncated), each result's distance to the m_k result, and
// each smooth displacement's distance to the spatial solution of the same energy.
#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "common.h"
#include "specdeform/deform/spectral_deformer.h"
#include "specdeform/mesh/surface_distance.h"
#include "specdeform/operators/mass_matrix.h"

namespace specdeform::cli {

namespace {

// RMS and maximum of the per-vertex distances between two fields on one mesh, over `scale`.
std::pair<double, double> distances(const Vertices& a, const Vertices& b, double scale) {
  const Eigen::VectorXd d = (a - b).rowwise().norm();
  return {std::sqrt(d.squaredNorm() / d.size()) / scale, d.maxCoeff() / scale};
}

std::string number(double v) {
  std::ostringstream s;
  s << std::setprecision(3) << v;
  return s.str();
}

}  // namespace

void add_converge_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "converge", "deform one scene with several m and compare (the paper's Fig. 6)");
  struct Args {
    std::string mesh, output;
    TableOutputs tables;
    SceneArgs scene;
    std::vector<int> modes{50, 100, 200, 300, 500, 900};
    DeformArgs deform;
    ManifoldHarmonicsOptions harmonics;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("MESH", args->mesh, "mesh file (optional with a --scene that names one)");
  args->scene.add_to(*cmd);
  cmd->add_option("-m,--modes", args->modes, "frequencies to compare (default 50 ... 900)")
      ->check(CLI::Range(1, 100000));
  cmd->add_option("-o,--output", args->output, "folder for the deformed meshes (optional)");
  args->tables.add_to(*cmd);
  args->deform.add_to(*cmd);
  add_harmonics_options(*cmd, args->harmonics);
  cmd->callback([args, cmd] {
    const LoadedScene s = load_scene(args->mesh, args->scene, args->deform.options);
    const TriangleMesh& mesh = s.mesh.mesh;
    DeformOptions options = args->deform.merged(*cmd, s.scene.options);
    options.validate();
    // Every check of the selection before the basis, which may take long.
    constrained_set(s.selection, mesh, options.unconstrained, s.mesh.info.vertex_to_file, s.name);
    std::vector<int> modes = args->modes;
    std::sort(modes.begin(), modes.end());
    modes.erase(std::unique(modes.begin(), modes.end()), modes.end());
    ManifoldHarmonicsOptions h = args->harmonics;
    h.num_modes = modes.back();
    const auto full_basis = obtain_basis(mesh, h, "");
    const ManifoldHarmonics& full = *full_basis;
    const double diagonal = bounding_box_diagonal(mesh.V);

    // The spatial solution of the same energy and constraints (the smooth displacement's limit).
    DeformOptions spatial = options;
    spatial.solver = DeformSolver::Spatial;
    spatial.detail = DetailMethod::None;
    SpectralDeformer reference(mesh, ManifoldHarmonics{}, spatial);
    reference.set_selection(s.selection);
    const Vertices spatial_displacement = reference.solve(s.scene.transforms) - mesh.V;
    const Eigen::VectorXd mass = lumped_mass(mesh);
    const auto m_norm = [&](const Vertices& d) {
      return std::sqrt((d.rowwise().squaredNorm().transpose() * mass).value());
    };

    std::vector<Vertices> results, bases;
    for (const int m : modes) {
      ManifoldHarmonics truncated = full;
      truncated.basis.conservativeResize(Eigen::NoChange, m);
      truncated.eigenvalues.conservativeResize(m);
      SpectralDeformer d(mesh, std::move(truncated), options);
      d.set_selection(s.selection);
      results.push_back(d.solve(s.scene.transforms));
      bases.push_back(d.deformed_base());
      if (!args->output.empty()) {
        const std::filesystem::path dir = args->output;
        std::filesystem::create_directories(dir);
        const std::string tag = "m" + std::to_string(m);
        const std::string ext = std::filesystem::path(s.mesh.file->name).extension().string();
        write_result(dir / (tag + "_smooth_deformed" + ext), s.mesh, d.deformed_base());
        write_result(dir / (tag + "_deformed" + ext), s.mesh, results.back());
        if (m == modes.front()) {
          write_result(dir / ("spatial_deformed" + ext), s.mesh, mesh.V + spatial_displacement);
        }
      }
      // The smooth displacement d_m = s'_m - s_m against the spatial one.
      const Vertices displacement = d.deformed_base() - d.base();
      const double error =
          m_norm(displacement - spatial_displacement) / m_norm(spatial_displacement);
      std::cerr << "converge: m = " << m << ", ||d_m - d_spatial||_M / ||d_spatial||_M = " << error
                << "\n";
      bases.back() = displacement;
    }
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    std::string table =
        "| m | result vs m = " + std::to_string(modes.back()) +
        ": RMS | Hausdorff | smooth displacement vs m = " + std::to_string(modes.back()) +
        ": RMS | max | smooth displacement vs spatial (M-norm) |\n"
        "|---:|---:|---:|---:|---:|---:|\n";
    for (size_t i = 0; i < modes.size(); ++i) {
      const double rms = distances(results[i], results.back(), diagonal).first;
      const double hausdorff =
          hausdorff_distance({results[i], mesh.F}, {results.back(), mesh.F}) / diagonal;
      const auto [base_rms, base_max] = distances(bases[i], bases.back(), diagonal);
      const double spatial_error =
          m_norm(bases[i] - spatial_displacement) / m_norm(spatial_displacement);
      rows.push_back({{"modes", modes[i]},
                      {"rms", rms},
                      {"hausdorff", hausdorff},
                      {"base_rms", base_rms},
                      {"base_max", base_max},
                      {"displacement_vs_spatial", spatial_error}});
      table += "| " + std::to_string(modes[i]) + " | " + number(rms) + " | " + number(hausdorff) +
               " | " + number(base_rms) + " | " + number(base_max) + " | " + number(spatial_error) +
               " |\n";
    }
    args->tables.write(rows, table);
  });
}

}  // namespace specdeform::cli
