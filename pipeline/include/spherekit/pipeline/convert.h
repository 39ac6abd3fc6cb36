// The conversion pipeline, written once: a mesh and its sphere map -> octahedral geometry
// image (EXR), PNG previews, the remesh and its PSNR, Draco glTF levels of detail (with their
// PSNRs), and a Catmull-Clark cage with its displacement atlas. `convert` (one mesh),
// `convert --collection` (every member) and the main job (`run`) call convert_geometry().
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "spherekit/convert/displacement.h"
#include "spherekit/convert/gltf_draco.h"
#include "spherekit/convert/gltf_lods.h"
#include "spherekit/formats/collection.h"
#include "spherekit/geometry_image.h"
#include "spherekit/mesh.h"
#include "spherekit/metrics.h"
#include "spherekit/progress.h"
#include "spherekit/status.h"

namespace spherekit::pipeline {

using Json = nlohmann::ordered_json;

/// Texel positions of the image: a least-squares fit of the surface (the lower remesh error)
/// or each texel the surface point it samples.
enum class TexelPositions { Fit, Sampled };

/// "fit" / "sampled"; "scalar" / "vector".
const char* texel_positions_name(TexelPositions p);
const char* displacement_kind_name(convert::DisplacementKind k);

/// What a mesh converts into (the same for one mesh and for every member of a collection).
struct ConvertOptions {
  int size = 257;                                   ///< image side N = 2^k+1
  TexelPositions positions = TexelPositions::Fit;
  int psnr_samples = RemeshErrorOptions{}.samples;  ///< per direction; 0: no PSNR
  int lods = 0;                                     ///< glTF levels of detail (0: none)
  /// How the levels are made (gltf_lods.h). Original by default: a single mesh's levels are
  /// the mesh itself simplified (original_lods.h), at equal PSNR smaller than the adaptive
  /// levels on every mesh measured (README, issue 22); a collection's members take the adaptive
  /// levels (one connectivity for all members) under Original as under Adaptive.
  convert::LodMode lod_mode = convert::LodMode::Original;
  bool lod_normals = true;  ///< glTF levels carry NORMAL (GltfLodOptions::normals; single meshes)
  bool lod_texcoords = true;  ///< glTF levels carry TEXCOORD_0 (GltfLodOptions::texcoords)
  int lod_coarse_position_bits = 0;  ///< GltfLodOptions::coarse_position_bits (adaptive single meshes)
  /// GltfLodOptions::position_bits_rule: each level's bits by rate and distortion (default) or
  /// level 0's bits from the error budget for all.
  convert::PositionBitsRule lod_position_bits = convert::PositionBitsRule::RateDistortion;
  convert::QuantizationBudget budget;               ///< their Draco quantization
  int cage = 0;                                     ///< cage quads per cube-face edge (0: no cage)
  int cage_tile = 17;                               ///< displacement samples per quad edge
  convert::DisplacementKind displacement = convert::DisplacementKind::Scalar;
  int threads = 0;  ///< effort: worker threads of the parallel stages (0: all cores); same bytes for any
};

/// InvalidArgument naming the option (as its flag) when `o` is wrong whatever the input.
Status check_convert_options(const ConvertOptions& o);

/// Where convert_geometry() writes, and what the files record as their sources.
struct GeometryOutputs {
  std::string image;   ///< the EXR path
  std::string prefix;  ///< PREFIX_normals.png, PREFIX_lod0.glb, PREFIX_cage.obj, ...
  std::string remesh;  ///< also write the remesh here (empty: not written)
  std::string name;    ///< the glTF's mesh name
  std::string source_mesh, sphere_map;  ///< provenance of the image, cage and displacement
  std::string lods_sphere_map;          ///< provenance of the glTF files (default: sphere_map)
};

/// The cage and its displacement, as written.
struct CageAssets {
  std::string cage_path, displacement_path;
  int n = 0, tile = 0, control_points = 0, quads = 0, samples_in_holes = 0;
  convert::DisplacementKind kind = convert::DisplacementKind::Scalar;
  double fit_rms = 0, max_displacement = 0, ray_residual = 0;
  long long stored_floats = 0;
  RemeshError limit_error, displaced_error;  ///< of the bare limit surface and the displaced one
  bool measured = false;
  double seconds = 0, psnr_seconds = 0;
};

struct GeometryAssets {
  GeometryImage image;
  /// The image's triangle mesh: for one mesh its holes left open (the faces spanning them
  /// have no counterpart); for a collection member closed, so that every member shares one
  /// connectivity.
  TriMesh remesh;
  std::vector<std::string> previews;  ///< PREFIX_normals.png, PREFIX_positions.png
  bool measured = false;              ///< psnr_samples > 0
  RemeshError error;                  ///< the remesh against the mesh, hole faces left out
  std::optional<RemeshError> error_all_faces;  ///< one mesh with holes: every face of the closed image mesh
  convert::GltfLods lods;
  convert::GltfLodPaths lod_paths;
  std::vector<RemeshError> lod_errors;  ///< per level, when measured
  std::optional<CageAssets> cage;
  struct Times {
    double sample = 0, remesh = 0, write = 0, psnr = 0, gltf = 0, gltf_psnr = 0;
  } times;
};

/// Samples, writes and measures everything `options` asks for. `collection_member`: the mesh
/// is one of a consistent collection, whose members keep one connectivity (hole faces stay
/// in the remesh and the levels of detail; the PSNR leaves them out). Progress: the glTF and
/// cage stages; returning false cancels (Cancelled). Errors: the stages' and the writers'.
Result<GeometryAssets> convert_geometry(const TriMesh& mesh, const RowMat3d& S, const ConvertOptions& options,
                                        const GeometryOutputs& outputs, bool collection_member,
                                        const ProgressFn& progress = {});

// ---------------------------------------------------------------------------------------
// convert: one mesh

struct ConvertMeshJob {
  std::string mesh, sphere;  ///< the mesh and its sphere map (from `param`)
  std::string output;        ///< the EXR; the other files are named after it without its extension
  std::string remesh;        ///< also write the remesh here (empty: no)
  ConvertOptions options;
};

struct ConvertMeshResult {
  ConvertMeshJob job;
  long long vertices = 0, faces = 0;
  GeometryAssets assets;
  double read_seconds = 0, wall_seconds = 0;
};

/// Reads the mesh (refused unless param accepts it: require_param_accepts) and the map
/// (refused unless bijective by the exact predicate), then convert_geometry(). Nothing is
/// written when the input is refused. Errors name the file.
Result<ConvertMeshResult> convert_mesh(const ConvertMeshJob& job, const ProgressFn& progress = {});

/// The report of `convert --report` (paths as given, file sizes as on disk now).
Json to_json(const ConvertMeshResult& r);
/// A cage's report object (file names as recorded in `c`).
Json to_json(const CageAssets& c);
/// A level of detail's quantization for the reports (the level files carry none of it):
/// position bits, their largest error, the error they were chosen against and by what rule,
/// texture-coordinate bits, and normal bits when the level has normals.
Json lod_quantization_json(const convert::GltfLodLevel& level);

/// OUT.exr -> OUT (the glTF files are OUT_lod0.glb ... and OUT_lods.glb).
std::string output_prefix(const std::string& output);

// ---------------------------------------------------------------------------------------
// convert --collection: every member of a consistent collection

inline constexpr const char* kConvertReport = "convert_report.json";

struct ConvertCollectionJob {
  std::string collection;  ///< the collection folder
  std::string output;      ///< the asset folder, written all-or-nothing (marker convert_report.json)
  ConvertOptions options;
};

struct ConvertedMember {
  std::string name, source;
  long long vertices = 0, faces = 0;
  GeometryAssets assets;
  double seconds = 0;
};

struct ConvertCollectionResult {
  ConvertCollectionJob job;
  std::vector<ConvertedMember> members;
  /// The levels' common connectivity (LodMode Original and Adaptive): "template" (the template
  /// member's mesh laid on every member, convert/template_lods.h) or "remesh" (the common
  /// geometry-image remesh, adaptive_lods.h); empty without such levels.
  std::string lod_connectivity;
  std::string lod_connectivity_reason;  ///< why Original took the remesh's levels, else empty
  std::string lod_template;             ///< the template member (Original), else empty
  Json lod_template_folds;              ///< per member: folded faces of the laid template (Original)
  Json lod_choice;                      ///< Original: both candidates' worst member PSNR per level, when both were made
  Json report;  ///< convert_report.json as written
  double wall_seconds = 0;
};

/// Converts every member with the same options into `job.output` (NAME.exr, previews, LODs,
/// cage per member, collection_morph.glb, convert_report.json with per-feature texels). The
/// folder appears only when complete. `keep_going` is polled between members.
Result<ConvertCollectionResult> convert_collection(const ConvertCollectionJob& job, const ProgressFn& progress = {},
                                                   const formats::KeepGoingFn& keep_going = {});

}  // namespace spherekit::pipeline
