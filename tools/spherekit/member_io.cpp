// Members of a collection for the applications, and all-or-nothing outputs (member_io.h).
#include "member_io.h"

#include <unistd.h>

#include <filesystem>
#include <system_error>

#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/formats/sphere_map_io.h"

namespace fs = std::filesystem;

namespace spherekit::cli {
namespace {

Result<Member> load_index(const CollectionInfo& c, int i, const std::string& fallback_path) {
  const Json& e = c.manifest["meshes"][static_cast<std::size_t>(i)];
  Member m;
  m.index = i;
  m.name = e["name"].get<std::string>();
  m.source = e.contains("source") && e["source"].is_string() ? e["source"].get<std::string>() : std::string();
  std::error_code ec;
  if ((m.source.empty() || !fs::is_regular_file(m.source, ec)) && !fallback_path.empty() &&
      fs::is_regular_file(fallback_path, ec))
    m.source = fallback_path;
  if (m.source.empty())
    return Status(ErrorCode::InvalidInput, c.dir + ": member " + m.name + " has no source mesh in the manifest");
  SPHEREKIT_ASSIGN_OR_RETURN(m.mesh, formats::read_mesh(m.source));
  const std::string map_path = (fs::path(c.dir) / e["map"].get<std::string>()).string();
  SPHEREKIT_ASSIGN_OR_RETURN(m.map, formats::read_sphere_map(map_path, m.mesh));
  if (e.contains("feature_vertices") && e["feature_vertices"].is_array()) {
    const Json& fv = e["feature_vertices"];
    m.features.resize(static_cast<Eigen::Index>(fv.size()), 3);
    for (std::size_t k = 0; k < fv.size(); ++k) {
      if (!fv[k].is_number_integer() || fv[k].get<long long>() < 0 || fv[k].get<long long>() >= m.mesh.V.rows())
        return Status(ErrorCode::InvalidInput, (fs::path(c.dir) / kCollectionManifest).string() + ": member " + m.name +
                                                   ": feature vertex out of range");
      m.features.row(static_cast<Eigen::Index>(k)) = m.mesh.V.row(fv[k].get<Eigen::Index>());
    }
  }
  return m;
}

bool holds_marker(const fs::path& dir, const std::string& marker) {
  std::error_code ec;
  return fs::is_regular_file(dir / marker, ec);
}

}  // namespace

Result<Member> load_member(const CollectionInfo& c, const std::string& name_or_path) {
  const int i = find_member(c, name_or_path);
  if (i < 0) {
    std::string names;
    for (const Json& e : c.manifest["meshes"]) names += (names.empty() ? "" : ", ") + e["name"].get<std::string>();
    return Status(ErrorCode::InvalidInput, name_or_path + ": not a member of the collection " + c.dir + " (members: " +
                                               names + ")");
  }
  return load_index(c, i, name_or_path);
}

Result<std::vector<Member>> load_all_members(const CollectionInfo& c) {
  std::vector<Member> out;
  for (std::size_t i = 0; i < c.manifest["meshes"].size(); ++i) {
    SPHEREKIT_ASSIGN_OR_RETURN(Member m, load_index(c, static_cast<int>(i), {}));
    out.push_back(std::move(m));
  }
  return out;
}

Status OutputFiles::write_all() const {
  for (std::size_t k = 0; k < files_.size(); ++k) {
    Status s = formats::write_file_atomic(files_[k].first, files_[k].second);
    if (s.ok()) continue;
    std::error_code ec;
    for (std::size_t j = 0; j < k; ++j) fs::remove(files_[j].first, ec);
    return s;
  }
  return Status();
}

Status require_output_folder(const std::string& dir, const std::string& marker) {
  std::error_code ec;
  const fs::path p(dir);
  if (!fs::is_directory(fs::absolute(p, ec).parent_path(), ec))
    return Status(ErrorCode::IoError, dir + ": parent folder does not exist");
  if (!fs::exists(p, ec)) return Status();
  if (!fs::is_directory(p, ec)) return Status(ErrorCode::IoError, dir + ": exists and is not a folder");
  if (fs::is_empty(p, ec) || holds_marker(p, marker)) return Status();
  return Status(ErrorCode::IoError, dir + ": folder is not empty and has no " + marker + "; refusing to replace it");
}

Status write_output_folder(const std::string& dir, const std::string& marker, const OutputFiles& files) {
  SPHEREKIT_RETURN_IF_ERROR(require_output_folder(dir, marker));
  std::error_code ec;
  const fs::path target = fs::absolute(dir, ec).lexically_normal();
  const fs::path base = target.has_filename() ? target : target.parent_path();
  const fs::path staging = base.parent_path() / ("." + base.filename().string() + ".partial." + std::to_string(::getpid()));
  fs::remove_all(staging, ec);
  if (!fs::create_directory(staging, ec))
    return Status(ErrorCode::IoError, staging.string() + ": cannot create staging folder (" + ec.message() + ")");
  for (const auto& [name, bytes] : files.files()) {
    Status s = formats::write_file_atomic((staging / name).string(), bytes);
    if (!s.ok()) {
      fs::remove_all(staging, ec);
      return s;
    }
  }
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
    return Status(ErrorCode::IoError, dir + ": cannot move the output folder into place (" + why + ")");
  }
  if (had_old) fs::remove_all(old, ec);
  return Status();
}

}  // namespace spherekit::cli
