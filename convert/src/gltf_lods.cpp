// Levels of detail of a geometry image as Draco glTF, per level and combined with MSFT_lod (see
// gltf_lods.h).
//
// References: MSFT_lod README (KhronosGroup/glTF, extensions/2.0/Vendor/MSFT_lod: "ids" on the
// highest level, MSFT_screencoverage in extras); KHR_draco_mesh_compression README;
// ALGORITHM.md §5.1-5.2 and §7 gotchas 9 and 11.
#include "spherekit/convert/gltf_lods.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "gltf_document.h"
#include "spherekit/convert/position_bits.h"
#include "spherekit/convert/adaptive_lods.h"
#include "spherekit/convert/original_lods.h"
#include "spherekit/formats/atomic_file.h"

namespace spherekit::convert {
namespace {

// mesh.extras.spherekit of one level.
tinygltf::Value level_extras(int level, int image_size, int texture_size, const QuantizationChoice& q, LodMode mode,
                             bool has_normals) {
  tinygltf::Value::Object o;
  o["lod"] = detail::json_int(level);
  o["lod_mode"] = detail::json_string(mode == LodMode::Adaptive ? "adaptive" : mode == LodMode::Original ? "original" : "uniform");
  o["geometry_image_size"] = detail::json_int(image_size);
  o["texture_size"] = detail::json_int(texture_size);
  o["quantization"] = detail::quantization_json(q, has_normals, true);
  tinygltf::Value::Object extras;
  extras["spherekit"] = detail::json_object(std::move(o));
  return detail::json_object(std::move(extras));
}

// asset.extras of a level's own file: only what reading TEXCOORD_0 needs (the level and the
// texture's side). The file is compared by size against other tools' files, and its JSON was
// a third of a coarse level's bytes; provenance and quantization are in the combined file
// (level_extras, asset_extras) and in the convert report. texture_size 0: the level has no
// TEXCOORD_0 (GltfLodOptions::texcoords), and the key is left out.
tinygltf::Value level_file_extras(int level, int texture_size) {
  tinygltf::Value::Object o;
  o["lod"] = detail::json_int(level);
  if (texture_size > 0) o["texture_size"] = detail::json_int(texture_size);
  tinygltf::Value::Object extras;
  extras["spherekit"] = detail::json_object(std::move(o));
  return detail::json_object(std::move(extras));
}

tinygltf::Value asset_extras(const GltfLodOptions& options, int texture_size, int levels) {
  tinygltf::Value::Object o;
  o["source_mesh"] = detail::json_string(options.provenance.source_mesh);
  o["sphere_map"] = detail::json_string(options.provenance.sphere_map);
  o["layout"] = detail::json_string("octahedral");
  o["geometry_image_size"] = detail::json_int(texture_size);
  o["levels"] = detail::json_int(levels);
  // The convention in brief (README, "glTF levels of detail"): each file carries it, but a
  // level's JSON is part of its size, which is compared against other tools' files.
  o["texcoord"] = detail::json_string("texel centre ((j+0.5)/T, (i+0.5)/T), T = geometry_image_size");
  return detail::provenance_json(std::move(o));
}

std::string level_name(const std::string& name, int level) { return name + "_LOD" + std::to_string(level); }

}  // namespace

GltfLodPaths gltf_lod_paths(const std::string& prefix, int levels) {
  GltfLodPaths paths;
  for (int k = 0; k < levels; ++k) paths.levels.push_back(prefix + "_lod" + std::to_string(k) + ".glb");
  paths.combined = prefix + "_lods.glb";
  return paths;
}

namespace {

Status check_lod_options(int size, int levels, const GltfLodOptions& options) {
  if (!is_geometry_image_size(size)) return Status(ErrorCode::InvalidArgument, "malformed geometry image");
  if (levels < 1 || levels > 30 || ((size - 1) >> (levels - 1)) < 2)
    return Status(ErrorCode::InvalidArgument, std::to_string(levels) + " levels of detail do not fit a " +
                                                  std::to_string(size) + " x " + std::to_string(size) +
                                                  " geometry image (the coarsest level needs >= 3 x 3 texels)");
  if (!(options.lod0_coverage >= 0 && options.lod0_coverage <= 1) ||
      !(options.lowest_coverage >= 0 && options.lowest_coverage <= options.lod0_coverage))
    return Status(ErrorCode::InvalidArgument, "screen coverages must satisfy 0 <= lowest_coverage <= lod0_coverage <= 1");
  return Status();
}

int level_size(int size, int level) { return (size - 1) / (1 << level) + 1; }

}  // namespace

Result<std::vector<GeometryImage>> lod_geometry_images(const TriMesh& mesh, const RowMat3d& S, GeometryImage finest,
                                                       int levels, const GeometryImageOptions& options) {
  SPHEREKIT_RETURN_IF_ERROR(check_lod_options(finest.size, levels, GltfLodOptions{}));
  std::vector<GeometryImage> out;
  out.reserve(static_cast<std::size_t>(levels));
  const int n = finest.size;
  out.push_back(std::move(finest));
  for (int k = 1; k < levels; ++k) {
    SPHEREKIT_ASSIGN_OR_RETURN(GeometryImage level, sample_geometry_image(mesh, S, level_size(n, k), options));
    out.push_back(std::move(level));
  }
  return out;
}

namespace {

// The levels of `adaptive_lod_meshes` for one member, holes dropped if asked.
std::vector<GltfMesh> adaptive_member_levels(std::vector<std::vector<GltfMesh>>& all, std::size_t member,
                                             const GeometryImage& finest, bool drop_hole_faces) {
  std::vector<GltfMesh> meshes;
  for (auto& level : all) {
    GltfMesh mesh = std::move(level[member]);
    // The rule of geometry_image_hole_faces on the level's corners (their texels in the finest
    // image): a face with two or three hole corners spans a hole.
    if (drop_hole_faces) mesh = gltf_mesh_without_faces(mesh, gltf_mesh_hole_faces(mesh, finest));
    meshes.push_back(std::move(mesh));
  }
  return meshes;
}

// `finest`: the finest remesh the levels were simplified from (adaptive); nullptr: level 0 is it.
Result<GltfLods> build_from_meshes(std::vector<GltfMesh> meshes, const std::vector<int>& sizes, int n,
                                   const GltfLodOptions& options, const ProgressFn& progress,
                                   const TriMesh* finest = nullptr);

}  // namespace

Result<GltfLods> build_gltf_lods(const GeometryImage& image, const GltfLodOptions& options,
                                 const ProgressFn& progress) {
  SPHEREKIT_RETURN_IF_ERROR(check_lod_options(image.size, options.levels, options));
  if (options.mode == LodMode::Adaptive) {
    AdaptiveLodOptions a;
    a.levels = options.levels;
    a.lod0_vertex_fraction = options.lod0_vertex_fraction;
    a.lod0_max_vertices = options.lod0_max_vertices;
    a.drop_hole_faces = options.drop_hole_faces;  // exactly, by the simplifier's rim constraint
    SPHEREKIT_ASSIGN_OR_RETURN(auto all, adaptive_lod_meshes({image}, a, progress));
    // The surface the levels approximate: with the holes open when the levels leave them out
    // (else the hole faces' distance to the level would count as its error).
    const TriMesh finest = options.drop_hole_faces ? geometry_image_open_mesh(image) : geometry_image_mesh(image);
    return build_from_meshes(adaptive_member_levels(all, 0, image, false),
                             std::vector<int>(static_cast<std::size_t>(options.levels), image.size), image.size,
                             options, progress, &finest);
  }
  std::vector<GeometryImage> levels{image};
  for (int k = 1; k < options.levels; ++k) {
    SPHEREKIT_ASSIGN_OR_RETURN(GeometryImage sub, subsample_geometry_image(image, level_size(image.size, k)));
    levels.push_back(std::move(sub));
  }
  return build_gltf_lods(levels, options, progress);
}

namespace {

// The simplifier's options of original-mesh levels (single meshes and laid templates), checked.
Result<OriginalLodOptions> original_options(const GltfLodOptions& options, int texture_size) {
  SPHEREKIT_RETURN_IF_ERROR(check_lod_options(texture_size, 1, options));
  if (!(options.texcoord_max_error_texels > 0))
    return Status(ErrorCode::InvalidArgument, "texture-coordinate error must be > 0 texels");
  OriginalLodOptions a;
  a.levels = options.levels;
  a.texture_size = texture_size;
  a.lod0_max_vertices = options.lod0_max_vertices;
  return a;
}

}  // namespace

Result<GltfLods> build_original_gltf_lods(const TriMesh& mesh, const RowMat3d& S, int texture_size,
                                          const GltfLodOptions& options, const ProgressFn& progress) {
  SPHEREKIT_ASSIGN_OR_RETURN(const OriginalLodOptions a, original_options(options, texture_size));
  SPHEREKIT_ASSIGN_OR_RETURN(std::vector<GltfMesh> meshes, original_lod_meshes(mesh, S, a, progress));
  GltfLodOptions o = options;
  o.mode = LodMode::Original;
  o.reference_rms_error = 0;  // level 0 is the mesh itself; each level's error is its distance to it
  return build_from_meshes(std::move(meshes), std::vector<int>(static_cast<std::size_t>(options.levels), texture_size),
                           texture_size, o, progress, &mesh);
}

Result<std::vector<GltfLods>> build_template_gltf_lods(const TemplateLayout& layout,
                                                       const std::vector<TemplateLodMember>& members, int texture_size,
                                                       const std::vector<GltfLodOptions>& options,
                                                       const ProgressFn& progress) {
  if (members.empty() || options.size() != members.size() ||
      layout.positions.cols() != 3 * static_cast<Eigen::Index>(members.size()))
    return Status(ErrorCode::InvalidArgument, "template levels of detail need one option set and layout per member");
  for (const TemplateLodMember& m : members)
    if (!m.mesh) return Status(ErrorCode::InvalidArgument, "template levels of detail: a member has no mesh");
  const GltfLodOptions& first = options[0];
  SPHEREKIT_ASSIGN_OR_RETURN(const OriginalLodOptions a, original_options(first, texture_size));
  SPHEREKIT_ASSIGN_OR_RETURN(auto all, template_lod_meshes(layout, a, progress));
  std::vector<GltfLods> out;
  for (std::size_t m = 0; m < members.size(); ++m) {
    std::vector<GltfMesh> meshes;
    for (auto& level : all) meshes.push_back(std::move(level[m]));
    GltfLodOptions o = options[m];
    o.mode = LodMode::Original;
    o.levels = first.levels;
    o.reference_rms_error = 0;  // each level's error is its distance to the member's own mesh
    SPHEREKIT_ASSIGN_OR_RETURN(GltfLods lods,
                               build_from_meshes(std::move(meshes), std::vector<int>(static_cast<std::size_t>(a.levels), texture_size),
                                                 texture_size, o, progress, members[m].mesh));
    out.push_back(std::move(lods));
  }
  return out;
}

Result<GltfLods> build_gltf_lods(const std::vector<GeometryImage>& level_images, const GltfLodOptions& options,
                                 const ProgressFn& progress) {
  if (level_images.empty()) return Status(ErrorCode::InvalidArgument, "no levels of detail");
  const int n = level_images[0].size;
  const int levels = static_cast<int>(level_images.size());
  SPHEREKIT_RETURN_IF_ERROR(check_lod_options(n, levels, options));
  if (options.mode == LodMode::Adaptive) {
    GltfLodOptions o = options;
    o.levels = levels;
    return build_gltf_lods(level_images[0], o, progress);
  }
  for (int k = 1; k < levels; ++k)
    if (level_images[static_cast<std::size_t>(k)].size != level_size(n, k))
      return Status(ErrorCode::InvalidArgument, "level " + std::to_string(k) + " of detail is not " +
                                                    std::to_string(level_size(n, k)) + " texels wide");
  std::vector<GltfMesh> meshes;
  std::vector<int> sizes;
  for (int k = 0; k < levels; ++k) {
    SPHEREKIT_ASSIGN_OR_RETURN(GltfMesh mesh, gltf_mesh_from_geometry_image(level_images[static_cast<std::size_t>(k)], n));
    // Before encoding the faces are geometry_image_mesh's, in its order.
    if (options.drop_hole_faces)
      mesh = gltf_mesh_without_faces(mesh, geometry_image_hole_faces(level_images[static_cast<std::size_t>(k)]));
    meshes.push_back(std::move(mesh));
    sizes.push_back(level_images[static_cast<std::size_t>(k)].size);
  }
  return build_from_meshes(std::move(meshes), sizes, n, options, progress);
}

Result<std::vector<GltfLods>> build_consistent_gltf_lods(const std::vector<GeometryImage>& members,
                                                         const std::vector<GltfLodOptions>& options,
                                                         const ProgressFn& progress) {
  if (members.empty() || options.size() != members.size())
    return Status(ErrorCode::InvalidArgument, "consistent levels of detail need one option set per member");
  const GltfLodOptions& first = options[0];
  for (const GeometryImage& g : members)
    SPHEREKIT_RETURN_IF_ERROR(check_lod_options(g.size, first.levels, first));
  std::vector<GltfLods> out;
  if (first.mode == LodMode::Uniform) {
    for (std::size_t m = 0; m < members.size(); ++m) {
      GltfLodOptions o = options[m];
      o.mode = LodMode::Uniform;
      o.levels = first.levels;
      o.drop_hole_faces = false;
      SPHEREKIT_ASSIGN_OR_RETURN(GltfLods lods, build_gltf_lods(members[m], o, progress));
      out.push_back(std::move(lods));
    }
    return out;
  }
  AdaptiveLodOptions a;
  a.levels = first.levels;
  a.lod0_vertex_fraction = first.lod0_vertex_fraction;
  for (const GltfLodOptions& o : options) a.lod0_max_vertices = std::max(a.lod0_max_vertices, o.lod0_max_vertices);
  SPHEREKIT_ASSIGN_OR_RETURN(auto all, adaptive_lod_meshes(members, a, progress));
  for (std::size_t m = 0; m < members.size(); ++m) {
    GltfLodOptions o = options[m];
    o.mode = LodMode::Adaptive;
    o.levels = first.levels;
    const TriMesh finest = geometry_image_mesh(members[m]);
    SPHEREKIT_ASSIGN_OR_RETURN(GltfLods lods,
                               build_from_meshes(adaptive_member_levels(all, m, members[m], false),
                                                 std::vector<int>(static_cast<std::size_t>(a.levels), members[m].size),
                                                 members[m].size, o, progress, &finest));
    out.push_back(std::move(lods));
  }
  return out;
}

namespace {

// Position bits of a coarse adaptive level from its own error: the RMS distance between it
// and level 0 (both directions, sampled, deterministic) stands for its error against the
// original (level 0's own is smaller and adds in squares). Same rule as
// choose_draco_quantization: step/2 <= fraction * error.
QuantizationChoice coarse_quantization(const QuantizationChoice& shared, const GltfMesh& finest, const GltfMesh& level,
                                       const GltfLodOptions& options) {
  QuantizationChoice q = shared;
  RemeshErrorOptions eo;
  eo.samples = 20000;
  const RemeshError e = remesh_error(TriMesh{finest.V, finest.F}, TriMesh{level.V, level.F}, eo);
  if (!(e.rms > 0) || !std::isfinite(e.rms)) return q;
  const double needed = static_cast<double>(shared.quantization.position_range) /
                        (2.0 * options.budget.position_error_fraction * e.rms);
  const int bits = static_cast<int>(std::clamp(std::ceil(std::log2(needed + 1.0)),
                                               static_cast<double>(options.coarse_position_bits),
                                               static_cast<double>(shared.quantization.position_bits)));
  q.quantization.position_bits = bits;
  q.reference_rms_error = e.rms;
  q.position_max_error = q.quantization.position_step() / 2;
  return q;
}

// Texture-coordinate bits of original level k: level 0's less k. Level k has 1/4^k of level 0's
// vertices, so edges 2^k times as long, and it is shown at most at 1/2^k of level 0's size (the
// screen coverages halve per level): a grid step 2^k times level 0's is the same fraction of its
// triangles, and the same distance on screen, which is half a texel of the mip level sampled
// there (mip k). Floored at kMinCoarseTexcoordBits, a 16-step grid over the octahedral domain.
constexpr int kMinCoarseTexcoordBits = 4;
int coarse_texcoord_bits(int level0_bits, int level) {
  return std::max(std::min(level0_bits, kMinCoarseTexcoordBits), level0_bits - level);
}

Result<GltfLods> build_from_meshes(std::vector<GltfMesh> meshes, const std::vector<int>& sizes, int n,
                                   const GltfLodOptions& options, const ProgressFn& progress, const TriMesh* finest) {
  const int levels = static_cast<int>(meshes.size());
  if (!options.texcoords)
    for (GltfMesh& m : meshes) m = gltf_mesh_without_texcoords(m);
  // Every level's primitive first: the shared quantization grid must hold all of them (fitted
  // levels can stray a little outside the finest level's bounding box).
  GltfLods out;
  GltfMesh all_points = meshes[0];
  for (int k = 1; k < levels; ++k) {
    const GltfMesh& m = meshes[static_cast<std::size_t>(k)];
    const Eigen::Index rows = all_points.V.rows();
    all_points.V.conservativeResize(rows + m.V.rows(), 3);
    all_points.V.bottomRows(m.V.rows()) = m.V;
    // An attribute the levels do not have stays empty (resized by V's rows it would hold
    // uninitialized values).
    if (m.N.rows() > 0) {
      all_points.N.conservativeResize(rows + m.N.rows(), 3);
      all_points.N.bottomRows(m.N.rows()) = m.N;
    }
    if (m.UV.rows() > 0) {
      all_points.UV.conservativeResize(rows + m.UV.rows(), 2);
      all_points.UV.bottomRows(m.UV.rows()) = m.UV;
    }
  }
  all_points.position_index.clear();
  SPHEREKIT_ASSIGN_OR_RETURN(out.quantization,
                             choose_draco_quantization(all_points, options.reference_rms_error, options.budget));
  if (options.mode == LodMode::Original && all_points.UV.rows() > 0) {
    // Arbitrary texture coordinates on the UV box's grid (at most the texel lattice's span,
    // (n-1)/n): b = ceil(log2((n-1) / (2 err))) bits, a step of about 2 err texels, so a
    // coordinate moves by about err texels at most (n = 257, err = 0.5: 8 bits, 0.502 texel).
    DracoQuantization& q = out.quantization.quantization;
    const double steps = (n - 1) / (2.0 * options.texcoord_max_error_texels);
    q.texcoord_bits = std::clamp(static_cast<int>(std::ceil(std::log2(std::max(steps, 1.0)) - 1e-9)), 1, 30);
  }
  DracoEncodeOptions encode;
  encode.quantization = out.quantization.quantization;
  encode.compression_level = options.compression_level;
  encode.smallest_texcoord_prediction = options.mode == LodMode::Original;

  // Rate-distortion bits need each level's error against the original: the finest remesh's
  // own (reference_rms_error) in squares with the level's distance to that remesh.
  std::vector<double> level_errors;
  double gamma = 1.0;
  if (options.position_bits_rule == PositionBitsRule::RateDistortion) {
    const double ref = options.reference_rms_error > 0 && std::isfinite(options.reference_rms_error)
                           ? options.reference_rms_error
                           : 0.0;
    RemeshErrorOptions eo;
    eo.samples = 20000;
    const TriMesh top = finest ? TriMesh{} : TriMesh{meshes[0].V, meshes[0].F};
    const TriMesh& source = finest ? *finest : top;
    for (int k = 0; k < levels; ++k) {
      const GltfMesh& m = meshes[static_cast<std::size_t>(k)];
      const double d = !finest && k == 0 ? 0.0 : remesh_error(source, TriMesh{m.V, m.F}, eo).rms;
      const double e = std::sqrt(ref * ref + (std::isfinite(d) ? d * d : 0.0));
      level_errors.push_back(e);
    }
    // Original levels: level 0 is the mesh itself (its tiny error is the cut's, not a
    // simplification error, and put gamma at its 0.5 floor), so the rate curve runs from level
    // 1 (bunny's coarsest level: 8 bits instead of 7, 1.36 -> 1.29 x gltf-transform at equal PSNR).
    const std::size_t first = options.mode == LodMode::Original && levels > 2 ? 1 : 0;
    if (levels > 1)
      gamma = rate_exponent(static_cast<double>(meshes[first].V.rows()), level_errors[first],
                            static_cast<double>(meshes.back().V.rows()), level_errors.back());
  }

  for (int k = 0; k < levels; ++k) {
    if (!report_progress(progress, "gltf", k, static_cast<double>(k) / levels))
      return Status(ErrorCode::Cancelled, "cancelled");
    GltfLodLevel level;
    level.image_size = sizes[static_cast<std::size_t>(k)];
    level.mesh = std::move(meshes[static_cast<std::size_t>(k)]);
    if (!options.normals) level.mesh.N.resize(0, 3);
    level.quantization = out.quantization;
    if (options.mode == LodMode::Original && options.coarse_texcoord_bits)
      level.quantization.quantization.texcoord_bits = coarse_texcoord_bits(encode.quantization.texcoord_bits, k);
    const double level_error = level_errors.empty() ? 0.0 : level_errors[static_cast<std::size_t>(k)];
    if (level_error > 0) {
      DracoEncodeOptions level_encode = encode;
      level_encode.quantization.texcoord_bits = level.quantization.quantization.texcoord_bits;
      // The file's bytes around the bitstream (GLB headers, JSON: ~0.8 KB, a third of a coarse
      // level), as in the previous level's file, count in the rate: the file is what a viewer
      // downloads (cat0's level 2: 8 -> 9 bits, 1.16 -> 1.15 x gltf-transform at equal PSNR).
      const double fixed =
          k > 0 ? static_cast<double>(out.levels.back().glb.size() - out.levels.back().primitive.bytes.size()) : 0.0;
      SPHEREKIT_ASSIGN_OR_RETURN(PositionBitsChoice c, choose_position_bits(level.mesh, level_encode, level_error, gamma,
                                                                            std::min(options.min_position_bits_rd,
                                                                                     encode.quantization.position_bits),
                                                                            fixed));
      level.quantization.quantization.position_bits = c.bits;
      level.quantization.reference_rms_error = level_error;
      level.quantization.position_max_error = level.quantization.quantization.position_step() / 2;
      level.quantization.rate_distortion = true;
      level.primitive = std::move(c.primitive);
    } else {
      if (k > 0 && options.mode == LodMode::Adaptive && options.coarse_position_bits > 0)
        level.quantization = coarse_quantization(out.quantization, out.levels[0].mesh, level.mesh, options);
      DracoEncodeOptions level_encode = encode;
      level_encode.quantization = level.quantization.quantization;
      SPHEREKIT_ASSIGN_OR_RETURN(level.primitive, encode_draco_primitive(level.mesh, level_encode));
    }

    detail::GlbBuilder doc;
    const int m = doc.add_draco_mesh(level.primitive, level_name(options.name, k), tinygltf::Value());
    tinygltf::Node node;
    node.name = level_name(options.name, k);
    node.mesh = m;
    doc.model().nodes.push_back(std::move(node));
    doc.model().scenes.emplace_back();
    doc.model().scenes[0].nodes = {0};
    doc.model().defaultScene = 0;
    doc.model().asset.extras = level_file_extras(k, level.mesh.UV.rows() > 0 ? n : 0);
    SPHEREKIT_ASSIGN_OR_RETURN(level.glb, doc.to_glb());
    out.levels.push_back(std::move(level));
  }

  // Screen coverage: halves per level (the sample spacing doubles), the last level down to
  // lowest_coverage.
  for (int k = 0; k < levels; ++k)
    out.screen_coverage.push_back(k + 1 == levels ? options.lowest_coverage
                                                          : options.lod0_coverage / static_cast<double>(1 << k));

  detail::GlbBuilder doc;
  tinygltf::Value::Array ids;
  for (int k = 0; k < levels; ++k) {
    const GltfLodLevel& level = out.levels[static_cast<std::size_t>(k)];
    const int m = doc.add_draco_mesh(level.primitive, level_name(options.name, k),
                                     level_extras(k, level.image_size, n, level.quantization, options.mode,
                                                  level.mesh.N.rows() > 0));
    tinygltf::Node node;
    node.name = level_name(options.name, k);
    node.mesh = m;
    doc.model().nodes.push_back(std::move(node));
    if (k > 0) ids.push_back(detail::json_int(k));
  }
  if (levels > 1) {
    // MSFT_lod on the highest level; "ids" needs at least one entry (schema minItems 1).
    tinygltf::Node& top = doc.model().nodes[0];
    tinygltf::Value::Object lod;
    lod["ids"] = tinygltf::Value(std::move(ids));
    top.extensions["MSFT_lod"] = detail::json_object(std::move(lod));
    tinygltf::Value::Object extras;
    extras["MSFT_screencoverage"] = detail::json_array(out.screen_coverage);
    top.extras = detail::json_object(std::move(extras));
    doc.use_extension("MSFT_lod", false);
  }
  doc.model().scenes.emplace_back();
  doc.model().scenes[0].nodes = {0};
  doc.model().defaultScene = 0;
  doc.model().asset.extras = asset_extras(options, n, levels);
  SPHEREKIT_ASSIGN_OR_RETURN(out.combined_glb, doc.to_glb());
  if (!report_progress(progress, "gltf", levels, 1.0)) return Status(ErrorCode::Cancelled, "cancelled");
  return out;
}

}  // namespace

Result<GltfLodPaths> write_gltf_lods(const std::string& prefix, const GltfLods& lods) {
  GltfLodPaths paths = gltf_lod_paths(prefix, static_cast<int>(lods.levels.size()));
  for (std::size_t k = 0; k < lods.levels.size(); ++k)
    SPHEREKIT_RETURN_IF_ERROR(formats::write_file_atomic(paths.levels[k], lods.levels[k].glb));
  SPHEREKIT_RETURN_IF_ERROR(formats::write_file_atomic(paths.combined, lods.combined_glb));
  return paths;
}

}  // namespace spherekit::convert
