#include "editor_session.h"

#include "archive.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <future>
#include <iostream>
#include <new>
#include <utility>

#include <nlohmann/json.hpp>

#include "basis_store.h"
#include "pose.h"
#include "preview.h"
#include "specdeform/deform/influence.h"
#include "specdeform/deform/scene.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/spectral/basis_cache.h"
#include "specdeform/spectral/basis_store.h"

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

// Undo steps kept, and poses whose basis stays in memory (older ones are computed again, or
// loaded from the cache, when an undo returns to them).
constexpr size_t kHistory = 200;
constexpr int kPoseBases = 3;
// The basis is computed at this nice value (Linux), as the transfer's factorisation is.
constexpr int kBasisNice = 5;

// Lowers the calling thread's priority (and that of the threads it starts) to `nice`.
void lower_this_thread(int nice) {
  setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), nice);
}

std::string hex(uint64_t v) {
  char s[17];
  std::snprintf(s, sizeof s, "%016llx", static_cast<unsigned long long>(v));
  return s;
}

Json matrix(const Eigen::Affine3d& t) {
  Json out = Json::array();
  for (int i = 0; i < 16; ++i) out.push_back(t.matrix()(i / 4, i % 4));
  return out;
}

const char* tag_name(Tag tag) {
  switch (tag) {
    case Tag::Selection:
      return "selection";
    case Tag::Frame:
      return "frame";
    case Tag::MeshFile:
      return "mesh_file";
    case Tag::SelectionFile:
      return "selection_file";
    case Tag::SceneFile:
      return "scene_file";
    case Tag::CompanionFile:
      return "companion_file";
    default:
      return "binary";
  }
}

// A scene uploaded by the browser names its vertices itself: files it would refer to are not
// the browser's to open on the server's disk.
void check_self_contained(const std::string& text, const std::string& name) {
  const Json j = Json::parse(text, nullptr, false);
  if (!j.is_object()) throw InputError(name + ": not a JSON object");
  const auto refers = [](const Json& item) {
    return item.is_object() && item.contains("selection");
  };
  bool refers_to_file = j.contains("fixed") && refers(j["fixed"]);
  if (j.contains("handles") && j["handles"].is_array()) {
    for (const Json& h : j["handles"]) refers_to_file = refers_to_file || refers(h);
  }
  if (refers_to_file) {
    throw InputError(name +
                     ": a scene opened in the editor must list its vertices (a "
                     "\"selection\" file cannot be read from the browser)");
  }
}

// The companions uploaded with a mesh file: by their name, or (the browser sends no folders) by
// the last part of it. A name that leaves the mesh file's folder is refused, as on disk.
FileResolver uploaded_companions(std::shared_ptr<const std::map<std::string, std::string>> files) {
  return [files](const std::string& name) -> std::optional<std::string> {
    const std::filesystem::path path(name);
    if (path.is_absolute() || std::find(path.begin(), path.end(), "..") != path.end()) {
      throw InputError(name + ": refused (a name outside the mesh file's folder)");
    }
    for (const std::string& key : {name, path.filename().string()}) {
      if (const auto it = files->find(key); it != files->end()) return it->second;
    }
    return std::nullopt;
  };
}

// Writes `basis` to the cache file `file`; returns the "saving" message that says how it went.
Json save_and_report(const std::filesystem::path& file, const ManifoldHarmonics& basis,
                     const TriangleMesh& mesh) {
  const Clock::time_point start = Clock::now();
  Json out = {{"type", "saving"}, {"file", file.filename().string()}, {"done", true}};
  try {
    save_basis(file, basis, mesh, cache_precision(basis));
    out["bytes"] = std::filesystem::file_size(file);
    out["error"] = "";
  } catch (const std::exception& e) {
    std::cerr << "specdeform: warning: basis not cached: " << e.what() << "\n";
    out["error"] = e.what();
  }
  out["seconds"] = seconds_since(start);
  return out;
}

// At most this many companions wait for their mesh file.
constexpr size_t kMaxCompanions = 64;

}  // namespace

struct Pose {
  Vertices rest;
  std::string id;  // mesh_hash of the rest shape
};

struct Entry {  // one undo step
  GroupSelection edit;
  int pose = 0;
};

