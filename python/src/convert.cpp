#include "convert.h"

#include <cmath>
#include <cstdint>
#include <utility>

#include "specdeform/deform/scene.h"
#include "specdeform/exceptions.h"

namespace specdeform::python {

namespace {

std::string shape_of(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) {
    s += (d > 0 ? ", " : "") + std::to_string(a.shape(d));
  }
  return s + (a.ndim() == 1 ? ",)" : ")");
}

py::array as_array(py::handle obj, const std::string& name) {
  py::array a = py::array::ensure(obj);
  if (!a) throw InputError(name + ": not convertible to a numpy array");
  return a;
}

bool is_integer(const py::array& a) {
  return a.dtype().kind() == 'i' || a.dtype().kind() == 'u';
}
bool is_real(const py::array& a) {
  return a.dtype().kind() == 'f' || is_integer(a);
}

std::string dtype_of(const py::array& a) {
  return py::str(a.dtype()).cast<std::string>();
}

// A real 1-D or 2-D array (1-D: one column) as a finite float64 matrix, read in place when it is
// float64 already (any positive strides) and copied once into `Matrix`.
template <typename Matrix>
Matrix real_matrix(const py::array& a, const std::string& name) {
  if (!is_real(a)) throw InputError(name + ": expected real numbers, got dtype " + dtype_of(a));
  py::array_t<double> d = py::array_t<double, py::array::forcecast>::ensure(a);
  const auto stride = [&](int dim) {
    return dim < d.ndim() && d.shape(dim) > 1 ? d.strides(dim) : py::ssize_t{sizeof(double)};
  };
  if (stride(0) <= 0 || stride(1) <= 0 || stride(0) % sizeof(double) ||
      stride(1) % sizeof(double)) {
    d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(d);
  }
  using Strides = Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>;
  const Eigen::Map<const Eigen::MatrixXd, Eigen::Unaligned, Strides> map(
      d.data(), d.shape(0), d.ndim() == 2 ? d.shape(1) : 1,
      Strides(stride(1) / sizeof(double), stride(0) / sizeof(double)));
  Matrix m = map;
  if (!m.allFinite()) throw InputError(name + ": not finite (NaN or Inf)");
  return m;
}

template <typename T>
std::vector<int> indices_as(const py::array& a, Eigen::Index n, const std::string& name,
                            int row_size) {
  const auto d = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(a);
  std::vector<int> out(d.size());
  for (py::ssize_t i = 0; i < d.size(); ++i) {
    const T v = d.data()[i];
    if (std::cmp_less(v, 0) || std::cmp_greater_equal(v, n)) {
      throw InputError(name + (row_size > 0 ? " (face " + std::to_string(i / row_size) + ")" : "") +
                       ": index " + std::to_string(v) + " out of range for " + std::to_string(n) +
                       " vertices");
    }
    out[i] = static_cast<int>(v);
  }
  return out;
}

// The entries of an integer array in C order, each a vertex index in [0, n); messages name the
// face (row) of an entry when row_size > 0.
std::vector<int> vertex_indices(const py::array& a, Eigen::Index n, const std::string& name,
                                int row_size) {
  if (!is_integer(a)) {
    throw InputError(name + ": expected integer indices, got dtype " + dtype_of(a));
  }
  return a.dtype().kind() == 'u' ? indices_as<uint64_t>(a, n, name, row_size)
                                 : indices_as<int64_t>(a, n, name, row_size);
}

}  // namespace

Vertices to_vertices(py::handle V, const char* name) {
  const py::array a = as_array(V, name);
  if (a.ndim() != 2 || a.shape(1) != 3) {
    throw InputError(std::string(name) + ": expected an (n, 3) array, got shape " + shape_of(a));
  }
  return real_matrix<Vertices>(a, name);
}

Faces to_faces(py::handle F, Eigen::Index n, const char* name) {
  const py::array a = as_array(F, name);
  if (a.ndim() != 2 || a.shape(1) != 3) {
    throw InputError(std::string(name) + ": expected an (f, 3) array of triangles, got shape " +
                     shape_of(a));
  }
  const std::vector<int> v = vertex_indices(a, n, name, 3);
  return Eigen::Map<const Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>>(v.data(),
                                                                                  a.shape(0), 3);
}

TriangleMesh to_mesh(py::handle V, py::handle F) {
  TriangleMesh mesh;
  mesh.V = to_vertices(V);
  check_coordinate_range(mesh.V, "V");
  mesh.F = to_faces(F, mesh.V.rows());
  if (mesh.F.rows() == 0) throw InputError("F: the mesh has no faces");
  return mesh;
}

