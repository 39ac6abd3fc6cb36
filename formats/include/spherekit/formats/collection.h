// The collection folder `spherekit consistent` writes and `add`, `correspond`, `convert
// --collection` and the applications read (format "spherekit-collection", version 1):
//   DIR/collection.json         manifest: features F (and F'), members, options, results, times
//   DIR/features.txt            `name x y z`: the final feature locations F (a copy for other tools)
//   DIR/<name>.sphere.obj       one sphere map per member (vertex order of the member's mesh)
//
// The manifest is typed below. What the format does not interpret (each member's recorded
// result, the options, the steps' measures and times, keys written by later versions) is kept
// as JSON and written back unchanged, in its order: reading and writing a manifest gives the
// same bytes.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "spherekit/formats/staged_folder.h"
#include "spherekit/mesh.h"
#include "spherekit/sphere_map.h"
#include "spherekit/status.h"

namespace spherekit::formats {

inline constexpr const char* kCollectionManifest = "collection.json";
inline constexpr const char* kCollectionFeatures = "features.txt";
inline constexpr const char* kCollectionFormat = "spherekit-collection";
inline constexpr int kCollectionFormatVersion = 1;

/// Reports and manifests keep the order in which keys are written.
using OrderedJson = nlohmann::ordered_json;

struct CollectionFeature {
  std::string name;
  Eigen::Vector3d location = Eigen::Vector3d::Zero();  ///< F: a unit vector
  std::optional<Eigen::Vector3d> initial_location;     ///< F' (from the reference), if recorded
  OrderedJson extra = OrderedJson::object();           ///< other keys of the entry, in file order
};

struct CollectionMember {
  std::string name;  ///< unique; the mesh file's stem unless `add --name`
  std::string map;   ///< the sphere map's file name in the folder (a plain file name)
  std::optional<std::string> source;         ///< the mesh file (absolute), or "builtin:NAME"
  std::optional<std::string> features_file;  ///< the landmark file, or "builtin"
  std::optional<long long> vertices, faces;  ///< of the mesh that was mapped (vertices >= 4)
  /// The feature vertices in the manifest's feature order (-1: an entry that is not a vertex
  /// index; load_collection_member() refuses it).
  std::optional<std::vector<long long>> feature_vertices;
  std::optional<bool> added;  ///< mapped by `add` (true) or by `consistent` (false)
  OrderedJson result;         ///< the map's measures as recorded (null: none)
  OrderedJson extra = OrderedJson::object();  ///< other keys of the entry, in file order
};

struct CollectionManifest {
  int format_version = kCollectionFormatVersion;
  std::optional<std::string> library_version, method, reference;
  std::vector<CollectionFeature> features;
  std::vector<CollectionMember> members;
  OrderedJson options;  ///< the options the maps were made with (null: not recorded)
  OrderedJson extra = OrderedJson::object();  ///< other top-level keys (steps, times, ...), in file order

  /// Index of the member named `name`, or -1.
  int member_index(const std::string& name) const;
  std::vector<std::string> feature_names() const;
  std::vector<Eigen::Vector3d> locations() const;  ///< F, in feature order
};

/// A collection folder as read: where it is and its validated manifest.
struct Collection {
  std::string dir;
  CollectionManifest manifest;
};

/// Parses and validates a manifest (`file` names it in errors). Errors: ParseError (not JSON,
/// empty), InvalidInput (wrong format or version, missing, duplicate or inconsistent fields,
/// non-unit locations, map names that are not plain file names).
Result<CollectionManifest> parse_collection_manifest(const std::string& text, const std::string& file);

/// The manifest as JSON, and as the text of collection.json (2-space indent, trailing newline).
OrderedJson collection_manifest_json(const CollectionManifest& manifest);
std::string collection_manifest_text(const CollectionManifest& manifest);

/// Reads and validates DIR/collection.json, and DIR/features.txt against it. Errors (naming
/// the file): IoError (missing), those of parse_collection_manifest(), InvalidInput
/// (features.txt not holding exactly the manifest's features).
Result<Collection> read_collection(const std::string& dir);

/// Every member's map exists in the folder, is a readable OBJ and has the vertex count the
/// manifest records (member `skip` excepted: the one `add --replace` maps again). Commands
/// that grow a collection check this first, so that they never extend a broken one. Errors
/// (naming the map): IoError (missing or unreadable), ParseError, InvalidInput (wrong count).
Status check_member_maps(const Collection& c, int skip = -1);

/// Index of the member whose source file is `mesh_path` (the same absolute path), else the
/// first whose name is its file stem, or -1.
int find_member(const Collection& c, const std::string& mesh_path);

/// A member of a collection, loaded.
struct LoadedMember {
  int index = -1;      ///< in the manifest's members
  std::string name;    ///< the manifest's name
  std::string source;  ///< the mesh file read
  TriMesh mesh;
  SphereMap map;
  /// #features by 3: positions of the feature vertices on the mesh (manifest order), or empty
  /// when the manifest does not list them.
  RowMat3d features;
};

/// Member `index`: reads the mesh from the manifest's source (or `fallback_path` when that is
/// an existing file and the source is not) and the sphere map from DIR. Errors name the file:
/// InvalidInput (no source, feature vertex out of range), IoError, ParseError, InvalidInput
/// (map and mesh differ).
Result<LoadedMember> load_collection_member(const Collection& c, int index, const std::string& fallback_path = {});

/// The member `name_or_path` (a member name, or its mesh file; see find_member()). Errors:
/// InvalidInput naming it and listing the members when it is not one, else as above.
Result<LoadedMember> load_collection_member(const Collection& c, const std::string& name_or_path);

/// Every member of the collection, in manifest order.
Result<std::vector<LoadedMember>> load_collection_members(const Collection& c);

/// `name x y z` lines with 17 significant digits (DIR/features.txt).
std::string sphere_points_text(const std::vector<std::string>& names, const std::vector<Eigen::Vector3d>& points);

}  // namespace spherekit::formats
