#include "common.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>

#include "specdeform/atomic_file.h"
#include "specdeform/exceptions.h"
#include "specdeform/spectral/basis_cache.h"
#include "specdeform/spectral/basis_store.h"

namespace specdeform::cli {

namespace {

CLI::Validator number_check(bool allow_zero) {
  return CLI::Validator(
      [allow_zero](std::string& text) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(text, v) || !std::isfinite(v)) {
          return "'" + text + "' is not a number";
        }
        if (v < 0.0 || (v == 0.0 && !allow_zero)) {
          return "'" + text + (allow_zero ? "' must be >= 0" : "' must be > 0");
        }
        return {};
      },
      allow_zero ? "NUMBER>=0" : "NUMBER>0");
}

}  // namespace

const CLI::Validator kPositive = number_check(false);
const CLI::Validator kNonNegative = number_check(true);

namespace {

// Name -> mode, the names from the library (deform_options.h).
template <typename Mode>
std::map<std::string, Mode> by_name(std::initializer_list<Mode> modes) {
  std::map<std::string, Mode> out;
  for (Mode m : modes) out.emplace(name(m), m);
  return out;
}

}  // namespace

void DeformArgs::add_to(CLI::App& cmd) {
  static const auto kEnergies = by_name({DeformEnergy::Linear, DeformEnergy::Arap});
  static const auto kDetails = by_name({DetailMethod::None, DetailMethod::Displacement,
                                        DetailMethod::Frames, DetailMethod::Transfer});
  static const auto kSolvers = by_name({DeformSolver::Spectral, DeformSolver::Spatial});
  static const auto kConstraints = by_name({ConstraintMode::Soft, ConstraintMode::Hard});
  static const auto kPieces =
      by_name({UnconstrainedPieces::Follow, UnconstrainedPieces::Keep, UnconstrainedPieces::Error});
  const DeformOptions defaults;
  const auto fallback = [](auto value) {
    std::ostringstream s;
    s << " (default " << value << ")";
    return s.str();
  };
  cmd.add_option("--energy", options.energy,
                 "linear (the paper's shell) | arap (as-rigid-as-possible)" +
                     fallback(name(defaults.energy)))
      ->transform(CLI::CheckedTransformer(kEnergies, CLI::ignore_case));
  cmd.add_option(
         "--iterations", options.arap.max_iterations,
         "ARAP: at most this many iterations per frame" + fallback(defaults.arap.max_iterations))
      ->check(CLI::Range(1, 1000000));
  cmd.add_option("--arap-tolerance", options.arap.tolerance,
                 "ARAP: stop when an iteration lowers the energy by less than this fraction" +
                     fallback(defaults.arap.tolerance))
      ->check(kNonNegative);
  cmd.add_option("--history", options.arap.history,
                 "ARAP: L-BFGS pairs kept, 0: plain local/global" + fallback(defaults.arap.history))
      ->check(CLI::Range(0, 50));
  cmd.add_option("--arap-bending", options.arap.bending,
                 "ARAP: bending weight against the membrane's 1" + fallback(defaults.arap.bending))
      ->check(kNonNegative);
  cmd.add_option("--clusters", options.arap.clusters,
                 "ARAP: rotation clusters" + fallback(defaults.arap.clusters))
      ->check(CLI::Range(1, 100000000));
  cmd.add_option("--ks", options.ks, "linear: stretching weight" + fallback(defaults.ks))
      ->check(kNonNegative);
  cmd.add_option("--kb", options.kb, "linear: bending weight" + fallback(defaults.kb))
      ->check(kNonNegative);
  cmd.add_option("--weight", options.constraint_weight,
                 "soft-constraint weight" + fallback(defaults.constraint_weight))
      ->check(kPositive);
  cmd.add_option("--detail", options.detail,
                 "none | displacement | frames | transfer" + fallback(name(defaults.detail)))
      ->transform(CLI::CheckedTransformer(kDetails, CLI::ignore_case));
  cmd.add_option("--solver", options.solver,
                 "spectral | spatial (the reference)" + fallback(name(defaults.solver)))
      ->transform(CLI::CheckedTransformer(kSolvers, CLI::ignore_case));
  cmd.add_option("--constraints", options.constraints,
                 "soft | hard" + fallback(name(defaults.constraints)))
      ->transform(CLI::CheckedTransformer(kConstraints, CLI::ignore_case));
  cmd.add_option("--unconstrained", options.unconstrained,
                 "pieces without handle or fixed vertex: follow (the surface around them) | "
                 "keep | error" +
                     fallback(name(defaults.unconstrained)))
      ->transform(CLI::CheckedTransformer(kPieces, CLI::ignore_case));
}

