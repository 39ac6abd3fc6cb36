// Locked, crash-safe member updates of a collection folder (collection_update.h).
#include "spherekit/pipeline/collection_update.h"

#include <algorithm>
#include <filesystem>
#include <system_error>

#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/folder_lock.h"
#include "spherekit/formats/folder_swap.h"

namespace fs = std::filesystem;

namespace spherekit::pipeline {
namespace {

// Temporary files of atomic writes (`.<name>.tmp.<pid>.<n>`, atomic_file.cpp) left in the
// folder by a writer that was killed. Only lock holders write into a collection folder, so
// under the lock every such file is a dead writer's.
void remove_stale_temp_files(const std::string& dir) {
  std::error_code ec;
  std::vector<fs::path> stale;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string n = e.path().filename().string();
    if (n.size() > 1 && n[0] == '.' && n.find(".tmp.") != std::string::npos && e.is_regular_file(ec))
      stale.push_back(e.path());
  }
  for (const fs::path& p : stale) fs::remove(p, ec);
}

bool same_locations(const formats::CollectionManifest& m, const MemberUpdate& u) {
  return m.feature_names() == u.feature_names && m.locations() == u.locations;
}

// A replaced member: the folder's new version holds hard links to every other file (the lock
// file too, so that lock holders and waiters keep one lock), the new map and manifest.
Status replace_by_new_version(const std::string& dir, const std::string& map_name,
                              const formats::CollectionManifest& manifest, const MemberUpdate& u) {
  SPHEREKIT_ASSIGN_OR_RETURN(formats::StagingFolder staging, formats::StagingFolder::create(dir));
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string n = e.path().filename().string();
    if (n == map_name || n == formats::kCollectionManifest || !e.is_regular_file(ec)) continue;
    const fs::path to = fs::path(staging.path()) / n;
    fs::create_hard_link(e.path(), to, ec);
    if (ec) {
      // A file system without hard links: a copy (the lock file must stay one inode, though).
      if (n == formats::kFolderLockFile)
        return Status(ErrorCode::IoError, dir + ": cannot link the lock file into the new version (" + ec.message() + ")");
      ec.clear();
      fs::copy_file(e.path(), to, ec);
      if (ec) return Status(ErrorCode::IoError, to.string() + ": cannot copy (" + ec.message() + ")");
    }
  }
  if (ec) return Status(ErrorCode::IoError, dir + ": cannot list (" + ec.message() + ")");
  SPHEREKIT_RETURN_IF_ERROR(u.write_map((fs::path(staging.path()) / map_name).string()));
  SPHEREKIT_RETURN_IF_ERROR(formats::write_file_atomic((fs::path(staging.path()) / formats::kCollectionManifest).string(),
                                                       formats::collection_manifest_text(manifest)));
  return staging.commit();
}

}  // namespace

void sort_members(formats::CollectionManifest& manifest) {
  std::stable_sort(manifest.members.begin(), manifest.members.end(),
                   [](const formats::CollectionMember& a, const formats::CollectionMember& b) { return a.name < b.name; });
}

Status check_member_maps_present(const formats::Collection& c, int skip) {
  const std::string manifest = (fs::path(c.dir) / formats::kCollectionManifest).string();
  for (size_t i = 0; i < c.manifest.members.size(); ++i) {
    if (static_cast<int>(i) == skip) continue;
    const formats::CollectionMember& m = c.manifest.members[i];
    const std::string path = (fs::path(c.dir) / m.map).string();
    std::error_code ec;
    if (!fs::is_regular_file(path, ec))
      return Status(ErrorCode::IoError, path + ": missing (the map of member '" + m.name + "' in " + manifest + ")");
  }
  return Status();
}

Result<formats::CollectionManifest> commit_member(const std::string& dir, const MemberUpdate& u) {
  SPHEREKIT_ASSIGN_OR_RETURN(formats::FolderLock lock, formats::FolderLock::acquire(dir));
  formats::recover_folder(dir);
  remove_stale_temp_files(dir);
  // The manifest as it is now: other adds may have landed while this map was computed.
  SPHEREKIT_ASSIGN_OR_RETURN(formats::Collection c, formats::read_collection(dir));
  const std::string manifest_path = (fs::path(dir) / formats::kCollectionManifest).string();
  if (!same_locations(c.manifest, u))
    return Status(ErrorCode::InvalidInput, manifest_path +
                                               ": the collection's feature locations changed while the map was "
                                               "computed (the folder was rewritten); run add again");
  formats::CollectionManifest man = c.manifest;
  const int existing = man.member_index(u.member.name);
  if (existing >= 0 && !u.replace)
    return Status(ErrorCode::InvalidArgument, dir + ": the collection already has a mesh named '" + u.member.name +
                                                  "' (use --name, or --replace to map it again)");
  if (existing >= 0) {
    man.members[static_cast<size_t>(existing)] = u.member;
    sort_members(man);
    SPHEREKIT_RETURN_IF_ERROR(replace_by_new_version(dir, u.member.map, man, u));
    return man;
  }
  man.members.push_back(u.member);
  sort_members(man);
  // The map first, then the manifest that names it: a reader never sees a member without
  // its map. If the manifest cannot be written, the new map is removed again.
  const std::string map_path = (fs::path(dir) / u.member.map).string();
  SPHEREKIT_RETURN_IF_ERROR(u.write_map(map_path));
  if (Status s = formats::write_file_atomic(manifest_path, formats::collection_manifest_text(man)); !s.ok()) {
    std::error_code ec;
    fs::remove(map_path, ec);
    return s;
  }
  return man;
}

}  // namespace spherekit::pipeline
