// libFuzzer harness: a collection folder's manifest (collection.json) and feature list
// (features.txt), as every collection command reads them (tools/spherekit/collection.h). The
// input is split at its first NUL byte: manifest before, features.txt after (no NUL: no
// features.txt). The reader takes a folder, so both are written into a scratch folder of this
// process. Contract: errors are one line naming a file of the folder; on success every
// feature has a unit location and a unique name, and every member a name and a plain map file
// name.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "collection.h"
#include "fuzz_common.h"

namespace {

const std::string& scratch_dir() {
  static const std::string dir = [] {
    const std::string d = (std::filesystem::temp_directory_path() / ("spherekit_fuzz_collection_" + std::to_string(getpid()))).string();
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

void put(const std::string& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace spherekit;
  const std::string_view all = fuzz::bytes_of(data, size);
  const std::size_t nul = all.find('\0');
  const std::string& dir = scratch_dir();
  put(dir + "/collection.json", all.substr(0, nul));
  std::error_code ec;
  if (nul == std::string_view::npos)
    std::filesystem::remove(dir + "/features.txt", ec);
  else
    put(dir + "/features.txt", all.substr(nul + 1));
  Result<cli::CollectionInfo> info = cli::read_collection(dir);
  if (!info.ok()) {
    fuzz::require(!info.status().message().empty());
    fuzz::require(info.status().message().find('\n') == std::string::npos);
    fuzz::require(info.status().message().rfind(dir, 0) == 0);
    return 0;
  }
  fuzz::require(!info->feature_names.empty());
  fuzz::require(info->feature_names.size() == info->locations.size());
  std::set<std::string> names(info->feature_names.begin(), info->feature_names.end());
  fuzz::require(names.size() == info->feature_names.size());
  for (const Eigen::Vector3d& p : info->locations) fuzz::require(p.allFinite() && std::abs(p.norm() - 1) < 1e-6);
  for (const cli::Json& m : info->manifest["meshes"]) {
    const std::string map = m["map"].get<std::string>();
    fuzz::require(!map.empty() && map.find('/') == std::string::npos && map != "." && map != "..");
  }
  return 0;
}