DeformOptions DeformArgs::merged(const CLI::App& cmd, const DeformOptions& scene) const {
  DeformOptions o = scene;
  const auto flag = [&](const char* name) { return cmd.count(name) > 0; };
  if (flag("--energy")) o.energy = options.energy;
  if (flag("--iterations")) o.arap.max_iterations = options.arap.max_iterations;
  if (flag("--arap-tolerance")) o.arap.tolerance = options.arap.tolerance;
  if (flag("--history")) o.arap.history = options.arap.history;
  if (flag("--clusters")) o.arap.clusters = options.arap.clusters;
  if (flag("--arap-bending")) o.arap.bending = options.arap.bending;
  if (flag("--ks")) o.ks = options.ks;
  if (flag("--kb")) o.kb = options.kb;
  if (flag("--weight")) o.constraint_weight = options.constraint_weight;
  if (flag("--detail")) o.detail = options.detail;
  if (flag("--solver")) o.solver = options.solver;
  if (flag("--constraints")) o.constraints = options.constraints;
  if (flag("--unconstrained")) o.unconstrained = options.unconstrained;
  return o;
}

namespace {

LoadedMesh load(const std::string& path, const ReadOptions& options) {
  LoadedMesh loaded = read_mesh(path, options);
  const MeshReadInfo& info = loaded.info;
  if (info.unused_vertices > 0) {
    std::cerr << path << ": note: " << info.unused_vertices
              << " vertices used by no face were dropped (outputs keep the file's numbering)\n";
  }
  if (info.collapsed_faces > 0) {
    std::cerr << path << ": note: " << info.collapsed_faces
              << " faces repeating a vertex were dropped\n";
  }
  if (info.duplicate_faces > 0) {
    std::cerr << path << ": note: " << info.duplicate_faces
              << " faces on the same three vertices as an earlier face were dropped\n";
  }
  return loaded;
}

}  // namespace

LoadedMesh load_mesh(const std::string& path, Confinement confinement) {
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  return load(path, {.keep_file = true, .companions = folder_resolver(folder, confinement)});
}

LoadedMesh load_geometry(const std::string& path) {
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  return load(path, {.companions = folder_resolver(folder, Confinement::Relative)});
}

void add_write_options(CLI::App& cmd, WriteOptions& options) {
  static const auto kNormals =
      by_name({NormalUpdate::Follow, NormalUpdate::Recompute, NormalUpdate::Rotate});
  cmd.add_option("--normals", options.normals,
                 "the file's normals: follow (carried by each face's deformation, default), "
                 "recompute (from the new faces) or rotate (by each vertex's rotation)")
      ->transform(CLI::CheckedTransformer(kNormals, CLI::ignore_case));
  static const auto kTargets = by_name({MorphTargets::Turn, MorphTargets::Keep});
  cmd.add_option("--morph-targets", options.morph_targets,
                 "a glTF's morph targets: turn (each delta turned with the surface at its "
                 "vertex, default) or keep")
      ->transform(CLI::CheckedTransformer(kTargets, CLI::ignore_case));
  static const auto kJoints = by_name({Joints::Follow, Joints::Keep});
  cmd.add_option("--joints", options.joints,
                 "a glTF's skins: follow (joints move with the vertices they drive, with their "
                 "inverse bind matrices, rest transforms and animation keys; default) or keep")
      ->transform(CLI::CheckedTransformer(kJoints, CLI::ignore_case));
}

