// Levels of detail of a geometry image as Draco-compressed binary glTF: one .glb per level, and
// one .glb holding every level with MSFT_lod.
//
// Levels. Level k is a geometry image of (N-1)/2^k + 1 texels per side (257, 129, 65, 33, ...):
// the octahedral lattices nest, so each level is the remesh the image of that size defines
// (geometry_image_mesh), with the texture coordinates of the full image (gltf_mesh.h), so one
// texture or normal map made from the image serves every level. The levels are either given
// (lod_geometry_images: each level's positions fitted to the mesh at its own size, 3-5 dB
// better than the finest image subsampled) or the finest image subsampled.
//
// Holes. For a mesh with holes, drop_hole_faces leaves out the faces that span a hole
// (geometry_image_hole_faces of the level's image: what is left is a manifold) and the
// points only they use, so a viewer shows the holes. A collection keeps them: its members
// must share one connectivity.
//
// Per primitive: POSITION, NORMAL, TEXCOORD_0 in a KHR_draco_mesh_compression bitstream, no
// uncompressed fallback (the extension is required), accessors written from the decoded data
// (gltf_draco.h). All levels share one position grid (the bounding cube of every level's
// positions).
//
// The combined file (MSFT_lod README, KhronosGroup/glTF extensions/2.0/Vendor/MSFT_lod):
//   scene 0 -> node 0 "NAME_LOD0" (mesh 0) with
//              extensions.MSFT_lod.ids = [1, 2, ..., L-1]   (progressively coarser)
//              extras.MSFT_screencoverage = [c0, c1, ..., c(L-1)]
//   nodes 1..L-1 "NAME_LODk" (mesh k), referenced only by the ids
// so a loader without MSFT_lod shows level 0, the best one (ALGORITHM.md §7, gotcha 11).
// MSFT_screencoverage holds, per level, the smallest screen coverage at which it is used: level k
// from c(k-1) down to c(k). Coverage thresholds halve with the level, like the sample spacing,
// so the projected edge length stays within a factor of two; the last level is used down to
// `lowest_coverage` (0: never culled).
//
// Provenance and quantization are recorded in the combined file's extras: asset.extras.spherekit
// (toolkit and format version, source mesh, sphere map, layout, texture coordinate convention)
// and, per mesh, extras.spherekit (level, image size, quantization with its error budget). A
// level's own file is kept minimal, since its size is what a viewer downloads and what is
// compared against other tools: asset.extras.spherekit holds only "lod" and "texture_size"
// (the T of TEXCOORD_0's texel centres), POSITION bounds are the shortest decimals of the
// decoded floats, and no mesh extras (the level's quantization is in GltfLodLevel and the
// convert report).
#pragma once

#include <string>
#include <vector>

#include "spherekit/convert/gltf_draco.h"
#include "spherekit/convert/gltf_mesh.h"
#include "spherekit/convert/template_lods.h"
#include "spherekit/geometry_image.h"
#include "spherekit/progress.h"
#include "spherekit/status.h"

