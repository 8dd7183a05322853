// The JSON scene (scene.h, docs/scene.md): read with every field checked, and written.
#include <algorithm>
#include <climits>
#include <cmath>
#include <numbers>
#include <numeric>
#include <set>

#include <nlohmann/json.hpp>

#include "scene_internal.h"
#include "specdeform/deform/scene.h"
#include "specdeform/exceptions.h"

namespace specdeform {

namespace {

using Json = nlohmann::json;

// What a JSON value is, for messages: "a number", "an array", ...
std::string kind(const Json& j) {
  switch (j.type()) {
    case Json::value_t::null:
      return "null";
    case Json::value_t::boolean:
      return "a boolean";
    case Json::value_t::string:
      return "a string";
    case Json::value_t::array:
      return "an array";
    case Json::value_t::object:
      return "an object";
    default:
      return "a number";
  }
}

// Whether a key or string can go into a one-line message as it is.
bool printable(std::string_view s) {
  return std::none_of(s.begin(), s.end(), [](unsigned char c) { return c < 0x20 || c == 0x7f; });
}

// A value of the scene with its place in it ("s.json handle 0 transform"). Every field is read
// through one: a missing field, an unknown key, or a value of the wrong type names the field and
// what was expected.
class Field {
 public:
  Field(const Json& j, std::string where) : j_(j), where_(std::move(where)) {}

  [[noreturn]] void fail(const std::string& problem) const {
    throw InputError(where_ + ": " + problem);
  }
  [[noreturn]] void expected(const std::string& what) const {
    fail("expected " + what + ", got " + kind(j_));
  }
  const std::string& where() const { return where_; }
  bool is_array() const { return j_.is_array(); }
  bool is_object() const { return j_.is_object(); }
  bool is_string() const { return j_.is_string(); }

  // An object whose keys are all among `keys`.
  const Field& object(std::initializer_list<std::string_view> keys) const {
    if (!j_.is_object()) expected("an object");
    for (const auto& item : j_.items()) {
      if (std::find(keys.begin(), keys.end(), item.key()) != keys.end()) continue;
      if (!printable(item.key())) fail("a key with control characters");
      std::string known;
      for (const std::string_view k : keys) known += (known.empty() ? "" : ", ") + std::string(k);
      fail("unknown key '" + item.key() + "' (known: " + known + ")");
    }
    return *this;
  }
  bool has(const char* key) const { return j_.contains(key); }
  Field operator[](const char* key) const {
    if (!j_.contains(key)) fail(std::string("'") + key + "' is missing");
    return Field(j_[key], where_ + " " + key);
  }
  // An array's size, and its elements.
  size_t size() const {
    if (!j_.is_array()) expected("an array");
    return j_.size();
  }
  Field operator[](size_t i) const { return element(i, where_ + " " + std::to_string(i)); }
  Field element(size_t i, std::string where) const { return Field(j_[i], std::move(where)); }

  double number() const {
    if (!j_.is_number()) expected("a number");
    const double v = j_.get<double>();
    if (!std::isfinite(v)) fail("the number is not finite");
    return v;
  }
  long long integer() const {
    if (j_.is_number_unsigned() && j_.get<unsigned long long>() > LLONG_MAX) return LLONG_MAX;
    if (j_.is_number_integer()) return j_.get<long long>();
    if (j_.is_number_float()) {  // 3.0 is 3
      const double v = j_.get<double>();
      if (v == std::floor(v) && std::abs(v) < 9e18) return static_cast<long long>(v);
      fail("expected an integer, got " + j_.dump());
    }
    expected("an integer");
  }
  int integer(int lo, int hi) const {
    const long long v = integer();
    if (v < lo || v > hi) {
      fail(std::to_string(v) + " is out of range [" + std::to_string(lo) + ", " +
           std::to_string(hi) + "]");
    }
    return static_cast<int>(v);
  }
  std::string string() const {
    if (!j_.is_string()) expected("a string");
    const std::string s = j_.get<std::string>();
    if (!printable(s)) fail("the string has control characters");
    return s;
  }
  Eigen::Vector3d vec3() const {
    if (!j_.is_array() || j_.size() != 3 ||
        !std::all_of(j_.begin(), j_.end(), [](const Json& x) { return x.is_number(); })) {
      expected("an array of 3 numbers");
    }
    const Eigen::Vector3d v(j_[0].get<double>(), j_[1].get<double>(), j_[2].get<double>());
    if (!v.allFinite()) fail("the numbers are not finite");
    return v;
  }
  // A mode by its name (deform_options.h).
  template <typename Mode>
  Mode mode(Mode (*from_name)(std::string_view)) const {
    const std::string name = string();
    try {
      return from_name(name);
    } catch (const InputError& e) {
      fail(e.what());
    }
  }

