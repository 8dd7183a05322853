// numpy and scipy.sparse to and from the library's types.
//
// In: anything numpy.asarray accepts, checked before it reaches the library (shape, dtype kind,
// finiteness, index range), each failure an InputError naming the argument. Face and index
// arrays must have an integer dtype: a float array is refused, never truncated.
// Out: results are moved into their array's owner (no copy); views of a longer-lived object are
// read-only and keep that object alive through the array's base.
#pragma once

#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/Sparse>

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform::python {

namespace py = pybind11;

// (n, 3) real, finite.
Vertices to_vertices(py::handle V, const char* name = "V");
// (f, 3) integer, each in [0, n).
Faces to_faces(py::handle F, Eigen::Index n, const char* name = "F");
// V and F as above, at least one face.
TriangleMesh to_mesh(py::handle V, py::handle F);
// A 1-D integer array of indices in [0, n), or a boolean mask of length n.
std::vector<int> to_indices(py::handle indices, Eigen::Index n, const std::string& name);
// (rows, cols) real, finite; a 1-D array is one column. rows < 0: any number of rows.
Eigen::MatrixXd to_matrix(py::handle X, Eigen::Index rows, const std::string& name);
// (size,) real, finite. size < 0: any size.
Eigen::VectorXd to_vector(py::handle x, Eigen::Index size, const std::string& name);
// Whether `x` converts to a 1-D array.
bool is_vector(py::handle x);
// One 4 x 4 affine matrix, a sequence of them, or a (k, 4, 4) array.
std::vector<Eigen::Affine3d> to_transforms(py::handle transforms);

// A matrix or vector moved into a new array that owns it.
template <typename Matrix>
py::array to_array(Matrix matrix);

// A read-only view of `matrix`, which `owner` keeps alive.
template <typename Matrix>
py::array view(const Matrix& matrix, py::handle owner);

// A scipy.sparse.csc_matrix holding `matrix`'s arrays.
py::object to_scipy(Eigen::SparseMatrix<double>&& matrix);

// ---- implementation of the templates ----

namespace detail {

template <typename Matrix>
py::array wrap(const Matrix& m, py::handle base) {
  using Scalar = typename Matrix::Scalar;
  constexpr auto size = static_cast<py::ssize_t>(sizeof(Scalar));
  if constexpr (Matrix::ColsAtCompileTime == 1) {
    return py::array(py::dtype::of<Scalar>(), {m.rows()}, {size}, m.data(), base);
  } else {
    const bool row_major = Matrix::IsRowMajor;
    const py::ssize_t rows = m.rows(), cols = m.cols();
    return py::array(py::dtype::of<Scalar>(), {rows, cols},
                     {row_major ? size * cols : size, row_major ? size : size * rows}, m.data(),
                     base);
  }
}

}  // namespace detail

template <typename Matrix>
py::array to_array(Matrix matrix) {
  auto* owned = new Matrix(std::move(matrix));
  const py::capsule owner(owned, [](void* p) { delete static_cast<Matrix*>(p); });
  return detail::wrap(*owned, owner);
}

template <typename Matrix>
py::array view(const Matrix& matrix, py::handle owner) {
  py::array a = detail::wrap(matrix, owner);
  a.attr("flags").attr("writeable") = false;
  return a;
}

}  // namespace specdeform::python
