#include <optional>
#include <string>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.h"
#include "convert.h"
#include "harmonics.h"
#include "specdeform/exceptions.h"
#include "specdeform/operators/laplacian.h"
#include "specdeform/operators/mass_matrix.h"
#include "specdeform/spectral/basis_cache.h"
#include "specdeform/spectral/basis_store.h"
#include "specdeform/spectral/spectral_transform.h"

namespace specdeform::python {

namespace {

// evecs as the library takes them, and the mass matrix they are orthonormal in: a Harmonics' own
// basis when evecs is its view (no copy), a copy otherwise.
struct TransformBasis {
  std::shared_ptr<const ManifoldHarmonics> shared;
  Eigen::MatrixXd copy;
  MassType mass = MassType::Lumped;

  TransformBasis(py::handle evecs, Eigen::Index rows, const std::optional<std::string>& mass_arg)
      : shared(shared_basis(evecs)) {
    if (!shared) copy = to_matrix(evecs, rows, "evecs");
    if (shared) mass = shared->mass;
    if (mass_arg) {
      const MassType asked = mass_from_name(*mass_arg);
      if (shared && asked != mass) {
        throw InputError("mass: the basis was computed with the " + mass_name(mass) + " mass");
      }
      mass = asked;
    }
  }
  const Eigen::MatrixXd& H() const { return shared ? shared->basis : copy; }
};

// A signal argument (X, default the vertex positions) and whether it was one vector.
struct Signal {
  Eigen::MatrixXd X;
  bool vector = false;
};
Signal to_signal(py::handle X, const TriangleMesh& mesh) {
  if (X.is_none()) return {mesh.V, false};
  return {to_matrix(X, mesh.num_vertices(), "X"), is_vector(X)};
}
py::array signal_array(Eigen::MatrixXd Y, bool vector) {
  if (vector) return to_array(Eigen::VectorXd(Y.col(0)));
  return to_array(std::move(Y));
}

// The options of manifold_harmonics and basis_cache_file: k pairs, the mass by name, and the
// eigensolver by name ("auto": the command line's choice for this mesh's size).
ManifoldHarmonicsOptions harmonics_options(const TriangleMesh& mesh, int k, const std::string& mass,
                                           const std::string& eigensolver) {
  ManifoldHarmonicsOptions o;
  o.num_modes = k;
  o.mass = mass_from_name(mass);
  o.solver = eigensolver == "auto" ? default_eigensolver(mesh.num_vertices(), o.policy)
                                   : eigen_solver_from_name(eigensolver);
  return o;
}

}  // namespace

void bind_spectral(py::module_& m) {
  m.def(
      "cotan_stiffness",
      [](py::handle V, py::handle F) {
        return to_scipy(stiffness_matrix(to_mesh(V, F), LaplacianType::Cotan));
      },
      py::arg("V"), py::arg("F"),
      R"(The cotangent stiffness matrix K (n x n scipy.sparse.csc_matrix).

Positive semi-definite, K 1 = 0, x^T K x the Dirichlet energy: K_ij = -(cot a + cot b) / 2 for
an edge ij. libigl's cotmatrix is -K. On a mesh with zero-area faces, zero-length edges or caps,
built on its mollified edge lengths, as every solver of the library builds it.)");
  m.def(
      "mass_matrix",
      [](py::handle V, py::handle F, const std::string& kind) {
        return to_scipy(mass_matrix(to_mesh(V, F), mass_from_name(kind), LaplacianType::Cotan));
      },
      py::arg("V"), py::arg("F"), py::arg("kind") = "lumped",
      R"(The mass matrix M (n x n scipy.sparse.csc_matrix): "lumped" (diagonal, a third of the
areas around each vertex) or "consistent" (linear finite elements); mollified as K is, so that
every vertex has an area.)");

