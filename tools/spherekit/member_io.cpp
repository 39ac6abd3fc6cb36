// Members of a collection for the applications, and all-or-nothing outputs (member_io.h).
#include "member_io.h"

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

// Both delegate to the staged-folder writer the collection commands use (collection.h), so
// every folder-writing command gets the same cancellation and signal-safe swap.
Status require_output_folder(const std::string& dir, const std::string& marker) {
  return require_staged_folder_target(dir, marker.c_str());
}

Status write_output_folder(const std::string& dir, const std::string& marker, const OutputFiles& files) {
  return write_staged_folder(dir, marker.c_str(), [&](const std::string& staging) -> Status {
    for (const auto& [name, bytes] : files.files())
      SPHEREKIT_RETURN_IF_ERROR(formats::write_file_atomic((fs::path(staging) / name).string(), bytes));
    return Status();
  });
}

}  // namespace spherekit::cli