struct EditorSession::State {
  LoadedMesh loaded;  // as read: the file's numbering, and the first pose's positions
  std::string name;
  std::vector<Pose> poses;
  std::optional<Appearance> appearance;  // the file's look (appearance.h)
  std::vector<PreparedBasis> bases;      // of each pose
  int pose = 0;
  double diagonal = 1.0;
  int modes = 100;
  DeformOptions options;
  bool base_view = false;
  std::optional<SpectralDeformer> deformer;
  GroupSelection edit;
  bool has_handles = false;
  std::vector<Entry> history;
  size_t at = 0;
  uint32_t seq = 0;
  Vertices result;                     // the last detailed result (the rest shape before any frame)
  bool result_stale = false;           // previews were solved since
  std::optional<PreviewMesh> preview;  // drawn during drags (SpectralDeformer::preview)
  double selection_seconds = 0.0, pin_error = 0.0;
  double influence = 0.0;  // the region of influence, of the diagonal (0: none)
  // The last full frame sent added displacements while the transfer's factorisation ran.
  bool shown_displacements = false;

  const Vertices& rest() const { return poses[pose].rest; }
  // What the deformers solve for the edit's selection: the surface beyond the region of
  // influence fixed too.
  Selection solved(const Selection& edit) const {
    return influence > 0.0 ? limit_influence(rest_mesh(pose), edit, influence * diagonal) : edit;
  }
  TriangleMesh rest_mesh(int p) const { return {poses[p].rest, loaded.mesh.F}; }
  const PreparedBasis& basis() const { return bases[pose]; }
};

LoadedMesh demo_mesh() {
  LoadedMesh demo;
  demo.mesh = make_bumpy_bar();
  demo.info = identity_read_info(demo.mesh);
  return demo;
}

EditorSession::EditorSession(EditorConfig config, Send send, Post post)
    : config_(std::move(config)), send_(std::move(send)), post_(std::move(post)) {}

EditorSession::~EditorSession() = default;

void EditorSession::send_error(const std::string& message, bool cancelled) {
  send_(false, dump(Json{{"type", "error"},
                         {"message", message},
                         {"request", request_},
                         {"cancelled", cancelled}}));
}

void EditorSession::handle(bool binary, std::string_view message) {
  request_ = binary ? "binary" : "text";
  // The browser shows the settings in force again after a rejected change.
  if (!answer([&] { dispatch(binary, message); }) && request_ == "settings" && state_) {
    send_ready();
  }
}

std::optional<std::string> EditorSession::start(LoadedMesh mesh, std::string name) {
  request_ = "open";
  if (answer([&] { open(std::move(mesh), std::move(name)); })) return std::nullopt;
  if (!state_) send_(false, dump({{"type", "empty"}, {"request", request_}}));
  return last_error_;
}

bool EditorSession::answer(const std::function<void()>& work) {
  try {
    work();
    return true;
  } catch (const Cancelled&) {
    last_error_ = state_ ? "cancelled: nothing changed" : "cancelled: no mesh is open";
    send_error(last_error_, true);
  } catch (const std::bad_alloc&) {
    last_error_ = "out of memory";
    send_error(last_error_);
  } catch (const std::exception& e) {
    last_error_ = e.what();
    send_error(last_error_);
  }
  return false;
}

