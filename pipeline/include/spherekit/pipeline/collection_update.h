// Growing a collection folder safely (issue 23): the manifest's read-modify-write under the
// folder's exclusive lock (formats/folder_lock.h), so that concurrent `add`s (one machine, or
// job-array tasks on a shared file system) all land; members kept sorted by name, so that the
// manifest's bytes do not depend on the order in which the adds finished.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "spherekit/formats/collection.h"
#include "spherekit/status.h"

namespace spherekit::pipeline {

/// One member to put into a collection.
struct MemberUpdate {
  formats::CollectionMember member;  ///< its manifest entry ("name", "map", ...)
  /// Writes the member's map at the given path (atomically). Called under the lock.
  std::function<Status(const std::string& path)> write_map;
  bool replace = false;  ///< an existing member of that name is replaced (else refused)
  /// The F the map was computed against: refused if the folder now holds another collection
  /// (rewritten by `consistent` while the map was computed).
  std::vector<std::string> feature_names;
  std::vector<Eigen::Vector3d> locations;
};

/// Under the lock of `dir`: re-reads the manifest, checks F, writes the map and the manifest
/// with the member merged in (sorted by name), and returns the manifest written. A new
/// member's map is written first and the manifest atomically after it, so that a crash leaves
/// at most an unlisted map (the old collection); a replaced member is written as a new version
/// of the whole folder (hard links to the unchanged files, swapped in atomically,
/// formats/folder_swap.h). Also removes the temporary files of writers killed in the folder.
/// Errors: InvalidArgument (name taken, no replace), InvalidInput (F changed),
/// read_collection()'s, IoError.
Result<formats::CollectionManifest> commit_member(const std::string& dir, const MemberUpdate& update);

/// The manifest's members sorted by name (its order on disk).
void sort_members(formats::CollectionManifest& manifest);

/// Every listed map exists (a stat per member: no map is read, so that growing a collection of
/// n members costs O(1) reads per `add`, not O(n)). Member `skip` is left out. Errors: IoError
/// naming the map.
Status check_member_maps_present(const formats::Collection& c, int skip = -1);

}  // namespace spherekit::pipeline