 private:
  const Json& j_;
  std::string where_;
};

Json parse_json(std::string_view text, const std::string& where) {
  // A key given twice in one object would silently take the last value: refused.
  std::vector<std::set<std::string>> keys;
  const auto unique_keys = [&](int, Json::parse_event_t event, Json& parsed) {
    if (event == Json::parse_event_t::object_start) keys.emplace_back();
    if (event == Json::parse_event_t::object_end) keys.pop_back();
    if (event == Json::parse_event_t::key &&
        !keys.back().insert(parsed.get<std::string>()).second) {
      throw InputError(where + ": the key \"" + parsed.get<std::string>() +
                       "\" appears twice in one object");
    }
    return true;
  };
  try {
    return Json::parse(text, unique_keys);
  } catch (const Json::parse_error& e) {
    const std::string_view read = text.substr(0, std::min(text.size(), e.byte));
    const size_t line_start = read.rfind('\n') + 1;  // 0 on the first line
    throw InputError(where + ": not valid JSON (line " +
                     std::to_string(std::count(read.begin(), read.end(), '\n') + 1) + ", column " +
                     std::to_string(read.size() - line_start) + ")");
  } catch (const Json::exception&) {  // a number beyond the range of a double
    throw InputError(where + ": not valid JSON (a number out of range)");
  }
}

// Reads one scene: `mesh` tells which file vertices the loaded mesh kept.
class SceneReader {
 public:
  SceneReader(const std::filesystem::path& path, const MeshReadInfo& mesh,
              const SceneFileReader& read_file)
      : dir_(path.parent_path()),
        V_(mesh.file_vertices),
        kept_(mesh.vertex_to_file),
        to_vertex_(mesh.file_to_vertex),
        read_file_(read_file) {
    if (kept_.empty()) return;
    Eigen::Vector3d lo = V_.row(kept_[0]), hi = lo;
    for (const int v : kept_) {
      lo = lo.cwiseMin(V_.row(v).transpose());
      hi = hi.cwiseMax(V_.row(v).transpose());
    }
    diagonal_ = (hi - lo).norm();
  }

  Scene read(const Field& root, const DeformOptions& defaults) const {
    root.object({"mesh", "handles", "fixed", "influence", "settings"});
    Scene scene;
    scene.options = defaults;
    if (root.has("mesh")) scene.mesh = dir_ / root["mesh"].string();
    if (!root.has("handles")) root.fail("the scene has no handles");
    const Field handles = root["handles"];
    if (handles.size() == 0) handles.fail("the scene has no handles");
    for (size_t g = 0; g < handles.size(); ++g) {
      const Field h = handles.element(g, root.where() + " handle " + std::to_string(g));
      h.object({"vertices", "around", "selection", "group", "transform"});
      const int sources = h.has("vertices") + h.has("around") + h.has("selection");
      if (sources != 1) h.fail("give one of 'vertices', 'around' or 'selection'");
      if (h.has("group") && !h.has("selection")) h.fail("'group' goes with a 'selection' file");
      std::vector<int> vertices = h.has("vertices") ? vertex_list(h["vertices"])
                                  : h.has("around") ? around(h["around"])
                                                    : from_file(h, false);
      if (vertices.empty()) h.fail("no vertices");
      scene.transforms.push_back(h.has("transform") ? transform(h["transform"], vertices)
                                                    : Eigen::Affine3d::Identity());
      scene.selection.handles.push_back(std::move(vertices));
    }
    if (root.has("fixed")) scene.selection.fixed = fixed(root["fixed"], scene.selection);
    if (root.has("influence")) {
      scene.influence = root["influence"].number();
      if (!(*scene.influence > 0)) root["influence"].fail("the radius must be > 0");
    }
    if (root.has("settings")) read_settings(root["settings"], scene);
    return scene;
  }

