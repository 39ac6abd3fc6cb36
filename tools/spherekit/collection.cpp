// The collection folder: manifest reading and validation, atomic folder replacement.
#include "collection.h"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <system_error>

#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/feature_io.h"
#include "spherekit/formats/mesh_io.h"

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

// DIR/features.txt must hold the manifest's features: the same names, each at the same
// location, and nothing else. It is a copy for other tools; a copy that disagrees means the
// folder was edited or mixed with another collection's, so which F is meant is unknown.
Status check_features_file(const CollectionInfo& c) {
  const std::string path = (fs::path(c.dir) / kCollectionFeatures).string();
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    return Status(ErrorCode::IoError, path + ": missing (every collection folder has one; rewrite it with 'spherekit consistent')");
  auto points = formats::read_sphere_points(path, /*require_unit=*/true);
  if (!points.ok()) return with_file(points.status(), path);
  const std::string manifest = (fs::path(c.dir) / kCollectionManifest).string();
  for (size_t k = 0; k < c.feature_names.size(); ++k) {
    auto it = std::find_if(points->begin(), points->end(),
                           [&](const SpherePoint& p) { return p.name == c.feature_names[k]; });
    if (it == points->end())
      return bad(path, "no feature '" + c.feature_names[k] + "' (" + manifest + " has it)");
    // Both files carry 17 significant digits: equal up to the last bit.
    if ((it->p - c.locations[k]).norm() > 1e-12)
      return bad(path, "feature '" + c.feature_names[k] + "' is not where " + manifest + " puts it");
  }
  if (points->size() != c.feature_names.size())
    return bad(path, strprintf("has %zu features, %s has %zu", points->size(), manifest.c_str(), c.feature_names.size()));
  return Status();
}

}  // namespace

Result<CollectionInfo> read_collection(const std::string& dir) {
  const std::string file = (fs::path(dir) / kCollectionManifest).string();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return Status(ErrorCode::IoError, dir + ": no such collection folder");
  if (!fs::is_regular_file(file, ec))
    return Status(ErrorCode::IoError, file + ": missing (not a collection folder; make one with 'spherekit consistent')");
  SPHEREKIT_ASSIGN_OR_RETURN(std::string text, formats::read_file(file));
  if (text.empty()) return Status(ErrorCode::ParseError, file + ": file is empty");
  CollectionInfo c;
  c.dir = dir;
  try {
    c.manifest = Json::parse(text);
  } catch (const Json::parse_error& e) {
    // Where it broke tells a cut-off file (a copy interrupted mid-way) from an edit gone wrong.
    if (e.byte >= text.size())
      return Status(ErrorCode::ParseError,
                    strprintf("%s: not valid JSON: ends early after %zu bytes (truncated?)", file.c_str(), text.size()));
    return Status(ErrorCode::ParseError, strprintf("%s: not valid JSON (syntax error at byte %zu)", file.c_str(), e.byte));
  } catch (const Json::exception& e) {
    // The parser's other refusals, e.g. "number overflow parsing '1e400'" (out_of_range).
    std::string why = e.what();
    if (const size_t at = why.find("] "); at != std::string::npos) why = why.substr(at + 2);
    return Status(ErrorCode::ParseError, file + ": not valid JSON (" + why + ")");
  }
  const Json& m = c.manifest;
  // (value() would throw on a "format" that is not a string: test the type first.)
  if (!m.is_object() || !m.contains("format") || !m["format"].is_string() ||
      m["format"].get<std::string>() != kCollectionFormat)
    return bad(file, std::string("not a ") + kCollectionFormat + " manifest (its \"format\" must be \"" +
                         kCollectionFormat + "\")");
  // Versions start at 1: 0, negative or non-integer versions were never written.
  if (!m.contains("format_version") || !m["format_version"].is_number_integer() ||
      m["format_version"].get<long long>() < 1 || m["format_version"].get<long long>() > kCollectionFormatVersion)
    return bad(file, "unsupported format_version " +
                         (m.contains("format_version") ? m["format_version"].dump() : std::string("(missing)")) +
                         " (this spherekit reads up to " + std::to_string(kCollectionFormatVersion) + ")");
  if (!m.contains("features") || !m["features"].is_array()) return bad(file, "missing 'features'");
  for (const Json& f : m["features"]) {
    if (!f.is_object() || !f.contains("name") || !f["name"].is_string() || f["name"].get<std::string>().empty() ||
        !f.contains("location") || !f["location"].is_array() || f["location"].size() != 3)
      return bad(file, "each feature needs a name and a location [x, y, z]");
    const std::string name = f["name"].get<std::string>();
    Eigen::Vector3d p;
    for (int a = 0; a < 3; ++a) {
      if (!f["location"][static_cast<size_t>(a)].is_number()) return bad(file, "feature location is not numeric");
      p[a] = f["location"][static_cast<size_t>(a)].get<double>();
    }
    if (!p.allFinite() || std::abs(p.norm() - 1) > 1e-9)
      return bad(file, "location of feature '" + name + "' is not a unit vector");
    // Two features of one name would be two constraints on one vertex of every member.
    if (std::find(c.feature_names.begin(), c.feature_names.end(), name) != c.feature_names.end())
      return bad(file, "duplicate feature name '" + name + "'");
    c.feature_names.push_back(name);
    c.locations.push_back(p);
  }
  if (c.feature_names.empty()) return bad(file, "no features");
  if (!m.contains("meshes") || !m["meshes"].is_array()) return bad(file, "missing 'meshes'");
  std::vector<std::string> names, maps;
  for (const Json& e : m["meshes"]) {
    if (!e.is_object() || !e.contains("name") || !e["name"].is_string() || !e.contains("map") ||
        !e["map"].is_string())
      return bad(file, "each mesh needs a name and a map file");
    const std::string name = e["name"].get<std::string>(), map = e["map"].get<std::string>();
    // Maps live in the folder (add writes them there): a path would read or overwrite
    // files elsewhere.
    if (map.empty() || map == "." || map == ".." || map.find('/') != std::string::npos)
      return bad(file, "map '" + map + "' of mesh '" + name + "' is not a file name in the collection folder");
    if (std::find(names.begin(), names.end(), name) != names.end()) return bad(file, "duplicate mesh name '" + name + "'");
    if (std::find(maps.begin(), maps.end(), map) != maps.end())
      return bad(file, "map '" + map + "' is listed for two meshes");
    if (e.contains("vertices") && !(e["vertices"].is_number_integer() && e["vertices"].get<long long>() >= 4))
      return bad(file, "'vertices' of mesh '" + name + "' is not a vertex count");
    names.push_back(name);
    maps.push_back(map);
  }
  SPHEREKIT_RETURN_IF_ERROR(check_features_file(c));
  return c;
}