  py::class_<Harmonics>(m, "Harmonics",
                        R"(A manifold-harmonics basis: the owner of the arrays manifold_harmonics
returns (evecs.base). SpectralDeformer shares it without a copy.)")
      .def_property_readonly(
          "eigenvalues",
          [](py::object self) {
            return view(self.cast<const Harmonics&>().value->eigenvalues, self);
          },
          "(k,) ascending, in 1/length^2 of the mesh (read-only).")
      .def_property_readonly(
          "vectors",
          [](py::object self) { return view(self.cast<const Harmonics&>().value->basis, self); },
          "(n, k), H^T M H = I (read-only).")
      .def_property_readonly("mass", [](const Harmonics& h) { return mass_name(h.value->mass); })
      .def_property_readonly(
          "converged", [](const Harmonics& h) { return h.value->status == SolveStatus::Converged; })
      .def_property_readonly("max_residual",
                             [](const Harmonics& h) { return h.value->max_residual; })
      .def_property_readonly(
          "residuals",
          [](py::object self) {
            return view(self.cast<const Harmonics&>().value->residuals, self);
          },
          "(k,) each pair's residual (read-only).")
      .def_property_readonly("approximate", [](const Harmonics& h) { return h.value->approximate; })
      .def_property_readonly("coarse_functions",
                             [](const Harmonics& h) { return h.value->coarse_functions; })
      .def_property_readonly("rounding_floor",
                             [](const Harmonics& h) { return h.value->rounding_floor; })
      .def_property_readonly("threshold", [](const Harmonics& h) { return h.value->threshold; })
      .def_property_readonly("max_orthogonality_error",
                             [](const Harmonics& h) { return h.value->max_orthogonality_error; })
      .def_property_readonly("cluster_truncated",
                             [](const Harmonics& h) { return h.value->cluster_truncated; })
      .def_property_readonly(
          "pieces", [](const Harmonics& h) { return h.value->pieces; },
          "Connected pieces, each given its own modes (0: not recorded).")
      .def_property_readonly(
          "requested_modes", [](const Harmonics& h) { return h.value->requested_modes; },
          "The modes asked for: fewer than the basis holds when several pieces each got their "
          "floor (spectral/piecewise.h).")
      .def_property_readonly(
          "stages",
          [](const Harmonics& h) {
            py::list out;
            for (const StageTime& t : h.value->stages)
              out.append(py::make_tuple(t.stage, t.seconds));
            return out;
          },
          "[(stage, seconds)]: where the computation's time went, in order (empty when read "
          "from a cache).")
      .def_property_readonly("bands", [](const Harmonics& h) { return h.value->bands; })
      .def_property_readonly("restarts", [](const Harmonics& h) { return h.value->restarts; })
      .def_property_readonly("solves", [](const Harmonics& h) { return h.value->solves; })
      .def("__repr__", [](const Harmonics& h) {
        const ManifoldHarmonics& b = *h.value;
        return py::str("Harmonics(n={}, k={}, mass='{}', max_residual={:.3g})")
            .format(b.basis.rows(), b.basis.cols(), mass_name(b.mass), b.max_residual);
      });

