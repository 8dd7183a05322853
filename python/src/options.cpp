#include "options.h"

#include <functional>
#include <map>
#include <string>

#include "specdeform/exceptions.h"

namespace specdeform::python {

namespace {

template <typename T>
T value(py::handle v, const std::string& key, const char* expected) {
  try {
    return v.cast<T>();
  } catch (const py::cast_error&) {
    throw InputError(key + ": expected " + expected + ", got " +
                     py::str(py::type::handle_of(v).attr("__name__")).cast<std::string>());
  }
}
double number(py::handle v, const std::string& key) {
  return value<double>(v, key, "a number");
}
int integer(py::handle v, const std::string& key) {
  return value<int>(v, key, "an integer");
}
bool boolean(py::handle v, const std::string& key) {
  return value<bool>(v, key, "True or False");
}
std::string text(py::handle v, const std::string& key) {
  return value<std::string>(v, key, "a name");
}

using Setter = std::function<void(DeformOptions&, py::handle, const std::string&)>;

const std::map<std::string, Setter>& setters() {
  static const std::map<std::string, Setter> table = {
      {"energy", [](auto& o, auto v, auto& k) { o.energy = deform_energy_from_name(text(v, k)); }},
      {"ks", [](auto& o, auto v, auto& k) { o.ks = number(v, k); }},
      {"kb", [](auto& o, auto v, auto& k) { o.kb = number(v, k); }},
      {"constraint_weight", [](auto& o, auto v, auto& k) { o.constraint_weight = number(v, k); }},
      {"detail", [](auto& o, auto v, auto& k) { o.detail = detail_method_from_name(text(v, k)); }},
      {"solver", [](auto& o, auto v, auto& k) { o.solver = deform_solver_from_name(text(v, k)); }},
      {"constraints",
       [](auto& o, auto v, auto& k) { o.constraints = constraint_mode_from_name(text(v, k)); }},
      {"unconstrained",
       [](auto& o, auto v, auto& k) {
         o.unconstrained = unconstrained_pieces_from_name(text(v, k));
       }},
      {"float32_basis", [](auto& o, auto v, auto& k) { o.float32_basis = boolean(v, k); }},
      {"background_transfer",
       [](auto& o, auto v, auto& k) { o.background_transfer = boolean(v, k); }},
      {"iterations", [](auto& o, auto v, auto& k) { o.arap.max_iterations = integer(v, k); }},
      {"clusters", [](auto& o, auto v, auto& k) { o.arap.clusters = integer(v, k); }},
      {"arap_tolerance", [](auto& o, auto v, auto& k) { o.arap.tolerance = number(v, k); }},
      {"history", [](auto& o, auto v, auto& k) { o.arap.history = integer(v, k); }},
      {"arap_bending", [](auto& o, auto v, auto& k) { o.arap.bending = number(v, k); }},
      {"warm_start", [](auto& o, auto v, auto& k) { o.arap.warm_start = boolean(v, k); }},
  };
  return table;
}

}  // namespace

DeformOptions to_options(const py::dict& keywords, DeformOptions defaults) {
  for (const auto& [key, v] : keywords) {
    const std::string k = py::str(key);
    const auto setter = setters().find(k);
    if (setter == setters().end()) {
      std::string known;
      for (const auto& [name, unused] : setters()) known += (known.empty() ? "" : ", ") + name;
      throw InputError("unknown deformation option '" + k + "' (options: " + known + ")");
    }
    setter->second(defaults, v, k);
  }
  defaults.validate();
  return defaults;
}

py::dict to_dict(const DeformOptions& o) {
  py::dict d;
  d["energy"] = std::string(name(o.energy));
  d["ks"] = o.ks;
  d["kb"] = o.kb;
  d["constraint_weight"] = o.constraint_weight;
  d["detail"] = std::string(name(o.detail));
  d["solver"] = std::string(name(o.solver));
  d["constraints"] = std::string(name(o.constraints));
  d["unconstrained"] = std::string(name(o.unconstrained));
  d["float32_basis"] = o.float32_basis;
  d["background_transfer"] = o.background_transfer;
  d["iterations"] = o.arap.max_iterations;
  d["clusters"] = o.arap.clusters;
  d["arap_tolerance"] = o.arap.tolerance;
  d["history"] = o.arap.history;
  d["arap_bending"] = o.arap.bending;
  d["warm_start"] = o.arap.warm_start;
  return d;
}

}  // namespace specdeform::python