Status check_member_maps(const CollectionInfo& c, int skip) {
  const std::string manifest = (fs::path(c.dir) / kCollectionManifest).string();
  int i = 0;
  for (const Json& e : c.manifest["meshes"]) {
    if (i++ == skip) continue;
    const std::string name = e["name"].get<std::string>();
    const std::string path = (fs::path(c.dir) / e["map"].get<std::string>()).string();
    std::error_code ec;
    if (!fs::is_regular_file(path, ec))
      return Status(ErrorCode::IoError, path + ": missing (the map of member '" + name + "' in " + manifest + ")");
    auto map = formats::read_mesh(path);
    if (!map.ok()) return with_file(map.status(), path);
    if (e.contains("vertices") && map->V.rows() != e["vertices"].get<long long>())
      return bad(path, strprintf("has %lld vertices, %s records %lld for member '%s'",
                                 static_cast<long long>(map->V.rows()), manifest.c_str(),
                                 e["vertices"].get<long long>(), name.c_str()));
  }
  return Status();
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
  // Ctrl-C while the files are written only sets the cancel flag (instead of exiting at
  // once, which removes temporary files but would leave the staging folder behind): the
  // staging folder is removed here and the command reports the cancellation.
  Status s;
  {
    ComputeScope cancellable;
    s = write_into(staging.string());
  }
  if (s.ok() && cancel_requested()) s = cancelled_status();
  if (!s.ok()) {
    fs::remove_all(staging, ec);
    return s;
  }
  // Swap: the old folder aside, the new one in, the old one removed. Readers see the old
  // collection or the new one (a brief moment with none in between). SIGINT/SIGTERM wait
  // until it is done: an exit between the renames would leave no folder at DIR, the old one
  // hidden as .DIR.old.PID.
  sigset_t stop_signals, saved_mask;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, &saved_mask);
  const Status swapped = [&]() -> Status {
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
  }();
  pthread_sigmask(SIG_SETMASK, &saved_mask, nullptr);  // a pending signal ends the program here
  return swapped;
}

std::string sphere_points_text(const std::vector<std::string>& names, const std::vector<Eigen::Vector3d>& points) {
  std::string out;
  for (size_t i = 0; i < names.size(); ++i)
    out += strprintf("%s %.17g %.17g %.17g\n", names[i].c_str(), points[i].x(), points[i].y(), points[i].z());
  return out;
}

}  // namespace spherekit::cli
