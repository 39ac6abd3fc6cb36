// The collection folder `spherekit consistent` writes and `add` / `correspond` read:
//   DIR/collection.json         manifest: meshes, feature names, F, F', options, versions, times
//   DIR/features.txt            `name x y z`: the final feature locations F
//   DIR/<stem>.sphere.obj       one sphere map per mesh (vertex order of the mesh file)
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "cli_common.h"

namespace spherekit::cli {

inline constexpr const char* kCollectionManifest = "collection.json";
inline constexpr const char* kCollectionFeatures = "features.txt";
inline constexpr const char* kCollectionFormat = "spherekit-collection";
inline constexpr int kCollectionFormatVersion = 1;

/// What the commands need from a collection folder (the manifest itself is kept too, to be
/// extended by `add`).
struct CollectionInfo {
  std::string dir;
  Json manifest;
  std::vector<std::string> feature_names;
  std::vector<Eigen::Vector3d> locations;  ///< F, one per feature name
};

/// Reads and validates DIR/collection.json, and DIR/features.txt against it. Errors (naming
/// the file): IoError (missing), ParseError, InvalidInput (wrong format or version, missing,
/// duplicate or inconsistent fields, non-unit locations, map names that are not plain file
/// names, features.txt not holding exactly the manifest's features).
Result<CollectionInfo> read_collection(const std::string& dir);

/// Every member's map exists in the folder, is a readable OBJ and has the vertex count the
/// manifest records (member `skip` excepted: the one `add --replace` maps again). Commands
/// that grow a collection check this first, so that they never extend a broken one. Errors
/// (naming the map): IoError (missing or unreadable), ParseError, InvalidInput (wrong count).
Status check_member_maps(const CollectionInfo& c, int skip = -1);

/// Index of the member whose map stem or source file matches `mesh_path` (its stem, or the
/// same absolute path), or -1.
int find_member(const CollectionInfo& c, const std::string& mesh_path);

/// Creates the folder `dir` with the files `write_into(staging)` writes into an empty
/// staging folder beside it; the staging folder is renamed into place only once every file
/// is written, replacing an existing collection folder (or an empty folder). On failure the
/// staging folder is removed and `dir` is untouched. A non-empty folder that is not a
/// collection is never replaced. SIGINT/SIGTERM during write_into only set the cancel flag
/// (write_into may poll cancel_requested() between files); then the staging folder is removed
/// and Cancelled returned. Errors: IoError, Cancelled, or write_into's.
Status write_collection_folder(const std::string& dir, const std::function<Status(const std::string&)>& write_into);

/// IoError unless `dir` can become a collection folder (absent, empty, or a collection), and
/// its parent exists. Checked before any work.
Status require_collection_target(const std::string& dir);

/// The same two for any command that writes a whole folder whose files are produced by
/// writers that take paths (e.g. `convert --collection`): `marker` is the file identifying a
/// folder the command wrote before (and may replace).
Status require_staged_folder_target(const std::string& dir, const char* marker);
Status write_staged_folder(const std::string& dir, const char* marker,
                           const std::function<Status(const std::string&)>& write_into);

/// `name x y z` lines with 17 significant digits.
std::string sphere_points_text(const std::vector<std::string>& names, const std::vector<Eigen::Vector3d>& points);

}  // namespace spherekit::cli
