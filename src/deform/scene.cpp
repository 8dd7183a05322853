#include "specdeform/deform/scene.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numeric>
#include <sstream>

#include <nlohmann/json.hpp>

#include "specdeform/exceptions.h"

namespace specdeform {

namespace {

std::string read_text(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path.string() + ": cannot open file");
  std::ostringstream s;
  s << file.rdbuf();
  return s.str();
}

// Whitespace-separated values of a text, '#' lines skipped.
std::vector<std::string> tokens(std::string_view text, bool skip_comments) {
  std::istringstream in{std::string(text)};
  std::vector<std::string> out;
  std::string line;
  while (std::getline(in, line)) {
    const size_t first = line.find_first_not_of(" \t\r");
    if (skip_comments && first != std::string::npos && line[first] == '#') continue;
    std::istringstream words(line);
    for (std::string w; words >> w;) out.push_back(w);
  }
  return out;
}

long long to_integer(const std::string& t, std::string_view name) {
  size_t used = 0;
  long long v = 0;
  try {
    v = std::stoll(t, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != t.size()) throw InputError(std::string(name) + ": '" + t + "' is not an integer");
  return v;
}

double to_number(const std::string& t, std::string_view name) {
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(t, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != t.size() || !std::isfinite(v)) {
    throw InputError(std::string(name) + ": '" + t + "' is not a finite number");
  }
  return v;
}

void check_count(size_t got, int expected, std::string_view name) {
  if (static_cast<long long>(got) != expected) {
    throw InputError(std::string(name) + ": " + std::to_string(got) +
                     " vertex entries, the mesh has " + std::to_string(expected) + " vertices");
  }
}

// The vertices within `radius` (absolute) of vertex `center`, ascending.
std::vector<int> vertices_within(const Vertices& V, int center, double radius) {
  std::vector<int> out;
  for (int i = 0; i < V.rows(); ++i) {
    if ((V.row(i) - V.row(center)).norm() <= radius) out.push_back(i);
  }
  return out;
}

// The `fraction` of the vertices lowest along `axis`, minus those in `excluded`, ascending.
std::vector<int> lowest_vertices(const Vertices& V, double fraction, int axis,
                                 const std::vector<std::vector<int>>& excluded) {
  const int n = static_cast<int>(V.rows());
  std::vector<char> skip(n, 0);
  for (const auto& group : excluded) {
    for (int v : group) skip[v] = 1;
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  const int count = static_cast<int>(fraction * n);
  std::nth_element(order.begin(), order.begin() + count, order.end(),
                   [&](int a, int b) { return V(a, axis) < V(b, axis); });
  std::vector<int> out;
  for (int k = 0; k < count; ++k) {
    if (!skip[order[k]]) out.push_back(order[k]);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

Eigen::Affine3d checked_transform(const Eigen::Matrix4d& m, const std::string& where) {
  if (!m.allFinite()) throw InputError(where + ": the transform is not finite");
  if (m.row(3) != Eigen::RowVector4d(0, 0, 0, 1)) {
    throw InputError(where + ": the transform's last row must be 0 0 0 1");
  }
  const Eigen::Matrix3d linear = m.topLeftCorner<3, 3>();
  if (!(std::abs(linear.determinant()) > 1e-12 * std::pow(linear.norm(), 3))) {
    throw InputError(where + ": the transform is not invertible");
  }
  return Eigen::Affine3d(m);
}

Selection parse_sel(std::string_view text, int file_vertices, std::string_view name) {
  const std::vector<std::string> t = tokens(text, true);
  check_count(t.size(), file_vertices, name);
  Selection s;
  s.handles.resize(1);
  for (size_t i = 0; i < t.size(); ++i) {
    const long long status = to_integer(t[i], name);
    if (status == 0) {
      s.fixed.push_back(static_cast<int>(i));
    } else if (status == 2) {
      s.handles[0].push_back(static_cast<int>(i));
    } else if (status != 1) {
      throw InputError(std::string(name) + ": status " + std::to_string(status) + " of vertex " +
                       std::to_string(i) + " is not 0 (fixed), 1 (free) or 2 (handle)");
    }
  }
  return s;
}

Selection parse_dmat(std::string_view text, int file_vertices, std::string_view name) {
  const std::vector<std::string> t = tokens(text, false);
  if (t.size() < 2) {
    throw InputError(std::string(name) + ": not a .dmat file (no 'cols rows' header)");
  }
  const long long cols = to_integer(t[0], name), rows = to_integer(t[1], name);
  if (cols != 1 || rows < 0) {
    throw InputError(std::string(name) + ": expected one column of per-vertex values, got " +
                     std::to_string(cols) + " x " + std::to_string(rows));
  }
  check_count(t.size() - 2, file_vertices, name);
  if (rows != file_vertices) check_count(static_cast<size_t>(rows), file_vertices, name);
  Selection s;
  for (size_t i = 2; i < t.size(); ++i) {
    const long long g = to_integer(t[i], name);
    if (g < -1 || g > 1000) {
      throw InputError(std::string(name) + ": group " + std::to_string(g) + " of vertex " +
                       std::to_string(i - 2) + " is not -1 (free) or a group number");
    }
    if (g < 0) continue;
    if (static_cast<size_t>(g) >= s.handles.size()) s.handles.resize(g + 1);
    s.handles[g].push_back(static_cast<int>(i - 2));
  }
  return s;
}

Selection read_sel(const std::filesystem::path& path, int file_vertices) {
  return parse_sel(read_text(path), file_vertices, path.string());
}

Selection read_dmat(const std::filesystem::path& path, int file_vertices) {
  return parse_dmat(read_text(path), file_vertices, path.string());
}

std::vector<Eigen::Affine3d> read_def(const std::filesystem::path& path) {
  std::istringstream in(read_text(path));
  std::string line;
  std::vector<std::string> t;
  bool first = true;
  while (std::getline(in, line)) {
    const size_t c = line.find_first_not_of(" \t\r");
    if (first || (c != std::string::npos && line[c] == '#')) {  // the first line is a comment
      first = false;
      continue;
    }
    std::istringstream words(line);
    for (std::string w; words >> w;) t.push_back(w);
  }
  if (t.empty() || t.size() % 16 != 0) {
    throw InputError(path.string() + ": expected 4 x 4 matrices (16 numbers each), got " +
                     std::to_string(t.size()) + " numbers");
  }
  std::vector<Eigen::Affine3d> out;
  for (size_t k = 0; k < t.size(); k += 16) {
    Eigen::Matrix4d m;
    for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = to_number(t[k + i], path.string());
    out.push_back(checked_transform(m, path.string() + " (matrix " + std::to_string(k / 16) + ")"));
  }
  return out;
}

std::vector<Eigen::Affine3d> match_transforms(const Selection& selection,
                                              std::vector<Eigen::Affine3d> transforms) {
  size_t handle_vertices = 0;
  for (const auto& g : selection.handles) handle_vertices += g.size();
  if (handle_vertices == 0) throw InputError("scene: no handle vertex");
  if (transforms.size() > selection.handles.size()) {
    throw InputError("scene: " + std::to_string(transforms.size()) + " transforms for " +
                     std::to_string(selection.handles.size()) + " handle groups");
  }
  transforms.resize(selection.handles.size(), Eigen::Affine3d::Identity());
  return transforms;
}

Selection radius_selection(const TriangleMesh& mesh, int center, double radius,
                           double fixed_fraction, int up) {
  const int n = mesh.num_vertices();
  if (center < 0 || center >= n || up < 0 || up > 2 ||
      !(fixed_fraction >= 0 && fixed_fraction < 1)) {
    throw InputError("radius selection: bad centre vertex, axis or fraction");
  }
  Selection s;
  s.handles = {vertices_within(mesh.V, center, radius * bounding_box_diagonal(mesh.V))};
  s.fixed = lowest_vertices(mesh.V, fixed_fraction, up, s.handles);
  return s;
}

Scene benchmark_scene(const TriangleMesh& mesh) {
  const Eigen::Vector3d extent = mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff();
  int axes[3] = {0, 1, 2};
  std::sort(axes, axes + 3, [&](int a, int b) { return extent[a] > extent[b]; });
  Eigen::Index top;
  mesh.V.col(axes[0]).maxCoeff(&top);
  Scene s;
  s.selection = radius_selection(mesh, static_cast<int>(top), 0.05, 0.10, axes[0]);
  Eigen::Vector3d move = Eigen::Vector3d::Zero();
  move[axes[1]] = 0.1 * extent.norm();
  s.transforms = {Eigen::Affine3d(Eigen::Translation3d(move))};
  return s;
}

Selection to_mesh_numbering(const Selection& selection, const MeshReadInfo& info) {
  std::vector<int> index(info.file_vertices.rows(), -1);
  for (size_t i = 0; i < info.vertex_to_file.size(); ++i) index[info.vertex_to_file[i]] = int(i);
  const auto map = [&](const std::vector<int>& in) {
    std::vector<int> out;
    for (const int v : in) {
      if (v < 0 || v >= static_cast<int>(index.size())) {
        throw InputError("selection: vertex " + std::to_string(v) +
                         " is out of range (the file has " + std::to_string(index.size()) +
                         " vertices)");
      }
      if (index[v] >= 0) out.push_back(index[v]);
    }
    return out;
  };
  Selection out;
  for (const auto& g : selection.handles) out.handles.push_back(map(g));
  out.fixed = map(selection.fixed);
  return out;
}

namespace {

using Json = nlohmann::json;

template <typename T>
T get(const Json& j, const char* key, const std::string& where) {
  try {
    return j.at(key).get<T>();
  } catch (const Json::exception&) {
    throw InputError(where + ": '" + key + "' is missing or has the wrong type");
  }
}

Eigen::Vector3d vec3(const Json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 3) throw InputError(where + ": expected [x, y, z]");
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k) {
    if (!j[k].is_number()) throw InputError(where + ": expected [x, y, z]");
    v[k] = j[k].get<double>();
  }
  if (!v.allFinite()) throw InputError(where + ": not finite");
  return v;
}

Eigen::Affine3d parse_transform(const Json& j, const std::vector<int>& vertices,
                                const Vertices& positions, const std::string& where) {
  if (j.is_array()) {
    Eigen::Matrix4d m;
    if (j.size() != 4) throw InputError(where + ": a matrix needs 4 rows of 4 numbers");
    for (int r = 0; r < 4; ++r) {
      if (!j[r].is_array() || j[r].size() != 4) {
        throw InputError(where + ": a matrix needs 4 rows of 4 numbers");
      }
      for (int c = 0; c < 4; ++c) {
        if (!j[r][c].is_number()) throw InputError(where + ": matrix entries must be numbers");
        m(r, c) = j[r][c].get<double>();
      }
    }
    return checked_transform(m, where);
  }
  if (!j.is_object()) throw InputError(where + ": a transform is a 4 x 4 matrix or an object");
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  if (j.contains("center") && j["center"].is_array()) {
    center = vec3(j["center"], where + " center");
  } else {
    for (const int v : vertices) center += positions.row(v).transpose();
    if (!vertices.empty()) center /= static_cast<double>(vertices.size());
  }
  Eigen::Matrix3d linear = Eigen::Matrix3d::Identity();
  if (j.contains("scale")) {
    if (!j["scale"].is_number()) throw InputError(where + ": scale must be a number");
    linear *= j["scale"].get<double>();
  }
  if (j.contains("rotate")) {
    const Json& r = j["rotate"];
    const Eigen::Vector3d axis = vec3(r.value("axis", Json::array({0, 0, 1})), where + " axis");
    if (axis.norm() == 0) throw InputError(where + ": the rotation axis is zero");
    const double degrees = get<double>(r, "degrees", where + " rotate");
    linear =
        Eigen::AngleAxisd(degrees * M_PI / 180.0, axis.normalized()).toRotationMatrix() * linear;
  }
  Eigen::Vector3d translate = Eigen::Vector3d::Zero();
  if (j.contains("translate")) translate = vec3(j["translate"], where + " translate");
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = linear;
  m.topRightCorner<3, 1>() = center + translate - linear * center;
  return checked_transform(m, where);
}

}  // namespace

Scene read_scene(const std::filesystem::path& path, const Vertices& file_vertices,
                 const DeformOptions& defaults) {
  const std::string where = path.string();
  Json j;
  try {
    j = Json::parse(read_text(path));
  } catch (const Json::parse_error& e) {
    throw InputError(where + ": not valid JSON (byte " + std::to_string(e.byte) + ")");
  }
  if (!j.is_object()) throw InputError(where + ": a scene is a JSON object");
  const std::filesystem::path dir = path.parent_path();
  const int n = static_cast<int>(file_vertices.rows());
  Scene scene;
  scene.options = defaults;
  if (j.contains("mesh")) scene.mesh = dir / get<std::string>(j, "mesh", where);
  const auto vertex_list = [&](const Json& list, const std::string& w) {
    std::vector<int> out;
    if (!list.is_array()) throw InputError(w + ": expected a list of vertex indices");
    for (const Json& v : list) {
      if (!v.is_number_integer()) throw InputError(w + ": vertex indices must be integers");
      const long long i = v.get<long long>();
      if (i < 0 || i >= n) {
        throw InputError(w + ": vertex " + std::to_string(i) + " is out of range (the mesh has " +
                         std::to_string(n) + " vertices)");
      }
      out.push_back(static_cast<int>(i));
    }
    return out;
  };
  const auto from_file = [&](const Json& spec, const std::string& w, bool fixed) {
    const std::filesystem::path file = dir / get<std::string>(spec, "selection", w);
    const bool is_sel = file.extension() == ".sel";
    const Selection s = is_sel ? read_sel(file, n) : read_dmat(file, n);
    if (fixed) {
      if (!is_sel) throw InputError(w + ": a fixed set comes from a .sel file");
      return s.fixed;
    }
    const int group = spec.value("group", is_sel ? 2 : 0);
    if (is_sel) {
      if (group != 2 && group != 0) throw InputError(w + ": in a .sel, group is 2 or 0");
      return group == 2 ? s.handles[0] : s.fixed;
    }
    if (group < 0 || group >= static_cast<int>(s.handles.size())) {
      throw InputError(w + ": " + file.string() + " has no group " + std::to_string(group));
    }
    return s.handles[group];
  };
  // {"vertex": v, "radius": r}: the vertices within r bounding-box diagonals of vertex v.
  const auto around = [&](const Json& spec, const std::string& w) {
    const int center = get<int>(spec, "vertex", w);
    const double radius = get<double>(spec, "radius", w);
    if (center < 0 || center >= n) throw InputError(w + ": vertex out of range");
    if (!(radius > 0)) throw InputError(w + ": radius must be > 0");
    return vertices_within(file_vertices, center, radius * bounding_box_diagonal(file_vertices));
  };
  // {"lowest": f, "axis": "y"}: the fraction f of the vertices lowest along the axis, handles
  // excepted.
  const auto lowest = [&](const Json& spec, const std::string& w, const Selection& handles) {
    const double fraction = get<double>(spec, "lowest", w);
    const std::string axis = spec.value("axis", "y");
    if (!(fraction > 0 && fraction < 1)) throw InputError(w + ": lowest is a fraction in (0, 1)");
    if (axis != "x" && axis != "y" && axis != "z") throw InputError(w + ": axis is x, y or z");
    return lowest_vertices(file_vertices, fraction, axis[0] - 'x', handles.handles);
  };
  if (!j.contains("handles") || !j["handles"].is_array() || j["handles"].empty()) {
    throw InputError(where + ": the scene has no handles");
  }
  for (size_t g = 0; g < j["handles"].size(); ++g) {
    const Json& h = j["handles"][g];
    const std::string w = where + " handle " + std::to_string(g);
    if (!h.is_object()) throw InputError(w + ": a handle is an object");
    std::vector<int> vertices = h.contains("vertices") ? vertex_list(h["vertices"], w)
                                : h.contains("around") ? around(h["around"], w)
                                                       : from_file(h, w, false);
    if (vertices.empty()) throw InputError(w + ": no vertices");
    scene.transforms.push_back(h.contains("transform")
                                   ? parse_transform(h["transform"], vertices, file_vertices, w)
                                   : Eigen::Affine3d::Identity());
    scene.selection.handles.push_back(std::move(vertices));
  }
  if (j.contains("fixed")) {
    const Json& f = j["fixed"];
    scene.selection.fixed = f.is_array()           ? vertex_list(f, where + " fixed")
                            : f.contains("lowest") ? lowest(f, where + " fixed", scene.selection)
                                                   : from_file(f, where + " fixed", true);
  }
  if (j.contains("settings")) {
    const Json& s = j["settings"];
    const std::string w = where + " settings";
    DeformOptions& o = scene.options;
    if (s.contains("modes")) scene.modes = get<int>(s, "modes", w);
    if (s.contains("ks")) o.ks = get<double>(s, "ks", w);
    if (s.contains("kb")) o.kb = get<double>(s, "kb", w);
    if (s.contains("constraint_weight"))
      o.constraint_weight = get<double>(s, "constraint_weight", w);
    const auto choose = [&](const char* key, auto& out, auto from_name) {
      if (!s.contains(key)) return;
      try {
        out = from_name(get<std::string>(s, key, w));
      } catch (const InputError& e) {
        throw InputError(w + ": " + e.what());
      }
    };
    choose("constraints", o.constraints, constraint_mode_from_name);
    choose("detail", o.detail, detail_method_from_name);
    choose("solver", o.solver, deform_solver_from_name);
  }
  return scene;
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
  const DeformOptions& o = scene.options;
  Json settings = {{"ks", o.ks}, {"kb", o.kb}, {"constraint_weight", o.constraint_weight}};
  if (scene.modes) settings["modes"] = *scene.modes;
  settings["constraints"] = name(o.constraints);
  settings["solver"] = name(o.solver);
  settings["detail"] = name(o.detail);
  j["settings"] = settings;
  return j.dump(1) + "\n";
}

}  // namespace specdeform
