// The `spherekit` Python module (pybind11): the library's stages on numpy arrays.
// Errors: one exception class per ErrorCode family, all deriving from spherekit.Error, with
// the library's one-line messages. Long stages release the GIL; progress and Ctrl-C reach
// them through the library's ProgressFn (Progress in py_common.h).
#include <map>

#include "py_common.h"
#include "spherekit/version.h"

namespace spherekit::py {
namespace {

// Exception classes by ErrorCode, created once at import (PyErr_NewException with the
// builtin base that fits, so `except ValueError` and `except OSError` work as expected).
std::map<ErrorCode, PyObject*>& exception_types() {
  static std::map<ErrorCode, PyObject*> types;
  return types;
}

PyObject* new_exception(pyb::module_& m, const char* name, const pyb::tuple& bases, const char* doc) {
  PyObject* type = PyErr_NewExceptionWithDoc((std::string("spherekit.") + name).c_str(), doc, bases.ptr(), nullptr);
  if (!type) throw pyb::error_already_set();
  m.add_object(name, pyb::handle(type));
  return type;
}

}  // namespace

void throw_status(const Status& status, const std::string& context) {
  const std::string message = context.empty() ? status.message() : context + ": " + status.message();
  auto it = exception_types().find(status.code());
  PyObject* type = it != exception_types().end() ? it->second : exception_types().at(ErrorCode::Internal);
  pyb::object value = pyb::reinterpret_steal<pyb::object>(PyObject_CallFunction(type, "s", message.c_str()));
  if (!value) throw pyb::error_already_set();
  pyb::setattr(value, "code", pyb::str(error_code_name(status.code())));
  pyb::setattr(value, "exit_code", pyb::int_(error_code_exit_code(status.code())));
  PyErr_SetObject(type, value.ptr());
  throw pyb::error_already_set();
}

ProgressFn Progress::fn() {
  return [this](const ProgressEvent& e) -> bool {
    pyb::gil_scoped_acquire gil;
    if (error_ || declined_) return false;
    if (PyErr_CheckSignals() != 0) {  // Ctrl-C (KeyboardInterrupt) or another signal handler raised
      error_ = pyb::error_already_set();
      return false;
    }
    if (!callback_) return true;
    try {
      pyb::object keep_going = (*callback_)(std::string(e.stage), e.level, e.fraction);
      // None (a callback that returns nothing) means "go on"; only an explicit False cancels.
      if (!keep_going.is_none() && !keep_going.cast<bool>()) declined_ = true;
    } catch (pyb::error_already_set& err) {
      error_ = std::move(err);
    } catch (const pyb::cast_error&) {
      declined_ = true;
    }
    return !(error_ || declined_);
  };
}

void Progress::finish(const Status& stage_status, const std::string& context) {
  if (error_) {
    pyb::error_already_set err = std::move(*error_);
    error_.reset();
    throw err;
  }
  if (declined_ && (stage_status.ok() || stage_status.code() == ErrorCode::Cancelled))
    throw_status(Status(ErrorCode::Cancelled, "cancelled by the progress callback"), context);
  if (!stage_status.ok()) throw_status(stage_status, context);
}

RowMat3d to_rowmat3d(const pyb::array& a, const char* what) {
  auto arr = pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>::ensure(a);
  if (!arr || arr.ndim() != 2 || arr.shape(1) != 3)
    throw_status(Status(ErrorCode::InvalidArgument, std::string(what) + " must be an (n, 3) array of numbers"));
  return Eigen::Map<const RowMat3d>(arr.data(), arr.shape(0), 3);
}

RowMat3i to_rowmat3i(const pyb::array& a, const char* what) {
  auto arr = pyb::array_t<std::int64_t, pyb::array::c_style | pyb::array::forcecast>::ensure(a);
  if (!arr || arr.ndim() != 2 || arr.shape(1) != 3)
    throw_status(Status(ErrorCode::InvalidArgument, std::string(what) + " must be an (n, 3) array of integers"));
  RowMat3i out(arr.shape(0), 3);
  const std::int64_t* p = arr.data();
  for (Eigen::Index i = 0; i < out.size(); ++i) {
    if (p[i] < INT32_MIN || p[i] > INT32_MAX)
      throw_status(Status(ErrorCode::InvalidArgument, std::string(what) + ": index " + std::to_string(p[i]) + " out of range"));
    out.data()[i] = static_cast<std::int32_t>(p[i]);
  }
  return out;
}

void bind_mesh_and_errors(pyb::module_& m) {
  pyb::handle exception = PyExc_Exception, value_error = PyExc_ValueError, os_error = PyExc_OSError,
              runtime_error = PyExc_RuntimeError;
  PyObject* base = new_exception(m, "Error", pyb::make_tuple(exception),
                                 "Base of SphereKit's errors; .code is the ErrorCode name, .exit_code the command line's exit code.");
  pyb::handle b = base;
  auto& t = exception_types();
  t[ErrorCode::InvalidArgument] = new_exception(m, "InvalidArgument", pyb::make_tuple(b, value_error),
                                                "An argument is out of range or inconsistent (exit code 2).");
  PyObject* invalid_input = new_exception(m, "InvalidInput", pyb::make_tuple(b, value_error),
                                          "The input is not supported: not genus 0, non-manifold, ... (exit code 3).");
  t[ErrorCode::InvalidInput] = invalid_input;
  t[ErrorCode::ParseError] = new_exception(m, "ParseError", pyb::make_tuple(pyb::handle(invalid_input)),
                                           "A malformed or truncated file (exit code 3).");
  t[ErrorCode::Unsupported] = new_exception(m, "Unsupported", pyb::make_tuple(pyb::handle(invalid_input)),
                                            "Content of a kind SphereKit does not read (exit code 3).");
  t[ErrorCode::IoError] = new_exception(m, "IoError", pyb::make_tuple(b, os_error),
                                        "A file cannot be opened, read or written (exit code 4).");
  t[ErrorCode::SolverFailed] = new_exception(m, "SolverFailed", pyb::make_tuple(b, runtime_error),
                                             "The computation failed, e.g. no bijective map (exit code 5).");
  t[ErrorCode::Internal] = new_exception(m, "InternalError", pyb::make_tuple(b, runtime_error),
                                         "A bug: please report it with the input (exit code 6).");
  t[ErrorCode::Cancelled] = new_exception(m, "Cancelled", pyb::make_tuple(b),
                                          "The progress callback returned False (exit code 130).");

  pyb::class_<Mesh>(m, "Mesh", "A triangle mesh: V (#V x 3 float64) and F (#F x 3 int32), views of the library's arrays.")
      .def(pyb::init([](const pyb::array& V, const pyb::array& F) {
             Mesh mesh;
             mesh.mesh.V = to_rowmat3d(V, "V");
             mesh.mesh.F = to_rowmat3i(F, "F");
             return mesh;
           }),
           pyb::arg("V"), pyb::arg("F"), "Copies V (n x 3) and F (m x 3) once into the library's layout.")
      .def_property_readonly(
          "V", [](Mesh& self) -> RowMat3d& { return self.mesh.V; }, pyb::return_value_policy::reference_internal)
      .def_property_readonly(
          "F", [](Mesh& self) -> RowMat3i& { return self.mesh.F; }, pyb::return_value_policy::reference_internal)
      .def_readwrite("source", &Mesh::source, "file the mesh was read from ('' if built from arrays); prefixes errors")
      .def_property_readonly("vertices", [](const Mesh& self) { return self.mesh.V.rows(); })
      .def_property_readonly("faces", [](const Mesh& self) { return self.mesh.F.rows(); })
      .def("__repr__", [](const Mesh& self) {
        return "<spherekit.Mesh " + std::to_string(self.mesh.V.rows()) + " vertices, " + std::to_string(self.mesh.F.rows()) +
               " faces" + (self.source.empty() ? "" : " from " + self.source) + ">";
      });
}

}  // namespace spherekit::py

PYBIND11_MODULE(spherekit, m) {
  m.doc() =
      "SphereKit: bijective spherical parameterization of genus-0 meshes (Praun & Hoppe 2003), consistent\n"
      "maps of collections (Asirvatham, Praun, Hoppe 2005), geometry images, glTF LODs and cages.\n"
      "Arrays are numpy; long stages release the GIL, and take progress=callable(stage, level, fraction)\n"
      "(return False to cancel: spherekit.Cancelled); Ctrl-C interrupts them (KeyboardInterrupt).";
  m.attr("__version__") = spherekit::kVersion;
  spherekit::py::bind_mesh_and_errors(m);
  spherekit::py::bind_param(m);
  spherekit::py::bind_formats(m);
  spherekit::py::bind_convert(m);
  spherekit::py::bind_pipeline(m);
}