void EditorSession::dispatch(bool binary, std::string_view message) {
  if (!binary) return text_message(message);
  const Tag tag = message_tag(message);
  request_ = tag_name(tag);
  if (tag == Tag::CompanionFile) {
    NamedFile file = decode_file(message);
    if (!companions_) companions_ = std::make_shared<std::map<std::string, std::string>>();
    if (companions_->size() >= kMaxCompanions) {
      throw InputError(file.name + ": more than " + std::to_string(kMaxCompanions) +
                       " files sent with one mesh");
    }
    (*companions_)[std::filesystem::path(file.name).filename().string()] = std::move(file.data);
    return;
  }
  if (tag == Tag::MeshFile) {
    NamedFile file = decode_file(message);
    const std::filesystem::path name = std::filesystem::path(file.name).filename();
    auto companions = std::move(companions_);
    if (!companions) companions = std::make_shared<std::map<std::string, std::string>>();
    LoadedMesh mesh = read_mesh_from_memory(
        file.data, mesh_format_from_path(name), name.string(),
        {.keep_file = true, .companions = uploaded_companions(std::move(companions))});
    return open(std::move(mesh), name.string());
  }
  if (!state_) throw InputError("no mesh is open");
  State& s = *state_;
  const int n = s.loaded.mesh.num_vertices();
  switch (tag) {
    case Tag::Selection: {
      GroupSelection edit = decode_selection(message, n);
      const bool echo = edit.echo;
      return set_edit(std::move(edit), true, echo);
    }
    case Tag::Frame: {
      if (!s.has_handles) throw InputError("frame message: select a handle first");
      const FrameRequest f = decode_frame(message, static_cast<int>(s.edit.transforms.size()));
      for (size_t g = 0; g < f.transforms.size(); ++g) {
        if (!s.edit.pinned[g]) s.edit.transforms[g] = f.transforms[g];
      }
      s.seq = f.seq;
      return solve_and_send(f.preview);
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
      GroupSelection edit;
      edit.selection = to_mesh_numbering(in_file, s.loaded.info);
      const size_t groups = edit.selection.handles.size();
      edit.transforms.assign(groups, Eigen::Affine3d::Identity());
      edit.pinned.assign(groups, false);
      edit.fit.assign(groups, false);
      return set_edit(std::move(edit), true, true);
    }
    case Tag::SceneFile:
      return open_scene(decode_file(message));
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
  request_ = type;
  if (type == "open_demo") return open(demo_mesh(), kDemoName);
  if (type == "hello" && !state_)
    return send_(false, dump({{"type", "empty"}, {"request", request_}}));
  if (type == "cancel") return;  // nothing runs: there is nothing to cancel
  if (!state_) throw InputError("no mesh is open");
  State& s = *state_;
  if (type == "hello") {
    resend_edit(!j.value("has_mesh", false));
    return send_state();
  }
  if (type == "settings") return change_settings(message);
  if (type == "commit") {
    commit();
    return send_state();
  }
  if (type == "undo" || type == "redo") {
    const bool undo = type == "undo";
    if (undo ? s.at == 0 : s.at + 1 >= s.history.size()) {
      throw InputError(undo ? "nothing to undo" : "nothing to redo");
    }
    return restore(undo ? s.at - 1 : s.at + 1);
  }
  if (type == "apply_pose") return apply_pose();
  if (type == "preview") {
    if (!j.contains("vertices") || !j["vertices"].is_number_integer()) {
      throw InputError("preview: \"vertices\" is a whole number");
    }
    const int64_t k = j["vertices"].get<int64_t>();
    s.preview = make_preview(s.rest_mesh(s.pose),
                             static_cast<int>(std::clamp<int64_t>(k, 0, s.rest().rows())));
    return send_(true, encode_preview(*s.preview));
  }
  if (type == "export_mesh") {
    const std::string own = std::filesystem::path(s.name).extension().string();
    const std::string format = j.value("format", own.empty() ? "obj" : own.substr(1));
    const std::filesystem::path out =
        std::filesystem::path(s.name).stem().string() + "-deformed." + format;
    WriteOptions write;
    write.morph_targets = morph_targets_from_name(j.value("morph_targets", "turn"));
    write.joints = joints_from_name(j.value("joints", "follow"));
    const TriangleMesh file_order = to_file_order(s.loaded.info, result(true), s.loaded.mesh.F);
    if (!s.loaded.file) {  // a mesh made here (the demo)
      return send_(
          true, encode_file({out.string(), encode_mesh(file_order, mesh_format_from_path(out))}));
    }
    // One download that works where it is saved: the file alone, or an archive of it with
    // every file it names (a .gltf's buffers and images, an OBJ's MTL and its images).
    EncodedMesh encoded = encode_mesh_file(*s.loaded.file, file_order.V, out, write);
    for (const std::string& name : encoded.companions) {
      std::optional<std::string> bytes;
      try {
        bytes = s.loaded.file->companions ? s.loaded.file->companions(name) : std::nullopt;
      } catch (const InputError&) {
      }
      if (bytes) {
        encoded.files.push_back({name, std::move(*bytes)});
      } else {
        encoded.notes.push_back(name + ", which it names, was not found: not in the export");
      }
    }
    for (const std::string& note : encoded.notes) {
      send_(false, dump({{"type", "note"}, {"message", out.string() + ": " + note}}));
    }
    if (encoded.files.size() == 1) {
      return send_(true, encode_file({out.string(), std::move(encoded.files[0].bytes)}));
    }
    const std::string archive = out.stem().string() + ".zip";
    return send_(true, encode_file({archive, zip_archive(encoded.files)}));
  }
  if (type == "export_scene") {
    if (s.pose > 0) {
      throw InputError(
          "export scene: a scene moves the file's shape, and a pose was applied "
          "since (export the mesh, or undo to before the pose)");
    }
    Scene scene;
    scene.mesh = s.name;
    scene.modes = s.modes;
    scene.options = s.options;
    if (s.influence > 0.0) scene.influence = s.influence;
    const std::vector<int>& to_file = s.loaded.info.vertex_to_file;
    const Selection& selection = s.edit.selection;
    for (size_t g = 0; g < selection.handles.size(); ++g) {
      if (selection.handles[g].empty()) continue;
      std::vector<int> group;
      for (int v : selection.handles[g]) group.push_back(to_file[v]);
      scene.selection.handles.push_back(std::move(group));
      scene.transforms.push_back(s.edit.transforms[g]);
    }
    for (int v : selection.fixed) scene.selection.fixed.push_back(to_file[v]);
    if (scene.selection.handles.empty()) throw InputError("export: select a handle first");
    const std::string out = std::filesystem::path(s.name).stem().string() + "-scene.json";
    return send_(true, encode_file({out, encode_scene(scene)}));
  }
  throw InputError("text message: unknown type '" + type + "'");
}

void EditorSession::change_settings(std::string_view message) {
  State& s = *state_;
  const Json j = Json::parse(message);
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
  double influence = s.influence;
  if (auto v = number("influence", 0, 10)) influence = *v;
  if (auto v = number("ks", 0, 1e6)) o.ks = *v;
  if (auto v = number("kb", 0, 1e6)) o.kb = *v;
  if (auto v = word("energy")) o.energy = deform_energy_from_name(*v);
  if (auto v = word("detail")) o.detail = detail_method_from_name(*v);
  if (auto v = word("constraints")) o.constraints = constraint_mode_from_name(*v);
  if (auto v = word("unconstrained")) o.unconstrained = unconstrained_pieces_from_name(*v);
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
  const bool new_influence = influence != s.influence;
  s.influence = influence;
  const bool new_basis = modes != s.modes;
  const bool new_deformer = new_basis || o.energy != s.options.energy || o.ks != s.options.ks ||
                            o.kb != s.options.kb || o.detail != s.options.detail ||
                            o.constraints != s.options.constraints ||
                            o.unconstrained != s.options.unconstrained;
  if (new_deformer) {
    const PreparedBasis basis = new_basis ? compute_basis(s.rest_mesh(s.pose), modes) : s.basis();
    if (new_basis) progress("setting up the solver", 1.0, false);
    SpectralDeformer deformer(s.rest_mesh(s.pose), basis.harmonics, o);
    if (s.has_handles) deformer.set_selection(s.solved(s.edit.selection));
    s.deformer.emplace(std::move(deformer));
    watch_detail();
    if (new_basis) {  // the other poses' bases have the old m
      for (PreparedBasis& b : s.bases) b.harmonics.reset();
      s.bases[s.pose] = basis;
      save_in_background();
    }
    s.modes = modes;
    s.options = o;
    config_.modes = modes;  // meshes opened later start with these settings too
    config_.options = o;
  } else if (new_influence && s.has_handles) {
    s.deformer->set_selection(s.solved(s.edit.selection));
  }
  s.base_view = base_view;
  solve_and_send();
  send_ready();
}

void EditorSession::set_edit(GroupSelection edit, bool record, bool echo) {
  State& s = *state_;
  const size_t groups = edit.selection.handles.size();
  if (edit.transforms.size() != groups || edit.pinned.size() != groups) {
    throw InputError("selection: one transform and one flag per group");
  }
  edit.fit.resize(groups, false);
  double pin_error = 0.0;
  for (size_t g = 0; g < groups; ++g) {
    if (!edit.fit[g] || !edit.pinned[g] || edit.selection.handles[g].empty()) continue;
    const FittedTransform fit = fit_transform(s.rest(), result(), edit.selection.handles[g]);
    edit.transforms[g] = fit.transform;
    pin_error = std::max(pin_error, fit.max_error / s.diagonal);
  }
  edit.fit.assign(groups, false);
  edit.echo = false;
  size_t handle_vertices = 0;
  for (const auto& g : edit.selection.handles) handle_vertices += g.size();
  const Clock::time_point start = Clock::now();
  if (handle_vertices > 0) {
    try {
      s.deformer->set_selection(s.solved(edit.selection));
    } catch (...) {
      if (s.has_handles) s.deformer->set_selection(s.solved(s.edit.selection));
      throw;
    }
  }
  s.selection_seconds = seconds_since(start);
  s.pin_error = pin_error;
  s.has_handles = handle_vertices > 0;
  s.edit = std::move(edit);
  if (!s.has_handles) s.result = s.rest(), s.result_stale = false;
  if (record) push_history();
  if (echo) send_selection();
  if (s.has_handles) solve_and_send();
  send_state();
}

void EditorSession::push_history() {
  State& s = *state_;
  s.history.resize(s.at + 1);
  s.history.push_back({s.edit, s.pose});
  if (s.history.size() > kHistory) s.history.erase(s.history.begin());
  s.at = s.history.size() - 1;
}

void EditorSession::commit() {
  const State& s = *state_;
  const auto& before = s.history[s.at].edit.transforms;
  const bool moved = !std::equal(
      before.begin(), before.end(), s.edit.transforms.begin(), s.edit.transforms.end(),
      [](const Eigen::Affine3d& a, const Eigen::Affine3d& b) { return a.matrix() == b.matrix(); });
  if (moved) push_history();
}

void EditorSession::restore(size_t entry) {
  State& s = *state_;
  const Entry& e = s.history[entry];
  if (e.pose != s.pose) {
    PreparedBasis& basis = s.bases[e.pose];
    if (!basis.harmonics) {
      basis = compute_basis(s.rest_mesh(e.pose), s.modes);
      progress("setting up the solver", 1.0, false);
    }
    SpectralDeformer deformer(s.rest_mesh(e.pose), basis.harmonics, s.options);
    s.deformer.emplace(std::move(deformer));
    watch_detail();
    s.pose = e.pose;
    save_in_background();
    s.has_handles = false;
    s.result = s.rest();
    s.result_stale = false;
    send_mesh();
    send_ready();
  }
  s.at = entry;
  set_edit(s.history[entry].edit, false, true);
}

void EditorSession::apply_pose() {
  State& s = *state_;
  if (!s.has_handles) throw InputError("apply pose: nothing is moved yet (drag a handle first)");
  const TriangleMesh posed{result(true), s.loaded.mesh.F};
  PreparedBasis basis;
  const Clock::time_point start = Clock::now();
  auto reused = std::make_shared<ManifoldHarmonics>(reuse_basis(posed, *s.basis().harmonics));
  if (reused->max_residual <= kReuseResidual) {
    basis.seconds = seconds_since(start);
    basis.source = "reused";
    basis.harmonics = std::move(reused);
  } else {
    reused.reset();
    basis = compute_basis(posed, s.modes);
    progress("setting up the solver", 1.0, false);
  }
  SpectralDeformer deformer(posed, basis.harmonics, s.options);
  commit();  // undo returns to the pose as it was dragged
  // Handles keep their vertices from here; pins become fixed where they are.
  GroupSelection edit;
  edit.selection.fixed = s.edit.selection.fixed;
  for (size_t g = 0; g < s.edit.selection.handles.size(); ++g) {
    const std::vector<int>& group = s.edit.selection.handles[g];
    if (s.edit.pinned[g]) {
      edit.selection.fixed.insert(edit.selection.fixed.end(), group.begin(), group.end());
      continue;
    }
    edit.selection.handles.push_back(group);
    edit.transforms.push_back(Eigen::Affine3d::Identity());
    edit.pinned.push_back(false);
  }
  s.deformer.emplace(std::move(deformer));
  watch_detail();
  s.poses.push_back({posed.V, hex(mesh_hash(posed))});
  s.bases.push_back(std::move(basis));
  for (int p = 0; p + kPoseBases < static_cast<int>(s.bases.size()); ++p) {
    s.bases[p].harmonics.reset();
  }
  s.pose = static_cast<int>(s.poses.size()) - 1;
  save_in_background();
  s.has_handles = false;
  s.result = s.rest();
  s.result_stale = false;
  send_mesh();
  send_ready();
  set_edit(std::move(edit), true, true);
}

void EditorSession::open_scene(const NamedFile& file) {
  State& s = *state_;
  if (s.pose > 0) {
    throw InputError(file.name +
                     ": a scene moves the file's shape, and a pose was applied (undo "
                     "to before it, or open the mesh again)");
  }
  check_self_contained(file.data, file.name);
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("specdeform-scene-" + std::to_string(::getpid()) + ".json");
  std::ofstream(path, std::ios::binary) << file.data;
  Scene scene;
  try {
    scene = read_scene(path, s.loaded.info.file_vertices, s.options);
  } catch (...) {
    std::filesystem::remove(path);
    throw;
  }
  std::filesystem::remove(path);
  GroupSelection edit;
  edit.selection = scene_selection(scene, s.loaded);
  edit.transforms = match_transforms(edit.selection, scene.transforms);
  edit.pinned.assign(edit.selection.handles.size(), false);
  // The scene's settings, as a settings request would set them.
  DeformOptions o = scene.options;
  o.float32_basis = s.options.float32_basis;
  o.arap.warm_start = s.options.arap.warm_start;
  Json settings = {{"type", "settings"},
                   {"modes", scene.modes.value_or(s.modes)},
                   {"energy", name(o.energy)},
                   {"ks", o.ks},
                   {"kb", o.kb},
                   {"detail", name(o.detail)},
                   {"constraints", name(o.constraints)},
                   {"unconstrained", name(o.unconstrained)}};
  change_settings(dump(settings));
  set_edit(std::move(edit), true, true);
}

void EditorSession::open(LoadedMesh mesh, std::string name) {
  build(std::move(mesh), std::move(name), config_.modes, config_.options);
}

void EditorSession::progress(std::string_view stage, double fraction, bool cancellable) {
  send_(false, dump({{"type", "progress"},
                     {"stage", stage},
                     {"fraction", fraction},
                     {"cancellable", cancellable}}));
}

PreparedBasis EditorSession::compute_basis(const TriangleMesh& mesh, int modes) {
  struct Computing {
    std::atomic<bool>& flag;
    explicit Computing(std::atomic<bool>& f) : flag(f) { flag = true; }
    ~Computing() { flag = false; }
  } computing(computing_);
  cancelled_ = false;
  Clock::time_point last_report{};
  std::string last_stage;
  const auto report = [&](double fraction, std::string_view stage) {
    if (cancelled_) throw Cancelled();
    if (seconds_since(last_report) < 0.1 && fraction < 1.0 && stage == last_stage) return;
    last_report = Clock::now();
    last_stage = stage;
    const bool loading = stage == "loading the basis";
    progress(loading ? std::string(stage) : "computing the basis: " + std::string(stage), fraction,
             true);
  };
  const EigenSolver solver =
      config_.eigensolver.value_or(default_eigensolver(mesh.num_vertices(), {}));
  // On a thread of its own at a lower priority (with the threads it starts): the page, most
  // often on this machine, receives and draws the mesh meanwhile and is not kept waiting for
  // the cores (the 25 MB of a 692k mesh arrived in 3.2 s beside it at the same priority).
  return std::async(std::launch::async,
                    [&] {
                      lower_this_thread(kBasisNice);
                      return prepare_basis(mesh, modes, solver, config_.cache_dir, report);
                    })
      .get();
}

void EditorSession::build(LoadedMesh mesh, std::string name, int modes,
                          const DeformOptions& options) {
  const int n = mesh.mesh.num_vertices();
  if (n < 4) throw InputError(name + ": too few vertices to deform");
  auto next = std::make_unique<State>();
  State& s = *next;
  s.modes = std::min(modes, n - 1);  // every eigensolver takes m < n
  s.options = options;
  if (s.modes < modes) {
    send_(false, dump({{"type", "note"},
                       {"message", name + ": m = " + std::to_string(s.modes) +
                                       ": the mesh has only " + std::to_string(n) + " vertices"}}));
  }
  s.appearance = file_appearance(mesh);
  // Drawn at once: the page shows it, and handles are painted, while the basis computes.
  send_mesh(mesh.mesh, s.appearance, mesh);
  PreparedBasis basis;
  try {
    basis = compute_basis(mesh.mesh, s.modes);
    progress("setting up the solver", 1.0, false);
    s.deformer.emplace(mesh.mesh, basis.harmonics, s.options);
  } catch (const SolverError& e) {
    resend_edit();
    throw SolverError(name + ": " + e.what());
  } catch (...) {
    resend_edit();  // the page shows the mesh that stays open
    throw;
  }
  s.bases.push_back(std::move(basis));
  s.poses.push_back({mesh.mesh.V, hex(mesh_hash(mesh.mesh))});
  s.loaded = std::move(mesh);
  s.name = std::move(name);
  s.result = s.rest();
  s.diagonal = bounding_box_diagonal(s.rest());
  s.history.push_back({s.edit, 0});
  state_ = std::move(next);
  {
    std::lock_guard lock(saved_mutex_);
    ++opened_;
    saved_.clear();
  }
  watch_detail();
  send_ready();
  send_selection();
  send_state();
  save_in_background();
}

void EditorSession::resend_edit(bool mesh) {
  if (!state_) return;
  if (mesh) send_mesh();
  send_ready();
  if (std::lock_guard lock(saved_mutex_); !saved_.empty()) send_(false, saved_);
  send_selection();
  if (state_->has_handles) solve_and_send();
}

void EditorSession::save_in_background() {
  State& s = *state_;
  PreparedBasis& b = s.bases[s.pose];
  if (b.save_to.empty()) return;
  const std::filesystem::path file = std::exchange(b.save_to, {});
  send_(false, dump({{"type", "saving"}, {"file", file.filename().string()}, {"done", false}}));
  if (saving_.valid()) saving_.wait();  // one file at a time
  const int opened = opened_;           // written on this thread only
  saving_ = std::async(std::launch::async,
                       [this, file, opened, basis = b.harmonics, mesh = s.rest_mesh(s.pose)] {
                         // A low CPU priority (this thread's own on Linux): it takes a tenth of a
                         // core from a drag at most. At the lowest (19) a thread gets about 1.5% of
                         // one beside busy programs (the transfer's did:
                         // detail_reconstruction.cpp), and twice in 14 runs of the loading e2e test
                         // a 35 MB save had not reported after two minutes.
                         lower_this_thread(10);
                         std::string report = dump(save_and_report(file, *basis, mesh));
                         {
                           std::lock_guard lock(saved_mutex_);
                           if (opened == opened_) saved_ = report;
                         }
                         send_(false, std::move(report));
                       });
}

void EditorSession::send_mesh() {
  const State& s = *state_;
  send_mesh(s.rest_mesh(s.pose), s.appearance, s.loaded);
}

void EditorSession::send_mesh(const TriangleMesh& rest, const std::optional<Appearance>& look,
                              const LoadedMesh& loaded) {
  for (std::string& part : encode_mesh_parts(rest)) send_(true, std::move(part));
  if (!look) return;
  send_(true, encode_appearance(*look));
  for (size_t m = 0; m < look->textured.size(); ++m) {
    if (!look->textured[m]) continue;
    if (const auto image = loaded.file->texture(static_cast<int>(m))) {
      send_(true, encode_texture(static_cast<uint32_t>(m), image->second, image->first));
      continue;
    }
    const Material& material = loaded.file->attributes.materials[m];
    const std::string image = material.texture.starts_with("data:") ? "its embedded image"
                              : material.texture.empty()            ? "its image"
                                                                    : "'" + material.texture + "'";
    send_(false, dump({{"type", "note"},
                       {"message", "material '" + material.name + "': " + image +
                                       " could not be read; drawn in its colour"}}));
  }
}

void EditorSession::send_ready() {
  const State& s = *state_;
  const SetupTimings& t = s.deformer->setup_timings();
  const PreparedBasis& b = s.basis();
  FileSummary rig;
  if (s.loaded.file &&
      (s.loaded.file->format == MeshFormat::Gltf || s.loaded.file->format == MeshFormat::Glb)) {
    rig = s.loaded.file->summary();
  }
  send_(false, dump(Json{{"type", "ready"},
                         {"name", s.name},
                         {"vertices", s.loaded.mesh.num_vertices()},
                         {"faces", s.loaded.mesh.num_faces()},
                         {"diagonal", s.diagonal},
                         {"mesh_id", s.poses[s.pose].id},
                         {"modes", s.modes},
                         {"pose", s.pose},
                         {"settings",
                          {{"energy", name(s.options.energy)},
                           {"ks", s.options.ks},
                           {"kb", s.options.kb},
                           {"detail", name(s.options.detail)},
                           {"constraints", name(s.options.constraints)},
                           {"unconstrained", name(s.options.unconstrained)},
                           {"influence", s.influence},
                           {"view", s.base_view ? "base" : "detailed"}}},
                         {"basis",
                          {{"seconds", b.seconds},
                           {"source", b.source},
                           {"residual", b.harmonics->max_residual},
                           {"approximate", b.harmonics->approximate},
                           {"warning", b.warning}}},
                         {"setup",
                          {{"reduced_system", t.reduced_system},
                           {"detail_factorization", t.detail_factorization},
                           {"selection", t.selection}}},
                         {"arap_clusters", s.deformer->rotation_clusters()},
                         {"rig", {{"morph_targets", rig.morph_targets}, {"skins", rig.skins}}}}));
}

void EditorSession::send_selection() {
  send_(true, encode_selection(state_->edit));
}

void EditorSession::send_state() {
  const State& s = *state_;
  Json groups = Json::array();
  for (size_t g = 0; g < s.edit.selection.handles.size(); ++g) {
    groups.push_back({{"vertices", s.edit.selection.handles[g].size()},
                      {"pinned", static_cast<bool>(s.edit.pinned[g])},
                      {"transform", matrix(s.edit.transforms[g])}});
  }
  send_(false, dump({{"type", "state"},
                     {"request", request_},
                     {"groups", groups},
                     {"fixed", s.edit.selection.fixed.size()},
                     {"undo", s.at > 0},
                     {"redo", s.at + 1 < s.history.size()},
                     {"selection_seconds", s.selection_seconds},
                     {"pin_error", s.pin_error},
                     {"free_pieces", s.has_handles ? s.deformer->free_pieces() : 0},
                     {"constrained_piece_modes",
                      s.has_handles ? s.deformer->constrained_piece_modes() : std::vector<int>()},
                     {"detail_pending", s.has_handles && s.deformer->detail_pending()},
                     {"pose", s.pose}}));
}

void EditorSession::watch_detail() {
  if (!post_) return;
  state_->deformer->on_detail_ready([this] { post_([this] { detail_ready(); }); });
}

void EditorSession::detail_ready() {
  if (!state_) return;
  State& s = *state_;
  if (!s.has_handles || s.deformer->detail_pending()) return;  // a newer selection factors
  request_ = "detail";
  if (s.shown_displacements) solve_and_send();
  send_state();
}

const Vertices& EditorSession::result(bool final) {
  State& s = *state_;
  if (final && s.has_handles) {  // with the transfer's details, not the displacements meanwhile
    s.deformer->wait_for_detail();
    if (s.deformer->applied_detail() != s.options.detail) s.result_stale = true;
  }
  if (s.result_stale) s.result = s.deformer->solve(s.edit.transforms);
  s.result_stale = false;
  return s.result;
}

void EditorSession::solve_and_send(bool preview) {
  State& s = *state_;
  const FrameView view{s.base_view, preview && s.preview.has_value()};
  const PreviewMesh* coarse = s.preview ? &*s.preview : nullptr;
  if (!s.has_handles) {
    const Vertices& rest = s.rest();
    return send_(true, encode_frame_result(
                           s.seq, view, {},
                           view.preview ? Vertices(rest(s.preview->vertices, Eigen::all)) : rest,
                           rest, coarse));
  }
  SpectralDeformer& deformer = *s.deformer;
  Vertices shown;
  if (view.preview) {
    shown = deformer.preview(s.edit.transforms, s.preview->vertices);
    if (s.base_view) {  // the smooth base: the details taken off again
      const std::vector<int>& at = s.preview->vertices;
      shown -= s.rest()(at, Eigen::all) - deformer.base()(at, Eigen::all);
    }
    s.result_stale = true;
  } else {
    shown = deformer.solve(s.edit.transforms);
    s.result = std::move(shown);
    s.result_stale = false;
    s.shown_displacements = deformer.applied_detail() != s.options.detail;
  }
  const FrameTimings& t = deformer.frame_timings();
  const ConstraintError& e = deformer.base_miss();
  const ArapReport& arap = deformer.arap_report();
  const FrameStats stats{t.reduced_solve,
                         t.inverse_transform,
                         t.detail,
                         t.total,
                         e.max,
                         e.rms,
                         arap.iterations,
                         s.options.energy == DeformEnergy::Linear || arap.converged,
                         deformer.detail_fold_zone()};
  const Vertices& positions = view.preview  ? shown
                              : s.base_view ? s.deformer->deformed_base()
                                            : s.result;
  send_(true, encode_frame_result(s.seq, view, stats, positions, s.rest(), coarse));
}

}  // namespace specdeform::server