 private:
  int file_vertices() const { return static_cast<int>(V_.rows()); }

  std::vector<int> vertex_list(const Field& list) const {
    std::vector<int> out;
    for (size_t k = 0; k < list.size(); ++k) {
      const long long v = list[k].integer();
      if (v < 0 || v >= file_vertices()) {
        list.fail("vertex " + std::to_string(v) + " is out of range (the mesh file has " +
                  std::to_string(file_vertices()) + " vertices)");
      }
      out.push_back(static_cast<int>(v));
    }
    return out;
  }

  // [v, ...] | {"lowest": f, "axis": a} | {"selection": "x.sel"}
  std::vector<int> fixed(const Field& f, const Selection& handles) const {
    if (f.is_array()) return vertex_list(f);
    if (!f.is_object()) f.expected("an array of vertices or an object");
    if (f.object({"lowest", "axis", "selection"}).has("selection")) {
      if (f.has("lowest") || f.has("axis")) f.fail("give 'lowest' (and 'axis') or 'selection'");
      return from_file(f, true);
    }
    return lowest(f, handles);
  }

  // {"selection": "x.sel" | "x.dmat", "group": k}: a .sel's handle (2) or fixed (0) vertices, a
  // .dmat's group k; a fixed set takes a .sel's fixed vertices.
  std::vector<int> from_file(const Field& spec, bool fixed) const {
    const std::filesystem::path file = dir_ / spec["selection"].string();
    const bool is_sel = file.extension() == ".sel";
    if (!is_sel && file.extension() != ".dmat") {
      spec["selection"].fail("a selection is a .sel or a .dmat file");
    }
    if (fixed && !is_sel) spec.fail("a fixed set comes from a .sel file");
    const std::string text = read_file_(file);
    const Selection s = is_sel ? parse_sel(text, file_vertices(), file.string())
                               : parse_dmat(text, file_vertices(), file.string());
    if (fixed) return s.fixed;
    const int group = spec.has("group") ? spec["group"].integer(0, 1000) : (is_sel ? 2 : 0);
    if (is_sel) {
      if (group != 2 && group != 0) spec["group"].fail("in a .sel, the group is 2 or 0");
      return group == 2 ? s.handles[0] : s.fixed;
    }
    if (group >= static_cast<int>(s.handles.size())) {
      spec["group"].fail(file.string() + " has no group " + std::to_string(group));
    }
    return s.handles[group];
  }

  // {"vertex": v, "radius": r}: the mesh's vertices within r bounding-box diagonals of vertex v.
  std::vector<int> around(const Field& spec) const {
    spec.object({"vertex", "radius"});
    const int center = spec["vertex"].integer(0, file_vertices() - 1);
    const double radius = spec["radius"].number();
    if (!(radius > 0)) spec["radius"].fail("the radius must be > 0");
    return detail::vertices_within(V_, kept_, V_.row(center).transpose(), radius * diagonal_);
  }

  // {"lowest": f, "axis": "y"}: the fraction f of the mesh's vertices lowest along the axis,
  // handles excepted.
  std::vector<int> lowest(const Field& spec, const Selection& handles) const {
    const double fraction = spec["lowest"].number();
    if (!(fraction > 0 && fraction < 1)) spec["lowest"].fail("a fraction in (0, 1) is expected");
    const std::string axis = spec.has("axis") ? spec["axis"].string() : "y";
    if (axis != "x" && axis != "y" && axis != "z") spec["axis"].fail("the axis is x, y or z");
    return detail::lowest_vertices(V_, kept_, fraction, axis[0] - 'x', handles.handles);
  }

