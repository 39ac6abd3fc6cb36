// Shared pieces of the Python module (python/src/*.cpp): the Mesh holder, Status -> exception,
// and the progress callback that carries Ctrl-C and a Python callback into the library.
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <optional>
#include <string>

#include "spherekit/mesh.h"
#include "spherekit/progress.h"
#include "spherekit/sphere_param.h"
#include "spherekit/status.h"

namespace spherekit::py {

namespace pyb = pybind11;

/// A triangle mesh owned by the library's TriMesh. Python sees V and F as numpy views of it
/// (no copy); constructing one from arrays copies them once into the library's layout
/// (float64 / int32, row-major). `source` (the file it was read from) prefixes error
/// messages as the command line's do.
struct Mesh {
  TriMesh mesh;
  std::string source;
};

/// Raises the Python exception of `status`'s code (spherekit.InvalidInput, ...) with its
/// message; `context`, when given, prefixes the message ("FILE: problem").
[[noreturn]] void throw_status(const Status& status, const std::string& context = {});

/// Unwraps a Result or raises.
template <class T>
T unwrap(Result<T>&& r, const std::string& context = {}) {
  if (!r.ok()) throw_status(r.status(), context);
  return std::move(r).value();
}
// The collection calls' sphere options: collection_sphere_options() (the collection stages'
// weights, no coarse-layout precision) with the call's effort, seed and threads.
inline SphereParamOptions collection_options(int effort, std::uint64_t seed, int threads) {
  SphereParamOptions o = collection_sphere_options();
  o.effort = effort;
  o.seed = seed;
  o.threads = threads;
  return o;
}

inline void check(const Status& s, const std::string& context = {}) {
  if (!s.ok()) throw_status(s, context);
}

/// The ProgressFn given to a library stage that runs with the GIL released. Each call takes
/// the GIL, checks for a pending signal (Ctrl-C: PyErr_CheckSignals) and calls the Python
/// callback `progress(stage, level, fraction)` if given; a signal, a False return or an
/// exception in the callback cancels the stage. After the stage, finish() re-raises the
/// signal's KeyboardInterrupt or the callback's exception, or spherekit.Cancelled when the
/// callback returned False.
class Progress {
 public:
  explicit Progress(std::optional<pyb::function> callback) : callback_(std::move(callback)) {}
  ProgressFn fn();
  /// Raises what cancelled the stage (if the stage was cancelled); otherwise returns.
  void finish(const Status& stage_status, const std::string& context = {});

 private:
  std::optional<pyb::function> callback_;
  std::optional<pyb::error_already_set> error_;
  bool declined_ = false;
};

/// Runs `stage(progress_fn)` with the GIL released and returns its Result, raising on error.
template <class F>
auto run_stage(std::optional<pyb::function> callback, const std::string& context, F&& stage) {
  Progress progress(std::move(callback));
  const ProgressFn fn = progress.fn();
  auto result = [&] {
    pyb::gil_scoped_release release;
    return stage(fn);
  }();
  progress.finish(result.status(), context);
  return std::move(result).value();
}

/// A float64 (n x 3) or int32 (n x 3) array copied into the library's row-major layout.
RowMat3d to_rowmat3d(const pyb::array& a, const char* what);
RowMat3i to_rowmat3i(const pyb::array& a, const char* what);

void bind_mesh_and_errors(pyb::module_& m);
void bind_param(pyb::module_& m);
void bind_formats(pyb::module_& m);
void bind_convert(pyb::module_& m);
void bind_pipeline(pyb::module_& m);

}  // namespace spherekit::py
