#include "editor_session.h"

#include <chrono>
#include <cstdio>
#include <iostream>
#include <new>

#include <nlohmann/json.hpp>

#include "protocol.h"
#include "specdeform/deform/scene.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/spectral/basis_cache.h"

namespace specdeform::server {

namespace {

using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

// Messages may echo what the browser sent: bytes that are not UTF-8 are replaced, not thrown on.
std::string dump(const Json& j) {
  return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// The largest basis residual (eigen_residual) the editor works with, warning, when the solver
// falls short of its tolerance.
constexpr double kUsableResidual = 1e-6;

std::filesystem::path cache_file(const std::filesystem::path& dir, const TriangleMesh& mesh,
                                 int modes, MassType mass) {
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(mesh_hash(mesh)));
  return dir / (std::string(hash) + "-m" + std::to_string(modes) +
                (mass == MassType::Lumped ? "-lumped" : "-consistent") + ".sdbasis");
}

}  // namespace

struct EditorSession::State {
  LoadedMesh loaded;
  std::string name;
  double diagonal = 1.0;
  int modes = 100;
  DeformOptions options;
  bool base_view = false;
  std::shared_ptr<const ManifoldHarmonics> basis;
  double basis_seconds = 0.0;
  bool basis_from_cache = false;
  std::string warning;  // about the basis, shown to the user
  std::optional<SpectralDeformer> deformer;
  Selection selection;
  bool has_handles = false;
  std::vector<Eigen::Affine3d> transforms;
  uint32_t seq = 0;
  Vertices result;  // the last detailed result (the rest positions before any frame)
};

LoadedMesh demo_mesh() {
  LoadedMesh demo;
  demo.mesh = make_bumpy_bar();
  demo.info = identity_read_info(demo.mesh);
  return demo;
}

EditorSession::EditorSession(EditorConfig config, Send send)
    : config_(std::move(config)), send_(std::move(send)) {}

EditorSession::~EditorSession() = default;

void EditorSession::send_error(const std::string& message) {
  send_(false, dump(Json{{"type", "error"}, {"message", message}}));
}

void EditorSession::handle(bool binary, std::string_view message) {
  try {
    dispatch(binary, message);
  } catch (const Cancelled&) {
    throw;
  } catch (const std::bad_alloc&) {
    send_error("out of memory");
  } catch (const std::exception& e) {
    send_error(e.what());
  }
}

void EditorSession::dispatch(bool binary, std::string_view message) {
  if (!binary) return text_message(message);
  const Tag tag = message_tag(message);
  if (tag == Tag::MeshFile) {
    NamedFile file = decode_file(message);
    const std::filesystem::path name = std::filesystem::path(file.name).filename();
    LoadedMesh mesh = read_mesh_from_memory(file.data, mesh_format_from_path(name), name.string());
    return open(std::move(mesh), name.string());
  }
  if (!state_) throw InputError("no mesh is open");
  State& s = *state_;
  const int n = s.loaded.mesh.num_vertices();
  switch (tag) {
    case Tag::Selection:
      return set_selection(decode_selection(message, n));
    case Tag::Frame: {
      if (!s.has_handles) throw InputError("frame message: select a handle first");
      FrameRequest f = decode_frame(message, static_cast<int>(s.selection.handles.size()));
      s.transforms = std::move(f.transforms);
      s.seq = f.seq;
      return solve_and_send();
    }
    case Tag::SelectionFile: {
      const NamedFile file = decode_file(message);
      const int file_vertices = static_cast<int>(s.loaded.info.file_vertices.rows());
      const bool is_sel = std::filesystem::path(file.name).extension() == ".sel";
      if (!is_sel && std::filesystem::path(file.name).extension() != ".dmat") {
        throw InputError(file.name + ": a selection file is a .sel or a .dmat");
      }
      const Selection in_file = is_sel ? parse_sel(file.data, file_vertices, file.name)
                                       : parse_dmat(file.data, file_vertices, file.name);
      return send_(true, encode_selection(to_mesh_numbering(in_file, s.loaded.info)));
    }
    default:
      throw InputError("binary message: unknown tag " + std::to_string(static_cast<uint32_t>(tag)));
  }
}

void EditorSession::text_message(std::string_view message) {
  const Json j = Json::parse(message, nullptr, false);
  if (!j.is_object() || !j.contains("type") || !j["type"].is_string()) {
    throw InputError("text message: expected a JSON object with a \"type\"");
  }
  const std::string type = j["type"];
  if (type == "open_demo") {
    return open(demo_mesh(), kDemoName);
  }
  if (!state_) throw InputError("no mesh is open");
  State& s = *state_;
  if (type == "hello") return send_state();
  if (type == "settings") {
    const auto number = [&](const char* key, double lo, double hi) -> std::optional<double> {
      if (!j.contains(key)) return std::nullopt;
      if (!j[key].is_number() || !(j[key].get<double>() >= lo && j[key].get<double>() <= hi)) {
        throw InputError(std::string("settings: ") + key + " must be a number in [" +
                         std::to_string(lo) + ", " + std::to_string(hi) + "]");
      }
      return j[key].get<double>();
    };
    const auto word = [&](const char* key) -> std::optional<std::string> {
      if (!j.contains(key)) return std::nullopt;
      if (!j[key].is_string()) throw InputError(std::string("settings: ") + key + " is a string");
      return j[key].get<std::string>();
    };
    DeformOptions o = s.options;
    int modes = s.modes;
    bool base_view = s.base_view;
    if (auto v = number("modes", 1, 5000)) modes = static_cast<int>(*v);
    if (auto v = number("ks", 0, 1e6)) o.ks = *v;
    if (auto v = number("kb", 0, 1e6)) o.kb = *v;
    if (auto v = word("energy")) o.energy = deform_energy_from_name(*v);
    if (auto v = word("detail")) o.detail = detail_method_from_name(*v);
    if (auto v = word("constraints")) o.constraints = constraint_mode_from_name(*v);
    if (auto v = word("view")) {
      if (*v != "detailed" && *v != "base") throw InputError("settings: view is detailed or base");
      base_view = *v == "base";
    }
    try {
      o.validate();
    } catch (const InputError& e) {
      throw InputError(std::string("settings: ") + e.what());
    }
    if (modes >= s.loaded.mesh.num_vertices()) {
      throw InputError("settings: m must be below the vertex count (" +
                       std::to_string(s.loaded.mesh.num_vertices()) + ")");
    }
    const bool new_basis = modes != s.modes;
    const bool new_deformer = new_basis || o.energy != s.options.energy || o.ks != s.options.ks ||
                              o.kb != s.options.kb || o.detail != s.options.detail ||
                              o.constraints != s.options.constraints;
    s.base_view = base_view;
    if (new_deformer) {
      build(s.loaded, s.name, modes, o, new_basis ? nullptr : s.basis);
      config_.modes = modes;  // meshes opened later start with these settings too
      config_.options = o;
      return;
    }
    return solve_and_send();
  }
  if (type == "export_mesh") {
    const std::string format = j.value("format", "obj");
    const std::filesystem::path out =
        std::filesystem::path(s.name).stem().string() + "-deformed." + format;
    const TriangleMesh file_order = to_file_order(s.loaded.info, s.result, s.loaded.mesh.F);
    return send_(true,
                 encode_file({out.string(), encode_mesh(file_order, mesh_format_from_path(out))}));
  }
  if (type == "export_scene") {
    Scene scene;
    scene.mesh = s.name;
    scene.modes = s.modes;
    scene.options = s.options;
    const std::vector<int>& to_file = s.loaded.info.vertex_to_file;
    for (size_t g = 0; g < s.selection.handles.size(); ++g) {
      if (s.selection.handles[g].empty()) continue;
      std::vector<int> group;
      for (int v : s.selection.handles[g]) group.push_back(to_file[v]);
      scene.selection.handles.push_back(std::move(group));
      scene.transforms.push_back(g < s.transforms.size() ? s.transforms[g]
                                                         : Eigen::Affine3d::Identity());
    }
    for (int v : s.selection.fixed) scene.selection.fixed.push_back(to_file[v]);
    if (scene.selection.handles.empty()) throw InputError("export: select a handle first");
    const std::string out = std::filesystem::path(s.name).stem().string() + "-scene.json";
    return send_(true, encode_file({out, encode_scene(scene)}));
  }
  throw InputError("text message: unknown type '" + type + "'");
}

void EditorSession::open(LoadedMesh mesh, std::string name) {
  build(std::move(mesh), std::move(name), config_.modes, config_.options, nullptr);
}

void EditorSession::build(LoadedMesh mesh, std::string name, int modes,
                          const DeformOptions& options,
                          std::shared_ptr<const ManifoldHarmonics> reuse_basis) {
  cancelled_ = false;
  auto next = std::make_unique<State>();
  State& s = *next;
  s.modes = modes;
  s.options = options;
  const int n = mesh.mesh.num_vertices();
  if (n < 4) throw InputError(name + ": too few vertices to deform");
  if (s.modes >= n) s.modes = n - 1;

  Clock::time_point last_report{};
  const auto report = [&](double fraction, std::string_view stage) {
    if (cancelled_) throw Cancelled();
    if (seconds_since(last_report) < 0.1 && fraction < 1.0) return;
    last_report = Clock::now();
    send_(false, dump({{"type", "progress"}, {"stage", stage}, {"fraction", fraction}}));
  };
  const Clock::time_point start = Clock::now();
  const std::filesystem::path cache =
      config_.cache_dir.empty()
          ? std::filesystem::path()
          : cache_file(config_.cache_dir, mesh.mesh, s.modes, MassType::Lumped);
  const bool reused = reuse_basis != nullptr;
  if (reused) {
    s.basis = std::move(reuse_basis);
    s.basis_seconds = state_->basis_seconds;
    s.basis_from_cache = state_->basis_from_cache;
    s.warning = state_->warning;
  } else if (!cache.empty() && std::filesystem::exists(cache)) {
    report(0.0, "loading the basis");
    s.basis = std::make_shared<const ManifoldHarmonics>(load_basis(cache, mesh.mesh));
    s.basis_from_cache = true;
  } else {
    ManifoldHarmonicsOptions o;
    o.num_modes = s.modes;
    o.progress = report;
    auto basis = std::make_shared<ManifoldHarmonics>(compute_manifold_harmonics(mesh.mesh, o));
    s.basis = basis;
    if (basis->status != SolveStatus::Converged) {
      // Short of the tolerance but far below what a deformation can show (nearly degenerate
      // triangles limit the attainable accuracy): usable, with a warning; not cached.
      if (!(basis->max_residual <= kUsableResidual)) {
        throw SolverError(name + ": the manifold harmonics did not converge: " +
                          residual_summary(*basis, o.tolerance));
      }
      s.warning = "the basis is less accurate than asked: " + residual_summary(*basis, o.tolerance);
    } else if (!cache.empty()) {
      try {
        std::filesystem::create_directories(cache.parent_path());
        save_basis(cache, *basis, mesh.mesh, BasisPrecision::Float64);
      } catch (const std::exception& e) {
        std::cerr << "specdeform: warning: basis not cached: " << e.what() << "\n";
      }
    }
  }
  if (!reused) s.basis_seconds = seconds_since(start);
  report(1.0, "factorizing");
  s.deformer.emplace(mesh.mesh, s.basis, s.options);
  s.loaded = std::move(mesh);
  s.name = std::move(name);
  s.result = s.loaded.mesh.V;
  const Vertices& V = s.loaded.mesh.V;
  s.diagonal = bounding_box_diagonal(V);
  // Settings changes reopen the same mesh: keep the selection and the handles' transforms.
  if (state_ && state_->loaded.mesh.V.rows() == V.rows() &&
      state_->loaded.mesh.F == s.loaded.mesh.F && state_->loaded.mesh.V == V) {
    s.selection = state_->selection;
    s.transforms = state_->transforms;
    s.seq = state_->seq;
    s.base_view = state_->base_view;
    if (state_->has_handles) {
      s.deformer->set_selection(s.selection);
      s.has_handles = true;
    }
  }
  state_ = std::move(next);
  send_state();
}

void EditorSession::send_state() {
  State& s = *state_;
  send_(true, encode_mesh_message(s.loaded.mesh));
  const SetupTimings& t = s.deformer->setup_timings();
  send_(false, dump(Json{{"type", "ready"},
                         {"name", s.name},
                         {"vertices", s.loaded.mesh.num_vertices()},
                         {"faces", s.loaded.mesh.num_faces()},
                         {"diagonal", s.diagonal},
                         {"modes", s.modes},
                         {"settings",
                          {{"energy", name(s.options.energy)},
                           {"ks", s.options.ks},
                           {"kb", s.options.kb},
                           {"detail", name(s.options.detail)},
                           {"constraints", name(s.options.constraints)},
                           {"view", s.base_view ? "base" : "detailed"}}},
                         {"basis",
                          {{"seconds", s.basis_seconds},
                           {"source", s.basis_from_cache ? "cache" : "computed"},
                           {"residual", s.basis->max_residual},
                           {"warning", s.warning}}},
                         {"setup",
                          {{"reduced_system", t.reduced_system},
                           {"detail_factorization", t.detail_factorization},
                           {"selection", t.selection}}}}));
  if (s.has_handles) solve_and_send();
}

void EditorSession::set_selection(Selection selection) {
  State& s = *state_;
  size_t handle_vertices = 0;
  for (const auto& g : selection.handles) handle_vertices += g.size();
  const Clock::time_point start = Clock::now();
  if (handle_vertices > 0) s.deformer->set_selection(selection);
  s.has_handles = handle_vertices > 0;
  s.selection = std::move(selection);
  s.transforms.assign(s.selection.handles.size(), Eigen::Affine3d::Identity());
  if (!s.has_handles) s.result = s.loaded.mesh.V;
  Json sizes = Json::array();
  for (const auto& g : s.selection.handles) sizes.push_back(g.size());
  send_(false, dump({{"type", "selection"},
                     {"handles", sizes},
                     {"fixed", s.selection.fixed.size()},
                     {"seconds", seconds_since(start)}}));
}

void EditorSession::solve_and_send() {
  State& s = *state_;
  if (!s.has_handles) {
    return send_(true, encode_frame_result(s.seq, s.base_view, {}, s.loaded.mesh.V));
  }
  s.result = s.deformer->solve(s.transforms);
  const FrameTimings& t = s.deformer->frame_timings();
  const ConstraintError e = s.deformer->constraint_error(s.result);
  const FrameStats stats{t.reduced_solve, t.inverse_transform, t.detail, t.total, e.max, e.rms};
  send_(true, encode_frame_result(s.seq, s.base_view, stats,
                                  s.base_view ? s.deformer->deformed_base() : s.result));
}

}  // namespace specdeform::server
