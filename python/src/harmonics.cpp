#include "harmonics.h"

#include <chrono>
#include <cstdio>

#include "bindings.h"
#include "convert.h"
#include "specdeform/exceptions.h"
#include "specdeform/operators/laplacian.h"
#include "specdeform/spectral/basis_cache.h"
#include "specdeform/spectral/basis_store.h"

namespace specdeform::python {

namespace {

// The shortest time between two calls into Python from a computation's progress: taking the
// GIL can wait for a switch interval (5 ms) while other threads run Python.
constexpr std::chrono::milliseconds kProgressInterval(50);

// The largest |H^T M H - I| accepted in a basis given as arrays.
constexpr double kOrthonormalityTolerance = 1e-6;

bool is_view_of(py::handle array, const Eigen::VectorXd& values, py::handle owner) {
  if (!py::isinstance<py::array>(array)) return false;
  const auto a = py::reinterpret_borrow<py::array>(array);
  return a.base().is(owner) && a.data() == values.data() && a.ndim() == 1 &&
         a.shape(0) == values.size();
}

std::shared_ptr<const ManifoldHarmonics> copied_basis(py::handle evals, py::handle evecs,
                                                      const TriangleMesh& mesh, MassType mass) {
  auto h = std::make_shared<ManifoldHarmonics>();
  h->basis = to_matrix(evecs, mesh.num_vertices(), "evecs");
  h->eigenvalues = to_vector(evals, h->basis.cols(), "evals");
  h->mass = mass;
  py::gil_scoped_release release;
  const LaplacianOperators L = laplacian_operators(mesh, mass, LaplacianType::Cotan);
  const Eigen::SparseMatrix<double>& M = L.mass;
  h->max_orthogonality_error = orthonormality_error(M, h->basis);
  if (!(h->max_orthogonality_error <= kOrthonormalityTolerance)) {
    throw InputError(
        "basis: evecs are not orthonormal in the " + mass_name(mass) +
        " mass matrix (max |H^T M H - I| = " + std::to_string(h->max_orthogonality_error) +
        "); solve K h = lambda M h, e.g. scipy's eigsh(K, k, M, sigma=-0.01)");
  }
  h->max_residual = eigen_residual(L.stiffness, M, h->basis, h->eigenvalues);
  return h;
}

// The first `modes` pairs of `h` (h itself when that is all of them, or the m it was computed
// piece by piece for).
std::shared_ptr<const ManifoldHarmonics> first_modes(std::shared_ptr<const ManifoldHarmonics> h,
                                                     int modes, const std::string& name) {
  const Eigen::Index m = h->basis.cols();
  if (modes < 1) throw InputError(name + ": " + std::to_string(modes) + " modes asked for");
  if (h->pieces > 1 && modes == h->requested_modes) return h;
  if (modes > m) {
    throw InputError(name + ": holds " + std::to_string(m) + " frequencies, " +
                     std::to_string(modes) + " are asked for");
  }
  if (modes == m) return h;
  auto first = std::make_shared<ManifoldHarmonics>(*h);
  first->basis.conservativeResize(Eigen::NoChange, modes);
  first->eigenvalues.conservativeResize(modes);
  return first;
}

}  // namespace

py::tuple eigenpairs(std::shared_ptr<const ManifoldHarmonics> basis) {
  const ManifoldHarmonics& h = *basis;
  const py::object owner = py::cast(Harmonics{std::move(basis)});
  return py::make_tuple(view(h.eigenvalues, owner), view(h.basis, owner));
}

std::shared_ptr<const ManifoldHarmonics> shared_basis(py::handle evecs) {
  if (!py::isinstance<py::array>(evecs)) return nullptr;
  const auto a = py::reinterpret_borrow<py::array>(evecs);
  const py::object owner = a.base();
  if (!owner || !py::isinstance<Harmonics>(owner)) return nullptr;
  const std::shared_ptr<const ManifoldHarmonics>& h = owner.cast<const Harmonics&>().value;
  const Eigen::MatrixXd& H = h->basis;
  const py::ssize_t size = sizeof(double);
  const bool full = a.data() == H.data() && a.ndim() == 2 && a.shape(0) == H.rows() &&
                    a.shape(1) == H.cols() && a.strides(0) == size &&
                    a.strides(1) == size * H.rows();
  return full ? h : nullptr;
}

std::shared_ptr<const ManifoldHarmonics> to_basis(py::handle basis, const TriangleMesh& mesh,
                                                  std::optional<MassType> mass,
                                                  std::optional<int> modes) {
  std::shared_ptr<const ManifoldHarmonics> h;
  if (py::isinstance<Harmonics>(basis)) {
    h = basis.cast<const Harmonics&>().value;
  } else {
    if (!py::isinstance<py::sequence>(basis) || py::len(basis) != 2) {
      throw InputError("basis: expected (evals, evecs) or a Harmonics");
    }
    const auto pair = py::reinterpret_borrow<py::sequence>(basis);
    h = shared_basis(pair[1]);
    if (!h || !is_view_of(pair[0], h->eigenvalues, py::object(pair[1].attr("base")))) {
      h = copied_basis(pair[0], pair[1], mesh, mass.value_or(MassType::Lumped));
    }
  }
  if (h->basis.rows() != mesh.num_vertices()) {
    throw InputError("basis: " + std::to_string(h->basis.rows()) + " rows for a mesh of " +
                     std::to_string(mesh.num_vertices()) + " vertices");
  }
  if (mass && *mass != h->mass) {
    throw InputError("basis: computed with the other mass matrix than the one asked for");
  }
  return modes ? first_modes(std::move(h), *modes, "basis") : h;
}

ProgressCallback python_progress(py::handle user) {
  using Clock = std::chrono::steady_clock;
  return [user, last = Clock::time_point()](double fraction, std::string_view stage) mutable {
    if (fraction < 1.0 && Clock::now() - last < kProgressInterval) return;
    last = Clock::now();
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (!user.is_none()) user(fraction, py::str(stage.data(), stage.size()));
  };
}

std::shared_ptr<const ManifoldHarmonics> obtain_basis(
    const TriangleMesh& mesh, const ManifoldHarmonicsOptions& options,
    const std::optional<std::filesystem::path>& cache, py::handle progress) {
  std::filesystem::path path;
  if (cache) {
    path = std::filesystem::is_directory(*cache) ? *cache / basis_file_name(mesh, options) : *cache;
    if (std::filesystem::exists(path)) {
      check_readable(path);
    } else {
      check_writable(path);
    }
  }
  ManifoldHarmonicsOptions o = options;
  o.progress = python_progress(progress);
  ObtainedBasis basis;
  {
    py::gil_scoped_release release;
    basis = specdeform::obtain_basis(mesh, o, path);
  }
  std::string message = basis.warning;
  if (!basis.loaded && basis.harmonics->cluster_truncated) {
    message = "manifold harmonics: k = " + std::to_string(options.num_modes) +
              " ends inside a cluster of equal eigenvalues; the last vectors are one arbitrary "
              "choice within it";
  }
  if (!message.empty() && PyErr_WarnEx(PyExc_UserWarning, message.c_str(), 2) != 0) {
    throw py::error_already_set();
  }
  return std::move(basis.harmonics);
}

MassType mass_from_name(const std::string& name) {
  if (name == "lumped") return MassType::Lumped;
  if (name == "consistent") return MassType::Consistent;
  throw InputError("mass: '" + name + "' is not one of lumped, consistent");
}

std::string mass_name(MassType mass) {
  return mass == MassType::Lumped ? "lumped" : "consistent";
}

}  // namespace specdeform::python
