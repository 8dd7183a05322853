// DeformOptions as Python keyword arguments, one per field, named as on the command line and in
// scene files: energy, ks, kb, constraint_weight, detail, solver, constraints, unconstrained,
// float32_basis, and ARAP's iterations, clusters, arap_tolerance, arap_bending, history, warm_start.
#pragma once

#include <pybind11/pybind11.h>

#include "specdeform/deform/deform_options.h"

namespace specdeform::python {

namespace py = pybind11;

// `defaults` with the given keywords applied, validated. InputError for an unknown keyword, a
// value of the wrong type or out of range.
DeformOptions to_options(const py::dict& keywords, DeformOptions defaults = {});

// Every field, as to_options takes them.
py::dict to_dict(const DeformOptions& options);

}  // namespace specdeform::python
