// Checks on output paths that every job makes before any work.
#pragma once

#include <string>
#include <vector>

#include "spherekit/status.h"

namespace spherekit::pipeline {

/// IoError naming the first output path whose folder does not exist (or is not a folder).
/// Jobs that write several files call it before any work, so that a bad second path cannot
/// fail the job after the first file was written. Empty paths are skipped.
Status require_output_folders(const std::vector<std::string>& paths);

}  // namespace spherekit::pipeline
