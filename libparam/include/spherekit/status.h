// Errors as values: every fallible library call returns Status or Result<T>.
// No exception crosses the public API and the library never aborts or prints.
#pragma once

#include <string>
#include <utility>
#include <variant>

namespace spherekit {

// The single table of error codes: name, process exit code used by the CLI, and a
// short description. Codes separate "input not supported" (InvalidInput,
// Unsupported, ParseError) from "we failed" (SolverFailed, Internal) and from
// Cancelled, so corpus runs can tell them apart.
#define SPHEREKIT_ERROR_CODES(X)                                   \
  X(Ok, 0, "ok")                                                   \
  X(InvalidArgument, 2, "invalid argument")                        \
  X(InvalidInput, 3, "invalid input")                              \
  X(ParseError, 3, "malformed file")                               \
  X(Unsupported, 3, "unsupported input")                           \
  X(IoError, 4, "input/output error")                              \
  X(SolverFailed, 5, "solver failed")                              \
  X(Internal, 6, "internal error")                                 \
  X(Cancelled, 130, "cancelled")

enum class ErrorCode {
#define SPHEREKIT_X(name, exit_code, text) name,
  SPHEREKIT_ERROR_CODES(SPHEREKIT_X)
#undef SPHEREKIT_X
};

/// Short name of an error code ("InvalidInput").
const char* error_code_name(ErrorCode code);
/// Process exit code the command line uses for an error code (0 for Ok).
int error_code_exit_code(ErrorCode code);

/// An error code plus a one-line, human-readable message that names the file (when
/// there is one) and the problem, e.g. "cow.obj: vertex 254 is non-manifold (2 fans)".
class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(ErrorCode code, std::string message) : code_(code), message_(std::move(message)) {}
  static Status ok_status() { return Status(); }

  bool ok() const { return code_ == ErrorCode::Ok; }
  ErrorCode code() const { return code_; }
  const std::string& message() const { return message_; }

  /// Returns a copy whose message is prefixed with `context: ` (e.g. a file name).
  Status with_context(const std::string& context) const {
    if (ok()) return *this;
    return Status(code_, context + ": " + message_);
  }

 private:
  ErrorCode code_ = ErrorCode::Ok;
  std::string message_;
};

/// Either a value or an error Status (never both, never an Ok status).
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : data_(std::move(value)) {}          // NOLINT: implicit by design
  Result(Status status) : data_(std::move(status)) {}   // NOLINT: implicit by design
  Result(ErrorCode code, std::string message) : data_(Status(code, std::move(message))) {}

  bool ok() const { return std::holds_alternative<T>(data_); }
  const Status& status() const {
    static const Status kOk;
    return ok() ? kOk : std::get<Status>(data_);
  }
  T& value() & { return std::get<T>(data_); }
  const T& value() const& { return std::get<T>(data_); }
  T&& value() && { return std::get<T>(std::move(data_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

 private:
  std::variant<T, Status> data_;
};

}  // namespace spherekit

#define SPHEREKIT_CONCAT_INNER(a, b) a##b
#define SPHEREKIT_CONCAT(a, b) SPHEREKIT_CONCAT_INNER(a, b)

/// Returns the Status from the enclosing function if `expr` (a Status) is an error.
#define SPHEREKIT_RETURN_IF_ERROR(expr)                 \
  do {                                                  \
    ::spherekit::Status _sk_status = (expr);            \
    if (!_sk_status.ok()) return _sk_status;            \
  } while (0)

/// `SPHEREKIT_ASSIGN_OR_RETURN(auto x, f());` — unwraps a Result or returns its Status.
#define SPHEREKIT_ASSIGN_OR_RETURN(lhs, expr)                                  \
  auto SPHEREKIT_CONCAT(_sk_result_, __LINE__) = (expr);                       \
  if (!SPHEREKIT_CONCAT(_sk_result_, __LINE__).ok())                           \
    return SPHEREKIT_CONCAT(_sk_result_, __LINE__).status();                   \
  lhs = std::move(SPHEREKIT_CONCAT(_sk_result_, __LINE__)).value()
