#include "test_paths.h"

#include <cstdlib>
#include <filesystem>

namespace fs = std::filesystem;

namespace spherekit::test {

std::optional<std::string> shared_dir() {
  if (const char* env = std::getenv("SPHEREKIT_SHARED_DIR")) {
    if (fs::is_directory(env)) return fs::absolute(env).string();
    return std::nullopt;
  }
  fs::path p = fs::path(SPHEREKIT_SOURCE_DIR).parent_path() / "shared";
  if (fs::is_directory(p)) return p.string();
  return std::nullopt;
}

std::optional<std::string> shared_meshes_dir() {
  auto s = shared_dir();
  if (!s) return std::nullopt;
  fs::path p = fs::path(*s) / "meshes";
  if (fs::is_directory(p)) return p.string();
  return std::nullopt;
}

std::string temp_dir(const std::string& name) {
  fs::path p = fs::path(SPHEREKIT_BINARY_DIR) / "test_tmp" / name;
  std::error_code ec;
  fs::remove_all(p, ec);
  fs::create_directories(p);
  return p.string();
}

}  // namespace spherekit::test