  Eigen::Affine3d transform(const Field& t, const std::vector<int>& vertices) const {
    if (t.is_array()) {
      if (t.size() != 4) t.fail("a matrix has 4 rows of 4 numbers");
      Eigen::Matrix4d m;
      for (size_t r = 0; r < 4; ++r) {
        const Field row = t[r];
        if (row.size() != 4) row.fail("a matrix has 4 rows of 4 numbers");
        for (size_t c = 0; c < 4; ++c) m(r, c) = row[c].number();
      }
      return checked_transform(m, t.where());
    }
    t.object({"translate", "rotate", "scale", "center"});
    Eigen::Vector3d center = centroid(vertices);
    if (t.has("center")) {
      const Field c = t["center"];
      if (!c.is_string()) {
        if (!c.is_array()) c.expected("an array of 3 numbers or \"centroid\"");
        center = c.vec3();
      } else if (c.string() != "centroid") {
        c.fail("expected an array of 3 numbers or \"centroid\", got \"" + c.string() + "\"");
      }
    }
    Eigen::Matrix3d linear = Eigen::Matrix3d::Identity();
    if (t.has("scale")) linear *= t["scale"].number();
    if (t.has("rotate")) {
      const Field r = t["rotate"];
      r.object({"axis", "degrees"});
      const Eigen::Vector3d axis = r.has("axis") ? r["axis"].vec3() : Eigen::Vector3d::UnitZ();
      if (axis.norm() == 0) r["axis"].fail("the rotation axis is zero");
      const double radians = r["degrees"].number() * std::numbers::pi / 180.0;
      linear = Eigen::AngleAxisd(radians, axis.normalized()).toRotationMatrix() * linear;
    }
    const Eigen::Vector3d translate =
        t.has("translate") ? t["translate"].vec3() : Eigen::Vector3d::Zero();
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() = linear;
    m.topRightCorner<3, 1>() = center + translate - linear * center;
    return checked_transform(m, t.where());
  }

  // The centroid of the mesh vertices the group names, each once: the file's copies of a welded
  // vertex (glTF seams, PLY splits, STL corners) and a vertex listed twice count once, so that
  // every exporter's file of a scene turns about the same point. Of the file vertices named, each
  // once, where the mesh kept none of them.
  Eigen::Vector3d centroid(const std::vector<int>& vertices) const {
    std::vector<int> points;
    for (const int v : vertices)
      if (to_vertex_[v] >= 0) points.push_back(kept_[to_vertex_[v]]);
    if (points.empty()) points = vertices;
    std::sort(points.begin(), points.end());
    points.erase(std::unique(points.begin(), points.end()), points.end());
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const int v : points) sum += V_.row(v).transpose();
    return sum / std::max<double>(static_cast<double>(points.size()), 1.0);
  }

  void read_settings(const Field& s, Scene& scene) const {
    s.object({"modes", "energy", "ks", "kb", "constraint_weight", "constraints", "detail", "solver",
              "unconstrained", "iterations", "clusters", "arap_bending", "arap_tolerance",
              "history"});
    DeformOptions& o = scene.options;
    if (s.has("modes")) scene.modes = s["modes"].integer(1, INT_MAX);
    if (s.has("energy")) o.energy = s["energy"].mode(deform_energy_from_name);
    if (s.has("ks")) o.ks = s["ks"].number();
    if (s.has("kb")) o.kb = s["kb"].number();
    if (s.has("constraint_weight")) o.constraint_weight = s["constraint_weight"].number();
    if (s.has("constraints")) o.constraints = s["constraints"].mode(constraint_mode_from_name);
    if (s.has("detail")) o.detail = s["detail"].mode(detail_method_from_name);
    if (s.has("solver")) o.solver = s["solver"].mode(deform_solver_from_name);
    if (s.has("unconstrained")) {
      o.unconstrained = s["unconstrained"].mode(unconstrained_pieces_from_name);
    }
    if (s.has("iterations")) o.arap.max_iterations = s["iterations"].integer(1, 1000000);
    if (s.has("clusters")) o.arap.clusters = s["clusters"].integer(1, 100000000);
    if (s.has("arap_bending")) o.arap.bending = s["arap_bending"].number();
    if (s.has("arap_tolerance")) o.arap.tolerance = s["arap_tolerance"].number();
    if (s.has("history")) o.arap.history = s["history"].integer(0, 50);
    try {
      o.validate();
    } catch (const InputError& e) {
      s.fail(e.what());
    }
  }