  const ManifoldHarmonicsOptions defaults;
  m.def(
      "manifold_harmonics",
      [](py::handle V, py::handle F, int k, const std::string& mass,
         std::optional<std::filesystem::path> cache, double tolerance,
         const std::string& eigensolver, py::object progress, uint64_t seed) {
        const TriangleMesh mesh = to_mesh(V, F);
        ManifoldHarmonicsOptions o = harmonics_options(mesh, k, mass, eigensolver);
        o.tolerance = tolerance;
        o.seed = seed;
        return eigenpairs(obtain_basis(mesh, o, cache, progress));
      },
      py::arg("V"), py::arg("F"), py::arg("k"), py::kw_only(), py::arg("mass") = "lumped",
      py::arg("cache") = py::none(), py::arg("tolerance") = defaults.tolerance,
      py::arg("eigensolver") = "krylov", py::arg("progress") = py::none(),
      py::arg("seed") = defaults.seed,
      R"(The first k manifold harmonics: (evals, evecs), as scipy's
eigsh(K, k, M, sigma=-0.01) gives them: K evecs = M evecs diag(evals), evals ascending,
evecs.T @ M @ evecs = I, each vector's largest-magnitude entry positive.

Both arrays are read-only views of one Harmonics (evecs.base: the solver's diagnostics), which
SpectralDeformer(basis=(evals, evecs)) shares instead of copying. mass: "lumped" or
"consistent". cache: a basis file, read when it exists and holds at least k pairs for this mesh,
written otherwise (the CLI's --basis), or an existing directory of bases named as the editor
names them (its cache is ~/.cache/specdeform). tolerance: the residual each pair must reach, on
the mesh scaled to unit area. progress: called as progress(fraction, stage); an exception it
raises, or Ctrl-C, aborts the computation. The GIL is released while it runs.
eigensolver: "krylov" (exact, the default), "lanczos" (Spectra, the baseline), "multilevel"
(an approximation for large meshes: M-orthonormal, not eigenvectors; Harmonics.approximate
and .residuals say so; its cache file is kept apart from the exact one's) or "auto" (the command
line's and the editor's choice: multilevel from 200,000 vertices, krylov below).
Raises SolverError if the eigensolver does not converge.)");

  m.def(
      "basis_cache_file",
      [](py::handle V, py::handle F, int k, const std::filesystem::path& cache,
         const std::string& mass, const std::string& eigensolver) {
        const TriangleMesh mesh = to_mesh(V, F);
        return cached_basis_file(mesh, harmonics_options(mesh, k, mass, eigensolver), cache);
      },
      py::arg("V"), py::arg("F"), py::arg("k"), py::kw_only(), py::arg("cache"),
      py::arg("mass") = "lumped", py::arg("eigensolver") = "krylov",
      R"(The file of the cache folder `cache` that manifold_harmonics(V, F, k, cache=cache, ...)
reads, or writes when it does not exist: to compute a basis without a cache and save it later
(save_basis), off the path of the work that waits for it.)");
  m.def(
      "load_basis",
      [](const std::filesystem::path& path, py::handle V, py::handle F) {
        check_readable(path);
        const TriangleMesh mesh = to_mesh(V, F);
        py::gil_scoped_release release;
        auto h = std::make_shared<const ManifoldHarmonics>(load_basis(path, mesh));
        py::gil_scoped_acquire gil;
        return eigenpairs(std::move(h));
      },
      py::arg("path"), py::arg("V"), py::arg("F"),
      "Reads a basis file (.sdbasis, as `specdeform basis -o` writes): (evals, evecs). Raises "
      "InputError if it was computed for another mesh.");
  m.def(
      "save_basis",
      [](const std::filesystem::path& path, py::handle basis, py::handle V, py::handle F,
         std::optional<bool> float32, std::optional<std::string> mass) {
        check_writable(path);
        const TriangleMesh mesh = to_mesh(V, F);
        const auto h =
            to_basis(basis, mesh, mass ? std::optional(mass_from_name(*mass)) : std::nullopt, {});
        py::gil_scoped_release release;
        save_basis(path, *h, mesh,
                   !float32   ? cache_precision(*h)
                   : *float32 ? BasisPrecision::Float32
                              : BasisPrecision::Float64);
      },
      py::arg("path"), py::arg("basis"), py::arg("V"), py::arg("F"), py::kw_only(),
      py::arg("float32") = py::none(), py::arg("mass") = py::none(),
      "Writes (evals, evecs) of the mesh (V, F) as a basis file the CLI and the editor read; "
      "float32 halves it (default: float32 for an approximate, multilevel basis, as the caches "
      "keep it; float64 for an exact one). Atomic.");

  m.def(
      "harmonics_forward",
      [](py::handle V, py::handle F, py::handle evecs, py::handle X,
         std::optional<std::string> mass) {
        const TriangleMesh mesh = to_mesh(V, F);
        const TransformBasis b(evecs, mesh.num_vertices(), mass);
        const Signal s = to_signal(X, mesh);
        Eigen::MatrixXd C;
        {
          py::gil_scoped_release release;
          C = harmonics_forward(b.H(), mass_matrix(mesh, b.mass, LaplacianType::Cotan), s.X);
        }
        return signal_array(std::move(C), s.vector);
      },
      py::arg("V"), py::arg("F"), py::arg("evecs"), py::arg("X") = py::none(), py::kw_only(),
      py::arg("mass") = py::none(),
      R"(Spectral coefficients C = evecs.T @ M @ X (k x d), M the mesh's mass matrix: the basis's
own for a view from manifold_harmonics, else `mass` (default "lumped"). X: (n, d) or (n,),
default V.)");
  m.def(
      "harmonics_inverse",
      [](py::handle evecs, py::handle C, std::optional<int> k) {
        const TransformBasis b(evecs, -1, std::nullopt);
        const bool vector = is_vector(C);
        const Eigen::MatrixXd coefficients = to_matrix(C, -1, "C");
        Eigen::MatrixXd X;
        {
          py::gil_scoped_release release;
          X = harmonics_inverse(b.H(), coefficients, k.value_or(-1));
        }
        return signal_array(std::move(X), vector);
      },
      py::arg("evecs"), py::arg("C"), py::arg("k") = py::none(),
      "The signal of the first k (default all) coefficients: evecs[:, :k] @ C[:k].");
  m.def(
      "low_pass",
      [](py::handle V, py::handle F, py::handle evecs, std::optional<int> k, py::handle X,
         std::optional<std::string> mass) {
        const TriangleMesh mesh = to_mesh(V, F);
        const TransformBasis b(evecs, mesh.num_vertices(), mass);
        const Signal s = to_signal(X, mesh);
        Eigen::MatrixXd Y;
        {
          py::gil_scoped_release release;
          Y = harmonics_inverse(
              b.H(), harmonics_forward(b.H(), mass_matrix(mesh, b.mass, LaplacianType::Cotan), s.X),
              k.value_or(-1));
        }
        return signal_array(std::move(Y), s.vector);
      },
      py::arg("V"), py::arg("F"), py::arg("evecs"), py::arg("k") = py::none(),
      py::arg("X") = py::none(), py::kw_only(), py::arg("mass") = py::none(),
      R"(X (default V) reconstructed from its first k (default all) frequencies: the smooth
shapes of the paper's Fig. 2 for X = V.)");
  m.def(
      "spectral_filter",
      [](py::handle V, py::handle F, py::handle evecs, py::handle gains, py::handle X,
         double residual_gain, std::optional<std::string> mass) {
        const TriangleMesh mesh = to_mesh(V, F);
        const TransformBasis b(evecs, mesh.num_vertices(), mass);
        const Signal s = to_signal(X, mesh);
        const Eigen::VectorXd g = to_vector(gains, b.H().cols(), "gains");
        Eigen::MatrixXd Y;
        {
          py::gil_scoped_release release;
          Y = spectral_filter(b.H(), mass_matrix(mesh, b.mass, LaplacianType::Cotan), s.X, g,
                              residual_gain);
        }
        return signal_array(std::move(Y), s.vector);
      },
      py::arg("V"), py::arg("F"), py::arg("evecs"), py::arg("gains"), py::arg("X") = py::none(),
      py::kw_only(), py::arg("residual_gain") = 0.0, py::arg("mass") = py::none(),
      R"(X' = evecs @ diag(gains) @ C + residual_gain * (X - evecs @ C), C = evecs.T @ M @ X:
one gain per frequency, residual_gain for the frequencies the basis does not hold.)");
}

}  // namespace specdeform::python