namespace spherekit::convert {

/// Where the asset came from (asset.extras.spherekit).
struct GltfProvenance {
  std::string source_mesh;  ///< path or name of the mesh
  std::string sphere_map;   ///< path or name of the sphere map
};

/// How the levels are made.
enum class LodMode {
  /// Level k = the geometry image of (N-1)/2^k + 1 texels (given or subsampled).
  Uniform,
  /// Level k = the finest image's remesh simplified by quadric edge collapses to a quarter of
  /// the previous level's vertices (adaptive_lods.h); the coarser images, if given, are unused.
  Adaptive,
  /// Single meshes: level k = the ORIGINAL mesh, cut along the octahedral fold and simplified
  /// by quadric edge collapses to V / 4^k vertices, TEXCOORD_0 = each vertex's octahedral
  /// domain point in the finest image (original_lods.h; build_original_gltf_lods).
  Original,
};

/// How each level's position bits are chosen.
enum class PositionBitsRule {
  /// QuantizationBudget: level 0's bits for every level (coarse_position_bits aside).
  ErrorBudget,
  /// position_bits.h: per level, the bits that give the smallest file at the level's error
  /// (its own error: reference_rms_error in squares with its RMS distance to the finest
  /// remesh). A level whose error is unknown (level 0 of uniform levels with no
  /// reference_rms_error) keeps the budget's bits.
  RateDistortion,
};

struct GltfLodOptions {
  // Shape-defining
  LodMode mode = LodMode::Uniform;
  /// Adaptive: vertices of level 0 as a fraction of the finest remesh's (adaptive_lods.h).
  double lod0_vertex_fraction = 0.25;
  int lod0_max_vertices = 0;  ///< Adaptive: cap on level 0's vertices (adaptive_lods.h; 0: none)
  int levels = 4;  ///< number of levels (>= 1); (N-1)/2^(levels-1) must be >= 2
  QuantizationBudget budget;  ///< how the quantization is chosen (gltf_draco.h)
  /// RMS surface error of level 0 against the original mesh (absolute units; remesh_error().rms
  /// of geometry_image_mesh(image)): the position bits' error budget. <= 0: unknown, the
  /// budget's minimum bits are used.
  double reference_rms_error = 0;
  double lod0_coverage = 0.5;   ///< MSFT_screencoverage of level 0 (coverage where level 1 takes over)
  double lowest_coverage = 0;   ///< MSFT_screencoverage of the last level (0: never culled)
  /// Leave out the faces spanning holes of the mesh (and the points only they use). Changes
  /// the connectivity from member to member of a collection, so collections keep them.
  bool drop_hole_faces = false;
  /// Write NORMAL. Without it a viewer computes the normals from the triangles (glTF 2.0
  /// §3.7.2.1: flat normals), as it does for gltfpack -cc and gltf-transform output of a mesh
  /// without normals; 10-bit octahedral normals are about a third of an adaptive level's bytes.
  bool normals = true;
  /// Write TEXCOORD_0 (the geometry image's domain: what the shared texture of a collection,
  /// the transfer and the viewer's grid use). Without it the copies of a vertex at the
  /// octahedral fold become one point (gltf_mesh_without_texcoords): geometry only, as the
  /// files of gltfpack and gltf-transform made from a mesh without texture coordinates.
  bool texcoords = true;
  /// Adaptive levels 1..L-1: position bits from the level's own error (RMS distance to level
  /// 0, sampled) with the budget's error fraction, floored at this many bits (0: off, every
  /// level has the shared bits). A coarse level's error is many times level 0's, so the bits
  /// level 0 needs are far below its error and only cost bytes.
  int coarse_position_bits = 0;
  PositionBitsRule position_bits_rule = PositionBitsRule::RateDistortion;
  int min_position_bits_rd = 6;  ///< RateDistortion: never fewer bits than this
  /// Original: texture-coordinate bits ceil(log2((T-1) / (2 err))), err this value: a grid
  /// step of about 2 err texels of the T x T geometry image, so a coordinate moves by about
  /// err texels at most (0.5 and T = 257: 8 bits, at most 0.502 texel).
  double texcoord_max_error_texels = 0.5;
  /// Original: level k's texture coordinates get k bits fewer than level 0's (at least 4): its
  /// edges are 2^k times as long and it is shown at most at 1/2^k of level 0's size (the screen
  /// coverages halve per level), so the grid step stays the same fraction of its triangles and
  /// the same distance on screen (half a texel of mip level k at T = 257 and 0.5 texel).
  /// false: every level has level 0's bits.
  bool coarse_texcoord_bits = true;
  std::string name = "mesh";    ///< node and mesh names: NAME_LOD0, NAME_LOD1, ...
  GltfProvenance provenance;
  // Effort
  int compression_level = 7;    ///< Draco compression level 0..10 (gltf_draco.h)
};

/// One level of detail.
struct GltfLodLevel {
  /// Texels per side of the level's geometry image (Adaptive: the finest image's, which the
  /// level's texture coordinates index).
  int image_size = 0;
  GltfMesh mesh;              ///< the level before Draco (point order of the source)
  DracoPrimitive primitive;   ///< the Draco bitstream and its decode
  /// The level's quantization: GltfLods::quantization, except for the position bits of
  /// coarser adaptive levels (GltfLodOptions::coarse_position_bits).
  QuantizationChoice quantization;
  std::string glb;            ///< the level alone as a .glb
};

struct GltfLods {
  std::vector<GltfLodLevel> levels;      ///< level 0 (finest) first
  std::string combined_glb;              ///< every level, MSFT_lod
  QuantizationChoice quantization;       ///< shared by all levels
  std::vector<double> screen_coverage;   ///< MSFT_screencoverage, one per level
};

/// Builds the levels of detail of `image` (in memory). Reports progress as stage "gltf" (level =
/// level index, fraction = levels done / levels) and stops with Cancelled when the callback
/// returns false. Errors: InvalidArgument (malformed image, levels < 1 or too many for the
/// image size, coverages not in [0, 1] or lod0_coverage < lowest_coverage), Internal (Draco or
/// tinygltf failed), Cancelled.
[[nodiscard]] Result<GltfLods> build_gltf_lods(const GeometryImage& image, const GltfLodOptions& options = {},
                                               const ProgressFn& progress = {});
/// The same with the level images given: `level_images[k]` has (N-1)/2^k + 1 texels per side,
/// N = level_images[0].size, one image per level (options.levels is ignored). Errors as above,
/// and InvalidArgument if a level has the wrong size.
[[nodiscard]] Result<GltfLods> build_gltf_lods(const std::vector<GeometryImage>& level_images,
                                               const GltfLodOptions& options = {}, const ProgressFn& progress = {});

/// Levels of detail of a single mesh by simplification of the mesh itself (LodMode::Original,
/// original_lods.h): `S` its sphere map, `texture_size` the finest geometry image's side, which
/// the texture coordinates index. Each level's position bits by rate and distortion against its
/// RMS distance to `mesh` (reference_rms_error is not used: level 0 is the mesh); texture
/// coordinate bits from texcoord_max_error_texels. options.mode is recorded as Original.
/// Errors: those of original_lod_meshes and build_gltf_lods.
[[nodiscard]] Result<GltfLods> build_original_gltf_lods(const TriMesh& mesh, const RowMat3d& S, int texture_size,
                                                        const GltfLodOptions& options = {},
                                                        const ProgressFn& progress = {});

/// The levels of detail of a consistent collection's members (one geometry image each, one
/// size), every member's levels with the same connectivity: Adaptive simplifies all members at
/// once in R^3n (adaptive_lods.h), so level k has the same faces, points and texture
/// coordinates in every member (GltfLodLevel::mesh; Draco's decode order is then the same
/// too). `options[m]` are member m's (names, provenance, error budget; the mode, levels and
/// fraction of options[0] apply to all). Uniform: build_gltf_lods per member (subsampled
/// images). Hole faces are kept (drop_hole_faces is ignored). Errors: those of
/// build_gltf_lods and adaptive_lod_meshes; InvalidArgument (options not one per member).
[[nodiscard]] Result<std::vector<GltfLods>> build_consistent_gltf_lods(const std::vector<GeometryImage>& members,
                                                                      const std::vector<GltfLodOptions>& options,
                                                                      const ProgressFn& progress = {});

/// The levels of detail of a consistent collection on its template member's own mesh laid on
/// every member (template_lods.h; the collections' LodMode::Original): level k has one
/// connectivity in every member (GltfLodLevel::mesh), the template's levels are its
/// original-mesh levels, the other members' are the template's triangulation on their
/// surfaces. `members` as given to lay_template; `options[m]` as build_consistent_gltf_lods
/// (levels and lod0_max_vertices of options[0] apply to all); each member's level errors are
/// its distance to members[m].mesh. Errors: those of template_lod_meshes and build_gltf_lods;
/// InvalidArgument (options or layout not one per member).
[[nodiscard]] Result<std::vector<GltfLods>> build_template_gltf_lods(const TemplateLayout& layout,
                                                                    const std::vector<TemplateLodMember>& members,
                                                                    int texture_size,
                                                                    const std::vector<GltfLodOptions>& options,
                                                                    const ProgressFn& progress = {});

/// The images of `levels` levels of detail of `mesh` through its sphere map `S`: level 0 is
/// `finest` (moved in), level k is sampled at (N-1)/2^k + 1 with `options` (so with
/// options.fit_positions each level's positions are fitted at its own size; hole flags, normals
/// and face ids equal the finest image's at the shared texels, the domain points being
/// bit-identical). Errors: those of sample_geometry_image, InvalidArgument (levels do not fit).
[[nodiscard]] Result<std::vector<GeometryImage>> lod_geometry_images(const TriMesh& mesh, const RowMat3d& S,
                                                                     GeometryImage finest, int levels,
                                                                     const GeometryImageOptions& options);

/// The file names write_gltf_lods uses: PREFIX_lod0.glb ... PREFIX_lod{L-1}.glb, PREFIX_lods.glb.
struct GltfLodPaths {
  std::vector<std::string> levels;
  std::string combined;
};
GltfLodPaths gltf_lod_paths(const std::string& prefix, int levels);

/// Writes every level and the combined file, each atomically (formats::write_file_atomic), to
/// gltf_lod_paths(prefix, lods.levels.size()). Errors: IoError (the first failing file; files
/// already written stay).
[[nodiscard]] Result<GltfLodPaths> write_gltf_lods(const std::string& prefix, const GltfLods& lods);

}  // namespace spherekit::convert
