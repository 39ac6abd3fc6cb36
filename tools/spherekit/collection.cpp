// The collection folder: manifest reading and validation, atomic folder replacement.
#include "collection.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <system_error>

#include "spherekit/formats/atomic_file.h"

namespace fs = std::filesystem;

namespace spherekit::cli {
namespace {

Status bad(const std::string& file, const std::string& what) {
  return Status(ErrorCode::InvalidInput, file + ": " + what);
}

bool has_marker(const fs::path& dir, const char* marker) {
  std::error_code ec;
  return fs::is_regular_file(dir / marker, ec);
}

bool is_empty_dir(const fs::path& dir) {
  std::error_code ec;
  return fs::is_directory(dir, ec) && fs::is_empty(dir, ec);
}

}  // namespace

Result<CollectionInfo> read_collection(const std::string& dir) {
  const std::string file = (fs::path(dir) / kCollectionManifest).string();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return Status(ErrorCode::IoError, dir + ": no such collection folder");
  if (!fs::is_regular_file(file, ec))
    return Status(ErrorCode::IoError, file + ": missing (not a collection folder; make one with 'spherekit consistent')");
  SPHEREKIT_ASSIGN_OR_RETURN(std::string text, formats::read_file(file));
  CollectionInfo c;
  c.dir = dir;
  c.manifest = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (c.manifest.is_discarded()) return Status(ErrorCode::ParseError, file + ": not valid JSON");
  const Json& m = c.manifest;
  if (!m.is_object() || m.value("format", std::string()) != kCollectionFormat)
    return bad(file, std::string("not a ") + kCollectionFormat + " manifest");
  if (!m.contains("format_version") || !m["format_version"].is_number_integer() ||
      m["format_version"].get<int>() > kCollectionFormatVersion)
    return bad(file, "unsupported format_version (this spherekit reads up to " +
                         std::to_string(kCollectionFormatVersion) + ")");
  if (!m.contains("features") || !m["features"].is_array()) return bad(file, "missing 'features'");
  for (const Json& f : m["features"]) {
    if (!f.is_object() || !f.contains("name") || !f["name"].is_string() || !f.contains("location") ||
        !f["location"].is_array() || f["location"].size() != 3)
      return bad(file, "each feature needs a name and a location [x, y, z]");
    Eigen::Vector3d p;
    for (int a = 0; a < 3; ++a) {
      if (!f["location"][static_cast<size_t>(a)].is_number()) return bad(file, "feature location is not numeric");
      p[a] = f["location"][static_cast<size_t>(a)].get<double>();
    }
    if (!p.allFinite() || std::abs(p.norm() - 1) > 1e-9)
      return bad(file, "location of feature '" + f["name"].get<std::string>() + "' is not a unit vector");
    c.feature_names.push_back(f["name"].get<std::string>());
    c.locations.push_back(p);
  }
  if (c.feature_names.empty()) return bad(file, "no features");
  if (!m.contains("meshes") || !m["meshes"].is_array()) return bad(file, "missing 'meshes'");
  for (const Json& e : m["meshes"])
    if (!e.is_object() || !e.contains("name") || !e["name"].is_string() || !e.contains("map") ||
        !e["map"].is_string())
      return bad(file, "each mesh needs a name and a map file");
  return c;
}

int find_member(const CollectionInfo& c, const std::string& mesh_path) {
  const std::string stem = file_stem(mesh_path);
  std::error_code ec;
  const fs::path abs = fs::weakly_canonical(fs::absolute(mesh_path, ec), ec);
  int i = 0, by_stem = -1;
  for (const Json& e : c.manifest["meshes"]) {
    if (e.contains("source") && e["source"].is_string() && fs::path(e["source"].get<std::string>()) == abs) return i;
    if (by_stem < 0 && e["name"].get<std::string>() == stem) by_stem = i;
    ++i;
  }
  return by_stem;
}

Status require_collection_target(const std::string& dir) { return require_staged_folder_target(dir, kCollectionManifest); }

Status require_staged_folder_target(const std::string& dir, const char* marker) {
  std::error_code ec;
  const fs::path p(dir);
  const fs::path parent = fs::absolute(p, ec).parent_path();
  if (!fs::is_directory(parent, ec)) return Status(ErrorCode::IoError, dir + ": parent folder does not exist");
  if (!fs::exists(p, ec)) return Status();
  if (!fs::is_directory(p, ec)) return Status(ErrorCode::IoError, dir + ": exists and is not a folder");
  if (is_empty_dir(p) || has_marker(p, marker)) return Status();
  if (std::string(marker) == kCollectionManifest)
    return Status(ErrorCode::IoError, dir + ": folder is not empty and not a collection; refusing to replace it");
  return Status(ErrorCode::IoError, dir + ": folder is not empty and has no " + marker + "; refusing to replace it");
}

Status write_collection_folder(const std::string& dir, const std::function<Status(const std::string&)>& write_into) {
  return write_staged_folder(dir, kCollectionManifest, write_into);
}

Status write_staged_folder(const std::string& dir, const char* marker,
                           const std::function<Status(const std::string&)>& write_into) {
  SPHEREKIT_RETURN_IF_ERROR(require_staged_folder_target(dir, marker));
  std::error_code ec;
  const fs::path target = fs::absolute(dir, ec).lexically_normal();
  const fs::path base = target.has_filename() ? target : target.parent_path();
  const std::string tag = "." + base.filename().string() + ".partial." + std::to_string(::getpid());
  const fs::path staging = base.parent_path() / tag;
  fs::remove_all(staging, ec);
  if (!fs::create_directory(staging, ec))
    return Status(ErrorCode::IoError, staging.string() + ": cannot create staging folder (" + ec.message() + ")");
  Status s = write_into(staging.string());
  if (!s.ok()) {
    fs::remove_all(staging, ec);
    return s;
  }
  // Swap: the old folder aside, the new one in, the old one removed. Readers see the old
  // collection or the new one (a brief moment with none in between).
  const fs::path old = base.parent_path() / ("." + base.filename().string() + ".old." + std::to_string(::getpid()));
  const bool had_old = fs::exists(base, ec);
  if (had_old) {
    fs::remove_all(old, ec);
    fs::rename(base, old, ec);
    if (ec) {
      fs::remove_all(staging, ec);
      return Status(ErrorCode::IoError, dir + ": cannot replace the existing folder (" + ec.message() + ")");
    }
  }
  fs::rename(staging, base, ec);
  if (ec) {
    const std::string why = ec.message();
    if (had_old) fs::rename(old, base, ec);
    fs::remove_all(staging, ec);
    return Status(ErrorCode::IoError, dir + ": cannot move the new folder into place (" + why + ")");
  }
  if (had_old) fs::remove_all(old, ec);
  return Status();
}

std::string sphere_points_text(const std::vector<std::string>& names, const std::vector<Eigen::Vector3d>& points) {
  std::string out;
  for (size_t i = 0; i < names.size(); ++i)
    out += strprintf("%s %.17g %.17g %.17g\n", names[i].c_str(), points[i].x(), points[i].y(), points[i].z());
  return out;
}

}  // namespace spherekit::cli