  std::filesystem::path dir_;
  const Vertices& V_;
  const std::vector<int>& kept_;       // mesh vertex -> its first file vertex
  const std::vector<int>& to_vertex_;  // file vertex -> mesh vertex (-1: dropped)
  const SceneFileReader& read_file_;
  double diagonal_ = 0.0;
};

}  // namespace

Scene parse_scene(std::string_view text, const std::filesystem::path& path,
                  const MeshReadInfo& mesh, const DeformOptions& options,
                  const SceneFileReader& read_file) {
  const Json j = parse_json(text, path.string());
  return SceneReader(path, mesh, read_file).read(Field(j, path.string()), options);
}

Scene read_scene(const std::filesystem::path& path, const MeshReadInfo& mesh,
                 const DeformOptions& options) {
  return parse_scene(detail::read_scene_file(path), path, mesh, options, detail::read_scene_file);
}

Scene read_scene(const std::filesystem::path& path, const Vertices& file_vertices,
                 const DeformOptions& options) {
  MeshReadInfo all;
  all.file_vertices = file_vertices;
  all.vertex_to_file.resize(file_vertices.rows());
  std::iota(all.vertex_to_file.begin(), all.vertex_to_file.end(), 0);
  all.file_to_vertex = all.vertex_to_file;
  return read_scene(path, all, options);
}

std::filesystem::path scene_mesh(const std::filesystem::path& path) {
  const Json j = parse_json(detail::read_scene_file(path), path.string());
  const Field root(j, path.string());
  root.object({"mesh", "handles", "fixed", "influence", "settings"});
  return root.has("mesh") ? path.parent_path() / root["mesh"].string() : std::filesystem::path();
}

std::string encode_scene(const Scene& scene) {
  Json j = Json::object();
  if (!scene.mesh.empty()) j["mesh"] = scene.mesh.generic_string();
  const std::vector<Eigen::Affine3d> transforms =
      match_transforms(scene.selection, scene.transforms);
  j["handles"] = Json::array();
  for (size_t g = 0; g < scene.selection.handles.size(); ++g) {
    const Eigen::Matrix4d m = transforms[g].matrix();
    Json rows = Json::array();
    for (int r = 0; r < 4; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
    j["handles"].push_back({{"vertices", scene.selection.handles[g]}, {"transform", rows}});
  }
  j["fixed"] = scene.selection.fixed;
  if (scene.influence) j["influence"] = *scene.influence;
  const DeformOptions& o = scene.options;
  Json settings = {{"energy", name(o.energy)},
                   {"ks", o.ks},
                   {"kb", o.kb},
                   {"constraint_weight", o.constraint_weight},
                   {"constraints", name(o.constraints)},
                   {"solver", name(o.solver)},
                   {"detail", name(o.detail)},
                   {"unconstrained", name(o.unconstrained)},
                   {"iterations", o.arap.max_iterations},
                   {"clusters", o.arap.clusters},
                   {"arap_bending", o.arap.bending},
                   {"arap_tolerance", o.arap.tolerance},
                   {"history", o.arap.history}};
  if (scene.modes) settings["modes"] = *scene.modes;
  j["settings"] = settings;
  return j.dump(1, ' ', false, Json::error_handler_t::replace) + "\n";
}

}  // namespace specdeform
