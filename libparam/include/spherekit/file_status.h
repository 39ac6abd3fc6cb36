// Errors name their file first: the one helper readers, jobs and the command line share.
#pragma once

#include <string>

#include "spherekit/status.h"

namespace spherekit {

/// `status` with its message prefixed by `path: ` unless it already starts with the path, so
/// that every input error names its file first (readers usually do; not every stage does).
inline Status with_file(const Status& status, const std::string& path) {
  if (status.ok() || status.message().rfind(path, 0) == 0) return status;
  return status.with_context(path);
}

}  // namespace spherekit
