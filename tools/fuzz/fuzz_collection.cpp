// libFuzzer harness: a collection folder's manifest (collection.json) and feature list
// (features.txt), as every collection command reads them (spherekit/formats/collection.h). The
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

#include "fuzz_common.h"
#include "spherekit/formats/collection.h"

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
  Result<formats::Collection> info = formats::read_collection(dir);
  if (!info.ok()) {
    fuzz::require(!info.status().message().empty());
    fuzz::require(info.status().message().find('\n') == std::string::npos);
    fuzz::require(info.status().message().rfind(dir, 0) == 0);
    return 0;
  }
  const formats::CollectionManifest& m = info->manifest;
  fuzz::require(!m.features.empty());
  const std::vector<std::string> feature_names = m.feature_names();
  std::set<std::string> names(feature_names.begin(), feature_names.end());
  fuzz::require(names.size() == feature_names.size());
  for (const Eigen::Vector3d& p : m.locations()) fuzz::require(p.allFinite() && std::abs(p.norm() - 1) < 1e-6);
  for (const formats::CollectionMember& e : m.members)
    fuzz::require(!e.map.empty() && e.map.find('/') == std::string::npos && e.map != "." && e.map != "..");
  // Written back and read again, a manifest is the same manifest.
  auto again = formats::parse_collection_manifest(formats::collection_manifest_text(m), "again");
  fuzz::require(again.ok());
  fuzz::require(formats::collection_manifest_text(again.value()) == formats::collection_manifest_text(m));
  return 0;
}
