#include <chrono>
#include <mutex>
#include <optional>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.h"
#include "convert.h"
#include "harmonics.h"
#include "options.h"
#include "specdeform/deform/scene.h"
#include "specdeform/deform/spectral_deformer.h"
#include "specdeform/exceptions.h"

namespace specdeform::python {

namespace {

// SpectralDeformer for Python: its calls run without the GIL, one at a time.
struct Deformer {
  std::unique_ptr<SpectralDeformer> deformer;
  double basis_seconds = 0.0;
  std::mutex mutex;
};

Selection to_selection(py::handle handles, py::handle fixed, Eigen::Index n) {
  if (py::isinstance<py::str>(handles) || !py::isinstance<py::iterable>(handles)) {
    throw InputError("handles: expected a list of vertex index arrays, one per handle group");
  }
  Selection s;
  for (py::handle group : handles) {
    const std::string name = "handles[" + std::to_string(s.handles.size()) + "]";
    s.handles.push_back(to_indices(group, n, name));
    // An empty group would take a transform and move nothing: the solve would return the input.
    if (s.handles.back().empty()) throw InputError(name + ": an empty handle group (no vertex)");
  }
  if (s.handles.empty()) {
    throw InputError("handles: no handle group (give one vertex index array per group)");
  }
  s.fixed = to_indices(fixed, n, "fixed");
  return s;
}

// `out` of solve() and preview(): a writeable C-contiguous float32 (n, 3) array, in place.
Eigen::Map<FloatVertices> vertex_buffer(py::handle out, const Deformer& d,
                                        const std::string& call) {
  const Eigen::Index n = d.deformer->mesh().num_vertices();
  auto buffer = py::cast<py::array>(out);
  if (!py::isinstance<py::array_t<float>>(buffer) || buffer.ndim() != 2 || buffer.shape(0) != n ||
      buffer.shape(1) != 3 || !buffer.writeable() || !(buffer.flags() & py::array::c_style)) {
    throw InputError(call + ": out must be a writeable C-contiguous float32 (" + std::to_string(n) +
                     ", 3) array");
  }
  return Eigen::Map<FloatVertices>(static_cast<float*>(buffer.mutable_data()), n, 3);
}

py::array index_array(const std::vector<int>& v) {
  return to_array(Eigen::VectorXi(Eigen::Map<const Eigen::VectorXi>(v.data(), v.size())));
}

// The scene `path` (JSON, or a .sel or .dmat with the .def `transforms`) of the mesh file `mesh`:
// the mesh, the selection in its numbering, one transform per handle group, the settings, and
// notes on the vertices the selection lost to the mesh reader (to_mesh_numbering()).
py::dict read_scene_files(const std::filesystem::path& path, const std::filesystem::path& mesh,
                          const std::optional<std::filesystem::path>& transforms) {
  check_readable(mesh);
  check_readable(path);
  const std::string kind = path.extension().string();
  if (kind != ".json" && kind != ".sel" && kind != ".dmat") {
    throw InputError(path.string() + ": a scene is a .json, .sel or .dmat file");
  }
  if (kind != ".json" && !transforms) {
    throw InputError(path.string() + ": a " + kind + " selection needs its transforms (a .def)");
  }
  if (transforms) check_readable(*transforms);
  LoadedMesh loaded;
  Scene scene;
  {
    py::gil_scoped_release release;
    loaded = read_mesh(mesh);
    const int file_vertices = static_cast<int>(loaded.info.file_vertices.rows());
    if (kind == ".json") {
      scene = read_scene(path, loaded.info);
    } else {
      scene.selection =
          kind == ".sel" ? read_sel(path, file_vertices) : read_dmat(path, file_vertices);
      scene.transforms = read_def(*transforms);
    }
  }
  std::vector<std::string> notes;
  const Selection selection = scene_selection(scene, loaded, &notes, path.string());
  py::list handles, matrices;
  for (const std::vector<int>& group : selection.handles) handles.append(index_array(group));
  for (const Eigen::Affine3d& t : match_transforms(scene.selection, scene.transforms)) {
    matrices.append(to_array(Eigen::Matrix4d(t.matrix())));
  }
  py::dict d;
  d["V"] = to_array(std::move(loaded.mesh.V));
  d["F"] = to_array(std::move(loaded.mesh.F));
  d["info"] = std::move(loaded.info);
  d["handles"] = handles;
  d["fixed"] = index_array(selection.fixed);
  d["transforms"] = matrices;
  d["modes"] = scene.modes;
  d["options"] = to_dict(scene.options);
  d["notes"] = notes;
  return d;
}

}  // namespace

void bind_deform(py::module_& m) {
  py::class_<Deformer>(m, "SpectralDeformer", R"(Spectral mesh deformation (Rong, Cao & Guo 2008).

Built once per mesh: the basis of the first `modes` manifold harmonics (default 100), computed
unless `basis` gives it, the smooth base and the reduced system; then set_selection() once per
selection and solve() once per frame.)")
      .def(py::init([](py::handle V, py::handle F, std::optional<int> modes, py::handle basis,
                       std::optional<std::string> mass, std::optional<std::filesystem::path> cache,
                       py::handle progress, double tolerance, const py::kwargs& keywords) {
             TriangleMesh mesh = to_mesh(V, F);
             const DeformOptions options = to_options(keywords);
             const std::optional<MassType> mass_type =
                 mass ? std::optional(mass_from_name(*mass)) : std::nullopt;
             auto d = std::make_unique<Deformer>();
             std::shared_ptr<const ManifoldHarmonics> shared;
             if (!basis.is_none()) {
               shared = to_basis(basis, mesh, mass_type, modes);
             } else if (options.solver == DeformSolver::Spectral) {
               ManifoldHarmonicsOptions o;
               o.num_modes = modes.value_or(default_modes(mesh.num_vertices()));
               if (!modes && o.num_modes < ManifoldHarmonicsOptions{}.num_modes) {
                 const std::string note =
                     "SpectralDeformer: modes = " + std::to_string(o.num_modes) +
                     ": the mesh has only " + std::to_string(mesh.num_vertices()) + " vertices";
                 if (PyErr_WarnEx(PyExc_UserWarning, note.c_str(), 1) != 0) {
                   throw py::error_already_set();
                 }
               }
               o.mass = mass_type.value_or(MassType::Lumped);
               o.tolerance = tolerance;
               const auto start = std::chrono::steady_clock::now();
               shared = obtain_basis(mesh, o, cache, progress);
               d->basis_seconds =
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
             }
             py::gil_scoped_release release;
             d->deformer = std::make_unique<SpectralDeformer>(std::move(mesh), shared, options);
             return d;
           }),
           py::arg("V"), py::arg("F"), py::arg("modes") = py::none(), py::arg("basis") = py::none(),
           py::kw_only(), py::arg("mass") = py::none(), py::arg("cache") = py::none(),
           py::arg("progress") = py::none(),
           py::arg("tolerance") = ManifoldHarmonicsOptions{}.tolerance,
           R"(V (n, 3), F (f, 3); modes: the harmonics used (default 100, lowered with a warning to
n - 1 for a mesh of fewer vertices, or all of `basis`);
basis: (evals, evecs) from manifold_harmonics (shared, not copied) or any M-orthonormal
eigenpairs (copied); mass, cache, progress, tolerance: as manifold_harmonics takes them, when
the basis is computed here. With solver="spatial" and no basis, the base is the mesh itself.
Keywords: the deformation options (energy="linear"|"arap", ks, kb, constraint_weight,
detail="none"|"displacement"|"frames"|"transfer", solver="spectral"|"spatial",
constraints="soft"|"hard", unconstrained="follow"|"keep"|"error", float32_basis,
background_transfer (the transfer's Poisson system built and factored on a thread of its own:
set_selection returns at once and solve() adds the details as displacements until it is ready,
see detail_pending), and for ARAP iterations, clusters, arap_tolerance, arap_bending, history,
warm_start).)")
      .def(
          "set_selection",
          [](Deformer& d, py::handle handles, py::handle fixed) {
            const Selection s = to_selection(handles, fixed, d.deformer->mesh().num_vertices());
            py::gil_scoped_release release;
            const std::lock_guard lock(d.mutex);
            d.deformer->set_selection(s);
          },
          py::arg("handles"), py::arg("fixed") = py::tuple(),
          R"(handles: one vertex index array (or boolean mask) per handle group, at least one, none
empty (InputError otherwise); fixed: the vertices held in place. A vertex may belong to one group
only.)")
      .def(
          "solve",
          [](Deformer& d, py::handle transforms, py::handle out) -> py::object {
            const std::vector<Eigen::Affine3d> t = to_transforms(transforms);
            if (!out.is_none()) {
              Eigen::Map<FloatVertices> rows = vertex_buffer(out, d, "solve");
              py::gil_scoped_release release;
              const std::lock_guard lock(d.mutex);
              d.deformer->solve(t, rows);
              return py::reinterpret_borrow<py::object>(out);
            }
            Vertices result;
            {
              py::gil_scoped_release release;
              const std::lock_guard lock(d.mutex);
              result = d.deformer->solve(t);
            }
            return to_array(std::move(result));
          },
          py::arg("transforms"), py::arg("out") = py::none(),
          R"(The deformed mesh (n, 3) for one 4 x 4 affine transform per handle group (a list, a
(k, 4, 4) array, or one matrix for one group). out: as preview() takes it, a float32 (n, 3)
C-contiguous array written in place and returned.)")
      .def(
          "preview",
          [](Deformer& d, py::handle transforms, py::handle vertices,
             py::handle out) -> py::object {
            const std::vector<Eigen::Affine3d> t = to_transforms(transforms);
            const int n = d.deformer->mesh().num_vertices();
            if (!out.is_none()) {
              if (!vertices.is_none()) throw InputError("preview: out is for every vertex");
              Eigen::Map<FloatVertices> rows = vertex_buffer(out, d, "preview");
              py::gil_scoped_release release;
              const std::lock_guard lock(d.mutex);
              d.deformer->preview(t, rows);
              return py::reinterpret_borrow<py::object>(out);
            }
            std::vector<int> at;
            if (!vertices.is_none()) at = to_indices(vertices, n, "vertices");
            Vertices result;
            {
              py::gil_scoped_release release;
              const std::lock_guard lock(d.mutex);
              result = vertices.is_none() ? d.deformer->preview(t) : d.deformer->preview(t, at);
            }
            return to_array(std::move(result));
          },
          py::arg("transforms"), py::arg("vertices") = py::none(), py::arg("out") = py::none(),
          R"(solve()'s frame with the details added as displacements, at `vertices` (k,) in
their order, or at every vertex (n, 3): the cost of the reduced solve and the inverse transform
only, for drags (a Transfer's solve follows once the handles rest). out: a float32 (n, 3)
C-contiguous array written in place and returned (a vertex buffer: nothing the mesh's size is
allocated per frame). base_miss and deformed_base stay those of the last solve().)")
      .def(
          "base_miss",
          [](Deformer& d) {
            const std::lock_guard lock(d.mutex);
            const ConstraintError& e = d.deformer->base_miss();
            return py::dict(py::arg("max") = e.max, py::arg("rms") = e.rms);
          },
          R"(How far the last solve() itself was from the handles and fixed vertices: the
deformed smooth base's distances to its targets over the bounding-box diagonal, {"max", "rms"}.
Soft constraints miss by what their weight allows; the detailed result's constrained vertices are
put on their targets (constraint_error).)")
      .def(
          "constraint_error",
          [](Deformer& d, py::handle X) {
            const std::lock_guard lock(d.mutex);
            const ConstraintError e = d.deformer->constraint_error(to_vertices(X, "X"));
            return py::dict(py::arg("max") = e.max, py::arg("rms") = e.rms);
          },
          py::arg("X"),
          "Distances of a solve() result's constrained vertices to their targets, over the "
          "bounding-box diagonal: {'max', 'rms'}.")
      .def_property_readonly(
          "detail_pending",
          [](Deformer& d) {
            const std::lock_guard lock(d.mutex);
            return d.deformer->detail_pending();
          },
          "background_transfer: whether the transfer's factorisation for the last selection "
          "still runs (solve() adds the details as displacements meanwhile; False otherwise).")
      .def(
          "wait_for_detail",
          [](Deformer& d) {
            py::gil_scoped_release release;
            const std::lock_guard lock(d.mutex);
            d.deformer->wait_for_detail();
          },
          "background_transfer: waits until the transfer's factorisation for the last selection "
          "is ready (at once otherwise). Raises SolverError where it failed.")
      .def_property_readonly(
          "base",
          [](py::object self) { return view(self.cast<Deformer&>().deformer->base(), self); },
          "The smooth base s (n, 3): the mesh low-passed to the basis (read-only).")
      .def_property_readonly(
          "deformed_base",
          [](Deformer& d) {
            const std::lock_guard lock(d.mutex);
            return to_array(Vertices(d.deformer->deformed_base()));
          },
          "The deformed smooth base s' of the last solve (n, 3).")
      .def_property_readonly(
          "basis",
          [](Deformer& d) -> py::object {
            const std::shared_ptr<const ManifoldHarmonics>& b = d.deformer->basis();
            if (!b || b->basis.cols() == 0) return py::none();
            return eigenpairs(b);
          },
          "(evals, evecs), read-only views of the shared basis; None without one.")
      .def_property_readonly(
          "options", [](Deformer& d) { return to_dict(d.deformer->options()); },
          "The deformation options, as keywords.")
      .def_property_readonly(
          "timings",
          [](Deformer& d) {
            const std::lock_guard lock(d.mutex);
            const SetupTimings& s = d.deformer->setup_timings();
            const FrameTimings& f = d.deformer->frame_timings();
            py::dict t;
            t["basis"] = d.basis_seconds;
            t["reduced_system"] = s.reduced_system;
            t["detail_factorization"] = s.detail_factorization;
            t["selection"] = s.selection;
            t["frame"] = py::dict(py::arg("reduced_solve") = f.reduced_solve,
                                  py::arg("inverse_transform") = f.inverse_transform,
                                  py::arg("detail") = f.detail, py::arg("total") = f.total);
            return t;
          },
          "Seconds per stage, as `specdeform deform --json` reports them: basis, "
          "reduced_system, detail_factorization, selection, frame {reduced_solve, "
          "inverse_transform, detail, total} (the last solve).")
      .def("__repr__",
           [](Deformer& d) {
             const SpectralDeformer& s = *d.deformer;
             const auto& b = s.basis();
             return py::str("SpectralDeformer(n={}, modes={}, energy='{}', solver='{}')")
                 .format(s.mesh().num_vertices(), b ? b->basis.cols() : 0, name(s.options().energy),
                         name(s.options().solver));
           })
      .def_property_readonly(
          "report",
          [](Deformer& d) {
            const std::lock_guard lock(d.mutex);
            const ArapReport& a = d.deformer->arap_report();
            py::dict r;
            r["energy"] = std::string(name(d.deformer->options().energy));
            r["iterations"] = a.iterations;
            r["quasi_newton_steps"] = a.accelerated;
            r["arap_energy"] = a.energy;
            r["relative_change"] = a.relative_change;
            r["converged"] = a.converged;
            r["clusters"] = d.deformer->rotation_clusters();
            r["free_pieces"] = d.deformer->free_pieces();
            r["constrained_piece_modes"] = d.deformer->constrained_piece_modes();
            r["detail_fold_zone"] = d.deformer->detail_fold_zone();
            return r;
          },
          R"(The last solve: ARAP's iterations (of which L-BFGS steps: quasi_newton_steps), its energy
and last relative change, whether it converged (the linear energy: 0 iterations, converged),
the rotation clusters, and free_pieces (components without a handle or fixed vertex in the last
selection: they follow the surface around them, or are held in place, as `unconstrained` says)
and constrained_piece_modes (the basis's modes on each piece with a constrained vertex), and
detail_fold_zone (faces where the details were added as displacements because the smooth base
folded there).)");

  m.def("_read_scene", &read_scene_files, py::arg("path"), py::arg("mesh"),
        py::arg("transforms") = py::none());
}

}  // namespace specdeform::python
