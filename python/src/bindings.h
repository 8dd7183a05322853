// The parts of the extension module, and what they share.
#pragma once

#include <filesystem>

#include <pybind11/pybind11.h>

namespace specdeform::python {

namespace py = pybind11;

void bind_mesh(py::module_& m);      // mesh files, generated meshes
void bind_spectral(py::module_& m);  // operators, manifold harmonics, transforms, basis files
void bind_deform(py::module_& m);    // SpectralDeformer, scenes

// Raises the OSError of opening `path` for reading (FileNotFoundError, PermissionError, ...) as a
// Python exception, if there is one.
void check_readable(const std::filesystem::path& path);
// The same for creating `path`: its folder must exist and be writable.
void check_writable(const std::filesystem::path& path);

}  // namespace specdeform::python
