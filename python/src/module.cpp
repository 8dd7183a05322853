// The extension module specdeform._specdeform: the library's exceptions as Python exceptions, and
// the bindings of bind_*.cpp.
#include <SuiteSparse_config.h>
#include <pybind11/pybind11.h>

#include "bindings.h"
#include "specdeform/exceptions.h"
#include "specdeform/version.h"

namespace py = pybind11;

namespace {

// The Python classes of the library's exceptions (module lifetime: never released).
PyObject* error = nullptr;
PyObject* input_error = nullptr;
PyObject* solver_error = nullptr;

PyObject* add_exception(py::module_& m, const char* name, py::handle bases, const char* doc) {
  PyObject* type = PyErr_NewExceptionWithDoc((std::string("specdeform.") + name).c_str(), doc,
                                             bases.ptr(), nullptr);
  if (type == nullptr) throw py::error_already_set();
  m.add_object(name, py::handle(type));
  return type;
}

}  // namespace

PYBIND11_MODULE(_specdeform, m) {
  m.doc() = "specdeform's compiled core; use the package `specdeform`.";
  m.attr("__version__") = std::string(specdeform::version());
  // CHOLMOD prints its warnings on stdout through SuiteSparse's printf hook; here the library's
  // exceptions report what went wrong.
  SuiteSparse_config.printf_func = nullptr;

  error = add_exception(m, "Error", PyExc_Exception, "Any error of the specdeform library.");
  input_error = add_exception(m, "InputError",
                              py::make_tuple(py::handle(error), py::handle(PyExc_ValueError)),
                              "Bad input: a malformed file, array, scene or option.");
  solver_error = add_exception(m, "SolverError",
                               py::make_tuple(py::handle(error), py::handle(PyExc_RuntimeError)),
                               "A numerical method failed: a factorisation or an iteration.");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const specdeform::InputError& e) {
      PyErr_SetString(input_error, e.what());
    } catch (const specdeform::SolverError& e) {
      PyErr_SetString(solver_error, e.what());
    } catch (const specdeform::Error& e) {
      PyErr_SetString(error, e.what());
    }
  });

  specdeform::python::bind_mesh(m);
  specdeform::python::bind_spectral(m);
  specdeform::python::bind_deform(m);
}
