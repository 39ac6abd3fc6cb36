// Atomic output files: write to a temporary file in the target's folder, then rename.
// Interrupted or failed writes leave no partial output and never clobber the old file.
#pragma once

#include <string>

#include "spherekit/status.h"

namespace spherekit::formats {

/// Writes `bytes` to `path` atomically (temp file + fsync + rename). Errors: IoError.
Status write_file_atomic(const std::string& path, const std::string& bytes);

/// Reads a whole file. Errors: IoError naming the file.
Result<std::string> read_file(const std::string& path);

/// Removes temporary files this process created and has not yet renamed (for signal
/// handlers: async-signal-safe, best effort).
void remove_pending_temp_files() noexcept;

}  // namespace spherekit::formats