void write_result(const std::filesystem::path& path, const LoadedMesh& loaded, const Vertices& V,
                  const WriteOptions& options) {
  const Vertices positions = to_file_order(loaded.info, V, loaded.mesh.F).V;
  for (const std::string& note : write_mesh_file(path, *loaded.file, positions, options)) {
    std::cerr << path.string() << ": note: " << note << "\n";
  }
}

ProgressCallback progress_bar(const std::string& label) {
  if (!isatty(STDERR_FILENO)) return {};
  return [label, last = -1](double fraction, std::string_view stage) mutable {
    const int percent = static_cast<int>(fraction * 100.0);
    if (percent == last && fraction < 1.0) return;
    last = percent;
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(fraction * kWidth);
    std::fprintf(stderr, "\r%s [%s%s] %3d%% %-24.*s", label.c_str(),
                 std::string(filled, '#').c_str(), std::string(kWidth - filled, ' ').c_str(),
                 percent, static_cast<int>(stage.size()), stage.data());
    if (fraction >= 1.0) std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
  };
}

nlohmann::ordered_json stages_json(const std::vector<StageTime>& stages) {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for (const StageTime& t : stages) j[t.stage] = t.seconds;
  return j;
}

std::string json_text(const nlohmann::ordered_json& j, int indent) {
  return j.dump(indent, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

void add_eigensolver_option(CLI::App& cmd, EigenSolver& solver) {
  static const auto kSolver =
      by_name({EigenSolver::BlockKrylov, EigenSolver::Lanczos, EigenSolver::Multilevel});
  cmd.add_option("--eigensolver", solver,
                 "krylov (block Krylov-Schur, exact), lanczos (Spectra, the baseline) or "
                 "multilevel (an approximate basis, linear in n); default: krylov, or for deform "
                 "and edit multilevel from 200,000 vertices")
      ->transform(CLI::CheckedTransformer(kSolver, CLI::ignore_case));
}

void add_harmonics_options(CLI::App& cmd, ManifoldHarmonicsOptions& o) {
  static const std::map<std::string, MassType> kMass{{"lumped", MassType::Lumped},
                                                     {"consistent", MassType::Consistent}};
  static const auto kLaplacian = by_name({LaplacianType::Cotan, LaplacianType::IntrinsicDelaunay});
  cmd.add_option("--mass", o.mass, "mass matrix: lumped (default) or consistent")
      ->transform(CLI::CheckedTransformer(kMass, CLI::ignore_case));
  cmd.add_option("--laplacian", o.laplacian,
                 "cotan (the mesh's triangles, default) or intrinsic-delaunay (robust to slivers "
                 "and non-manifold edges)")
      ->transform(CLI::CheckedTransformer(kLaplacian, CLI::ignore_case));
  add_eigensolver_option(cmd, o.solver);
  cmd.add_option("--tolerance", o.tolerance, "eigenpair residual to reach (default 1e-8)")
      ->check(kPositive);
  cmd.add_option("--band-size", o.band_size, "eigenpairs per shift (default: automatic)")
      ->check(kNonNegative);
  cmd.add_option("--block-size", o.block_size, "right-hand sides per solve (default: automatic)")
      ->check(kNonNegative);
}

void TableOutputs::add_to(CLI::App& cmd) {
  cmd.add_option("--json", json, "write the rows as JSON to this file");
  cmd.add_option("--markdown", markdown, "write a markdown table to this file");
}

void TableOutputs::write(const nlohmann::ordered_json& rows, const std::string& table) const {
  if (!json.empty()) write_file_atomically(json, json_text(rows, 2) + "\n");
  if (!markdown.empty()) write_file_atomically(markdown, table);
  std::cout << table;
}

void SceneArgs::add_to(CLI::App& cmd) {
  auto* sel_opt =
      cmd.add_option("--sel", sel, "Botsch-Sorkine selection (0 fixed, 1 free, 2 handle)");
  auto* dmat_opt = cmd.add_option("--dmat", dmat, "libigl selection (-1 free, k handle group k)");
  auto* def_opt = cmd.add_option("--def", def, "handle transforms: 4x4 row-major, one per group");
  auto* scene_opt = cmd.add_option("--scene", scene, "JSON scene (see docs/scene.md)");
  cmd.add_option("--influence", influence,
                 "hold the surface farther than this fraction of the diagonal from the handles "
                 "(along the surface; overrides the scene's)")
      ->check(kPositive);
  sel_opt->excludes(dmat_opt)->excludes(scene_opt)->needs(def_opt);
  dmat_opt->excludes(scene_opt)->needs(def_opt);
  def_opt->excludes(scene_opt);
}

LoadedScene load_scene(const std::string& mesh_path, const SceneArgs& args,
                       const DeformOptions& defaults) {
  if (args.sel.empty() && args.dmat.empty() && args.scene.empty()) {
    throw CLI::ValidationError("scene", "give --sel and --def, --dmat and --def, or --scene");
  }
  std::string path = mesh_path;
  if (path.empty()) {
    if (args.scene.empty()) throw CLI::ValidationError("MESH", "MESH is required");
    path = scene_mesh(args.scene).string();
    if (path.empty()) throw InputError(args.scene + ": the scene names no mesh; give MESH");
  }
  LoadedScene out{load_mesh(path), {}, {}, {}};
  const MeshReadInfo& info = out.mesh.info;
  const int file_vertices = static_cast<int>(info.file_vertices.rows());
  if (!args.scene.empty()) {
    out.scene = read_scene(args.scene, info, defaults);
  } else {
    out.scene.options = defaults;
    out.scene.selection =
        args.sel.empty() ? read_dmat(args.dmat, file_vertices) : read_sel(args.sel, file_vertices);
    out.scene.transforms = read_def(args.def);
  }
  out.scene.transforms = match_transforms(out.scene.selection, out.scene.transforms);
  const std::string& name = !args.scene.empty() ? args.scene
                            : !args.sel.empty() ? args.sel
                                                : args.dmat;
  out.name = name;
  std::vector<std::string> notes;
  if (args.influence > 0.0) out.scene.influence = args.influence;
  out.selection = scene_selection(out.scene, out.mesh, &notes, name);
  for (const std::string& note : notes) std::cerr << name << ": note: " << note << "\n";
  return out;
}

FrameTimings median_frame(SpectralDeformer& deformer,
                          const std::vector<Eigen::Affine3d>& transforms, int repeat,
                          Vertices* result) {
  std::vector<double> reduced, inverse, detail, total;
  for (int r = 0; r < repeat; ++r) {
    Vertices frame = deformer.solve(transforms);
    if (result != nullptr) *result = std::move(frame);
    const FrameTimings& t = deformer.frame_timings();
    reduced.push_back(t.reduced_solve);
    inverse.push_back(t.inverse_transform);
    detail.push_back(t.detail);
    total.push_back(t.total);
  }
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  return {median(reduced), median(inverse), median(detail), median(total)};
}

void check_mesh_output(const std::string& path) {
  mesh_format_from_path(path);
  check_writable(path);
}

int modes_for(int requested, bool asked, int vertices) {
  if (asked) return requested;
  const int modes = default_modes(vertices);
  if (modes < requested) {
    std::cerr << "note: m = " << modes << ": the mesh has only " << vertices
              << " vertices (the default is " << requested << " modes)\n";
  }
  return modes;
}

std::shared_ptr<const ManifoldHarmonics> obtain_basis(const TriangleMesh& mesh,
                                                      const ManifoldHarmonicsOptions& options,
                                                      const std::string& cache, bool* loaded) {
  ManifoldHarmonicsOptions o = options;
  o.progress = progress_bar("manifold harmonics");
  ObtainedBasis basis = specdeform::obtain_basis(mesh, o, cache);
  if (loaded != nullptr) *loaded = basis.loaded;
  if (!basis.warning.empty()) std::cerr << "warning: " << basis.warning << "\n";
  if (!basis.loaded && basis.harmonics->cluster_truncated) {
    std::cerr << "note: m = " << options.num_modes
              << " ends inside a cluster of equal eigenvalues; the last basis vectors are one "
                 "arbitrary choice within it\n";
  }
  return std::move(basis.harmonics);
}

}  // namespace specdeform::cli
