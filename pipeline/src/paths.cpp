// Output path checks (paths.h).
#include "spherekit/pipeline/paths.h"

#include <filesystem>
#include <system_error>

namespace fs = std::filesystem;

namespace spherekit::pipeline {

Status require_output_folders(const std::vector<std::string>& paths) {
  for (const std::string& path : paths) {
    if (path.empty()) continue;
    const fs::path parent = fs::path(path).parent_path();
    std::error_code ec;
    if (!parent.empty() && !fs::is_directory(parent, ec))
      return Status(ErrorCode::IoError, path + ": folder '" + parent.string() + "' does not exist");
  }
  return Status::ok_status();
}

}  // namespace spherekit::pipeline
