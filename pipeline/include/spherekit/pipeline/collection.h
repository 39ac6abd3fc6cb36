// Making and growing a consistent collection folder (paper §3 and §5): `consistent` calls
// make_collection(), `add` add_to_collection(); the main job makes one of its inputs.
#pragma once

#include <string>
#include <vector>

#include "spherekit/consistent_param.h"
#include "spherekit/formats/collection.h"
#include "spherekit/mesh.h"
#include "spherekit/progress.h"
#include "spherekit/status.h"

namespace spherekit::pipeline {

using Json = nlohmann::ordered_json;

struct MakeCollectionJob {
  std::vector<std::string> meshes;    ///< genus 0, holes allowed; empty: the built-in samples
  std::vector<std::string> features;  ///< one landmark file per mesh, or none (NAME.lm.txt beside each)
  std::string output;                 ///< the collection folder, written all-or-nothing
  std::string reference;              ///< member giving F' (file stem or index); empty: the first
  /// The consistent stage's options; `reference` is resolved from the field above.
  ConsistentParamOptions options;
};

/// A member as the job read it.
struct CollectionInput {
  std::string name, source, features_file;
  TriMesh mesh;
  std::vector<int> feature_vertices;  ///< in the order of the collection's feature names
};

struct MakeCollectionResult {
  std::vector<CollectionInput> members;
  std::vector<std::string> feature_names;
  int reference = 0;
  ConsistentParamResult maps;
  formats::CollectionManifest manifest;  ///< as written to the folder
  /// The step-6 failure (member name: reason) when the collection kept the step-2 maps.
  std::string refinement_warning;
  /// Given landmarks that are most likely on another feature (suspect_landmarks), one line each.
  std::vector<std::string> landmark_warnings;
  double wall_seconds = 0;
};

/// Reads the meshes (each must be one param accepts) and their landmark files, maps them
/// consistently and writes the folder (manifest, features.txt, one sphere map per member).
/// Errors name the file: the mesh that failed, by its path (not "mesh i"); a map that is not
/// a bijection with every feature on its location is SolverFailed/Internal. `keep_going` is
/// polled while the folder is written.
Result<MakeCollectionResult> make_collection(const MakeCollectionJob& job, const ProgressFn& progress = {},
                                             const formats::KeepGoingFn& keep_going = {});

struct AddToCollectionJob {
  std::string dir;       ///< the collection folder
  std::string mesh;      ///< the mesh to add
  std::string features;  ///< its landmark file (empty: NAME.lm.txt beside it)
  std::string name;      ///< member name (empty: the mesh's file stem)
  bool replace = false;  ///< map again if the collection has a member of that name
  /// A sphere map computed elsewhere to register instead of computing one (e.g. `param
  /// --features F.lm.txt --targets DIR/features.txt` in a job): verified to have the mesh's
  /// vertices and faces, 0 flipped faces by the exact predicate and every feature within
  /// 1e-9 rad of its location; its bytes are copied. Empty: compute the map.
  std::string map;
  /// The constrained stage's options. The collection's recorded seed is used unless
  /// `seed_given` (the caller chose one).
  ConstrainedParamOptions options;
  bool seed_given = false;
  /// ConsistentParamOptions::efficiency_retry for the new map (its unconstrained map is then
  /// made too); the collection's recorded value unless `efficiency_retry_given`.
  double efficiency_retry = 0.8;
  bool efficiency_retry_given = false;
  /// Refine the new map's correspondence against the collection's reference member
  /// (refine_correspondence.h) when the collection was made with the refinement (its
  /// options say so, with the refinement's settings); false: never. Registered maps (`map`)
  /// are taken as given.
  bool refine_correspondence = true;
};

struct AddToCollectionResult {
  std::string name, map_path;
  long long vertices = 0;
  std::size_t features = 0;
  ConstrainedParamResult map;  ///< registered: the map and its measures only (no network, no times)
  bool registered = false;
  formats::CollectionManifest manifest;  ///< as written
  /// Its landmarks most likely on another feature, judged against the collection's reference
  /// member (suspect_landmarks; nothing when that member's mesh cannot be read), one line each.
  std::vector<std::string> landmark_warnings;
  double wall_seconds = 0;
};

/// Maps the mesh with its features exactly on the collection's locations F (or registers
/// `map`), then, under the folder's lock, re-reads the manifest, writes DIR/<name>.sphere.obj
/// and the manifest naming it, members sorted by name (commit_member(), collection_update.h:
/// concurrent adds all land). Reads only the manifest and F: the other members' maps are only
/// checked to exist (check_member_maps_present).
Result<AddToCollectionResult> add_to_collection(const AddToCollectionJob& job, const ProgressFn& progress = {});

/// A member's entry "result" in the manifest: the measures of its map (no times: see below).
Json map_entry_json(const ConstrainedParamResult& r);
/// A map's times (for reports; the manifest holds none).
Json map_times_json(const ConstrainedParamResult& r);
/// The six steps' times and each member's map times (for `consistent --report`).
Json consistent_times_json(const MakeCollectionResult& out);

}  // namespace spherekit::pipeline