std::vector<int> to_indices(py::handle indices, Eigen::Index n, const std::string& name) {
  const py::array a = as_array(indices, name);
  if (a.size() == 0) return {};
  if (a.dtype().kind() == 'b') {
    if (a.ndim() != 1 || a.shape(0) != n) {
      throw InputError(name + ": a boolean mask needs one entry per vertex (" + std::to_string(n) +
                       "), got shape " + shape_of(a));
    }
    const auto mask = py::array_t<bool, py::array::c_style>::ensure(a);
    std::vector<int> out;
    for (Eigen::Index i = 0; i < n; ++i) {
      if (mask.data()[i]) out.push_back(static_cast<int>(i));
    }
    return out;
  }
  if (a.ndim() != 1) {
    throw InputError(name + ": expected a 1-D array of vertex indices, got shape " + shape_of(a));
  }
  return vertex_indices(a, n, name, 0);
}

Eigen::MatrixXd to_matrix(py::handle X, Eigen::Index rows, const std::string& name) {
  const py::array a = as_array(X, name);
  if (a.ndim() != 1 && a.ndim() != 2) {
    throw InputError(name + ": expected a 1-D or 2-D array, got shape " + shape_of(a));
  }
  if (rows >= 0 && a.shape(0) != rows) {
    throw InputError(name + ": expected " + std::to_string(rows) + " rows, got shape " +
                     shape_of(a));
  }
  return real_matrix<Eigen::MatrixXd>(a, name);
}

Eigen::VectorXd to_vector(py::handle x, Eigen::Index size, const std::string& name) {
  const py::array a = as_array(x, name);
  if (a.ndim() != 1 || (size >= 0 && a.shape(0) != size)) {
    throw InputError(name + ": expected shape (" + (size >= 0 ? std::to_string(size) : "k") +
                     ",), got " + shape_of(a));
  }
  return real_matrix<Eigen::VectorXd>(a, name);
}

bool is_vector(py::handle x) {
  const py::array a = py::array::ensure(x);
  return a && a.ndim() == 1;
}

std::vector<Eigen::Affine3d> to_transforms(py::handle transforms) {
  py::array a = as_array(transforms, "transforms");
  if (a.size() == 0) return {};
  if (!(a.ndim() == 2 || a.ndim() == 3) || a.shape(a.ndim() - 2) != 4 ||
      a.shape(a.ndim() - 1) != 4) {
    throw InputError("transforms: expected 4 x 4 matrices, got shape " + shape_of(a));
  }
  const auto rows =
      real_matrix<Eigen::MatrixXd>(a.reshape({py::ssize_t{-1}, py::ssize_t{4}}), "transforms");
  std::vector<Eigen::Affine3d> out;
  for (Eigen::Index k = 0; k < rows.rows() / 4; ++k) {
    out.push_back(checked_transform(rows.middleRows<4>(4 * k), "transform " + std::to_string(k)));
  }
  return out;
}

py::object to_scipy(Eigen::SparseMatrix<double>&& matrix) {
  matrix.makeCompressed();
  auto* owned = new Eigen::SparseMatrix<double>(std::move(matrix));
  const py::capsule owner(owned,
                          [](void* p) { delete static_cast<Eigen::SparseMatrix<double>*>(p); });
  const py::ssize_t nnz = owned->nonZeros(), cols = owned->cols();
  const py::array data(py::dtype::of<double>(), {nnz}, {sizeof(double)}, owned->valuePtr(), owner);
  const py::array indices(py::dtype::of<int>(), {nnz}, {sizeof(int)}, owned->innerIndexPtr(),
                          owner);
  const py::array indptr(py::dtype::of<int>(), {cols + 1}, {sizeof(int)}, owned->outerIndexPtr(),
                         owner);
  py::module_ sparse;
  try {
    sparse = py::module_::import("scipy.sparse");
  } catch (const py::error_already_set& e) {
    if (!e.matches(PyExc_ImportError)) throw;
    throw py::import_error(
        "this function returns a scipy.sparse matrix, and scipy is not installed (pip install "
        "'specdeform[scipy]', or Debian's python3-scipy); the rest of specdeform needs numpy "
        "only");
  }
  return sparse.attr("csc_matrix")(py::make_tuple(data, indices, indptr),
                                   py::arg("shape") = py::make_tuple(owned->rows(), cols));
}

}  // namespace specdeform::python
