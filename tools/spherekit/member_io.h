// What the collection applications (`transfer`, `morph`, `pca`) share: loading members of a
// collection folder by name with their sphere maps and feature positions, and writing a set of
// output files or a whole output folder all-or-nothing.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "cli_common.h"
#include "collection.h"
#include "spherekit/sphere_map.h"

namespace spherekit::cli {

/// A member of a collection, loaded.
struct Member {
  int index = -1;        ///< in the manifest's "meshes"
  std::string name;      ///< the manifest's name (the mesh file's stem)
  std::string source;    ///< the mesh file
  TriMesh mesh;
  SphereMap map;
  /// #features by 3: positions of the feature vertices on the mesh (manifest order), or empty
  /// when the manifest does not list them.
  RowMat3d features;
};

/// The member `name_or_path` (a member name, or its mesh file): reads the mesh from the
/// manifest's source (or `name_or_path` when that is an existing file and the source is not)
/// and the sphere map from DIR. Errors name the file: InvalidInput (not a member), IoError,
/// ParseError, InvalidInput (map and mesh differ).
Result<Member> load_member(const CollectionInfo& c, const std::string& name_or_path);

/// Every member of the collection, in manifest order.
Result<std::vector<Member>> load_all_members(const CollectionInfo& c);

/// Files written together: either all of them end up in place or none does (already renamed
/// files are removed again when a later one fails). Each file is written atomically.
class OutputFiles {
 public:
  void add(std::string path, std::string bytes) { files_.emplace_back(std::move(path), std::move(bytes)); }
  /// Writes every file. Errors: the first write's IoError (naming the file).
  Status write_all() const;
  const std::vector<std::pair<std::string, std::string>>& files() const { return files_; }

 private:
  std::vector<std::pair<std::string, std::string>> files_;
};

/// Replaces the folder `dir` by one holding `files` (names relative to it): staged beside it
/// and renamed into place when complete. An existing `dir` is replaced only if it is empty or
/// holds `marker` (the report file a previous run of the same command wrote), so that an
/// unrelated folder is never deleted. Errors: IoError naming the folder.
Status write_output_folder(const std::string& dir, const std::string& marker, const OutputFiles& files);

/// IoError unless `dir` could become an output folder as above (parent exists; absent, empty
/// or holding `marker`). Checked before any work.
Status require_output_folder(const std::string& dir, const std::string& marker);

}  // namespace spherekit::cli
