// The applications over a consistent collection (paper §5): attribute transfer, a morph
// sequence between two members, and PCA with the compression experiment. `transfer`,
// `morph`, `pca` and the main job call these.
#pragma once

#include <string>

#include "spherekit/formats/staged_folder.h"
#include "spherekit/pipeline/json.h"
#include "spherekit/progress.h"
#include "spherekit/status.h"

namespace spherekit::pipeline {

enum class TransferWhat { Colors, Normals, UV, Texture };
/// "colors", "normals", "uv", "texture".
const char* transfer_what_name(TransferWhat what);

struct TransferJob {
  std::string collection;  ///< the collection folder
  std::string from, to;    ///< members A and B (name or mesh file)
  TransferWhat what = TransferWhat::Colors;
  std::string output;      ///< B with the attribute (.obj; .ply also for colors)
  std::string attributes;  ///< A's attribute source (default: A's mesh file; A's vertices and faces)
  std::string texture;     ///< A's texture image (texture; default: from A's material library)
  int size = 129;          ///< normals: normal map and remesh size, 2^k+1
  bool align = true;       ///< normals: rotate A's normals into B's orientation (features)
  int threads = 0;         ///< effort: remeshing threads (0: all cores); same output for any
};

struct TransferResult {
  std::string from, to;  ///< the members' names
  long long vertices = 0;  ///< of the mesh written
  int vertices_in_holes = 0;
  Json report;  ///< `transfer --report`
};

/// Transfers A's attribute to B through the common sphere and writes the output with its
/// sibling files (material, texture or normal map) together or not at all.
Result<TransferResult> transfer_attributes(const TransferJob& job);

inline constexpr const char* kMorphReport = "morph.json";

struct MorphJob {
  std::string collection, a, b;  ///< the collection folder, the first and last member
  std::string output;            ///< the folder, written all-or-nothing (marker morph.json)
  int frames = 9;                ///< including both ends (>= 2)
  int size = 65;                 ///< geometry-image size of the remeshes, 2^k+1
  bool align = true;             ///< align with the features (false: linear blend)
  bool rigid = false;            ///< align without scaling
  double seconds = 3;            ///< length of the glTF animation
  int threads = 0;               ///< effort: remeshing threads (0: all cores); same output for any
};

struct MorphResult {
  std::string a, b;
  long long vertices = 0;
  bool aligned = false;
  double scale = 1, rotation_deg = 0;
  Json report;  ///< morph.json
};

/// A morph sequence A -> B on their consistent remeshes: morph.glb (morph targets, animated),
/// frame_NNN.obj, morph.json. `progress` covers the remeshing; false cancels.
Result<MorphResult> morph_members(const MorphJob& job, const ProgressFn& progress = {},
                                  const formats::KeepGoingFn& keep_going = {});

inline constexpr const char* kPcaReport = "pca.json";

struct PcaJob {
  std::string collection, output;  ///< the folder is written all-or-nothing (marker pca.json)
  int size = 65;                   ///< geometry-image size of the remeshes, 2^k+1
  bool compression = true;         ///< run the compression experiment (PCA against Draco)
  int threads = 0;                 ///< effort: remeshing threads (0: all cores); same output for any
};

struct PcaResult {
  Json report;  ///< pca.json: components, errors, compression, files
};

/// Mean shape, principal components (OBJ, glTF morph targets), reconstruction errors (CSV,
/// plot) and the compression experiment of every member's consistent remesh.
Result<PcaResult> shape_pca(const PcaJob& job, const ProgressFn& progress = {},
                            const formats::KeepGoingFn& keep_going = {});

}  // namespace spherekit::pipeline
