// convert_geometry(): the one conversion pipeline (convert.h) that one mesh, every collection
// member and the main job go through: sample -> remesh -> EXR -> previews -> PSNR -> glTF
// levels of detail (and their PSNR) -> cage + displacement (and their PSNR).
#include <chrono>
#include <cstdio>

#include "spherekit/convert/cage_uv_atlas.h"
#include "spherekit/convert/displacement_exr.h"
#include "spherekit/convert/geometry_image_exr.h"
#include "spherekit/convert/geometry_image_png.h"
#include "spherekit/convert/subd_cage.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/file_status.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/pipeline/convert.h"
#include "stopwatch.h"

namespace spherekit::pipeline {
namespace {

Status cancelled() { return Status(ErrorCode::Cancelled, "cancelled"); }

GeometryImageOptions image_options(const ConvertOptions& o) {
  GeometryImageOptions g;
  g.fit_positions = o.positions == TexelPositions::Fit;
  g.threads = o.threads;
  return g;
}

convert::CageFitOptions cage_options(const ConvertOptions& o) {
  convert::CageFitOptions c;
  c.threads = o.threads;
  return c;
}

Result<std::vector<std::string>> write_previews(const GeometryImage& image, const std::string& prefix) {
  std::vector<std::string> written;
  const std::pair<convert::GeometryImagePreview, const char*> kinds[] = {
      {convert::GeometryImagePreview::Normals, "_normals.png"}, {convert::GeometryImagePreview::Positions, "_positions.png"}};
  for (const auto& [kind, suffix] : kinds) {
    SPHEREKIT_ASSIGN_OR_RETURN(convert::Image8 preview, convert::geometry_image_preview(image, kind));
    SPHEREKIT_ASSIGN_OR_RETURN(std::string png, convert::encode_png(preview));
    const std::string path = prefix + suffix;
    SPHEREKIT_RETURN_IF_ERROR(formats::write_file_atomic(path, png));
    written.push_back(path);
  }
  return written;
}

// Fits the cage, samples the displacement, writes both, and measures the bare limit surface
// and the displaced surface against the mesh (hole spans left out, as for the image).
Result<CageAssets> build_cage(const TriMesh& mesh, const RowMat3d& S, const ConvertOptions& o,
                              const GeometryOutputs& names, const ProgressFn& progress) {
  Stopwatch time;
  CageAssets out;
  SPHEREKIT_ASSIGN_OR_RETURN(convert::CageDomain domain, convert::cube_cage_domain(o.cage));
  SPHEREKIT_ASSIGN_OR_RETURN(convert::CageLimit limit, convert::CageLimit::create(domain));
  SPHEREKIT_ASSIGN_OR_RETURN(convert::SubdCage cage, convert::fit_subd_cage(mesh, S, limit, domain, cage_options(o), progress));
  convert::DisplacementOptions dopt;
  dopt.tile = o.cage_tile;
  dopt.kind = o.displacement;
  dopt.threads = o.threads;
  SPHEREKIT_ASSIGN_OR_RETURN(convert::DisplacementMap disp, convert::sample_displacement(mesh, S, cage, limit, dopt, progress));
  out.cage_path = names.prefix + "_cage.obj";
  out.displacement_path = names.prefix + "_disp.exr";
  // The cage's texture coordinates and the displacement texture share one UV atlas of its quads.
  SPHEREKIT_ASSIGN_OR_RETURN(convert::CageUvAtlas atlas,
                             convert::cage_uv_atlas(disp.faces, disp.tile, convert::kDefaultDisplacementGutter));
  SPHEREKIT_RETURN_IF_ERROR(convert::write_cage_obj(out.cage_path, cage, "fitted to " + names.source_mesh, &atlas));
  SPHEREKIT_RETURN_IF_ERROR(convert::write_displacement_exr(out.displacement_path, disp, atlas,
                                                            {names.source_mesh, names.sphere_map, out.cage_path}));
  out.n = o.cage;
  out.tile = o.cage_tile;
  out.kind = o.displacement;
  out.control_points = static_cast<int>(cage.points.rows());
  out.quads = static_cast<int>(cage.domain.quads.size());
  out.fit_rms = cage.fit_rms;
  out.max_displacement = disp.max_abs;
  out.ray_residual = disp.mean_ray_residual;
  out.samples_in_holes = disp.samples_in_holes;
  out.stored_floats = convert::stored_floats(cage, disp);
  out.seconds = time.seconds();
  if (o.psnr_samples > 0) {
    Stopwatch t;
    RemeshErrorOptions opts;
    opts.samples = o.psnr_samples;
    opts.threads = o.threads;
    std::vector<std::uint8_t> holes;
    const TriMesh displaced = convert::displaced_surface_mesh(cage, limit, &disp, 0, &holes);
    out.displaced_error = remesh_error(mesh, displaced, opts, holes);
    const TriMesh limit_mesh = convert::displaced_surface_mesh(cage, limit, nullptr, o.cage_tile);
    out.limit_error = remesh_error(mesh, limit_mesh, opts, holes);
    out.measured = true;
    out.psnr_seconds = t.seconds();
  }
  return out;
}

}  // namespace

const char* texel_positions_name(TexelPositions p) { return p == TexelPositions::Fit ? "fit" : "sampled"; }
const char* displacement_kind_name(convert::DisplacementKind k) {
  return k == convert::DisplacementKind::Vector ? "vector" : "scalar";
}

std::string output_prefix(const std::string& output) {
  const std::size_t slash = output.find_last_of('/'), dot = output.find_last_of('.');
  if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) return output.substr(0, dot);
  return output;
}

Status check_convert_options(const ConvertOptions& o) {
  char text[160];
  auto bad = [&](int n) { return Status(ErrorCode::InvalidArgument, std::string(text, static_cast<std::size_t>(n))); };
  if (!is_geometry_image_size(o.size) || o.size > 16385)
    return bad(std::snprintf(text, sizeof text, "--size %d is not 2^k+1 (e.g. 65, 129, 257, 513)", o.size));
  if (o.psnr_samples < 0) return Status(ErrorCode::InvalidArgument, "--psnr-samples must be >= 0");
  if (o.threads < 0) return Status(ErrorCode::InvalidArgument, "--threads must be >= 0 (0: all cores)");
  if (o.lods < 0 || o.lods > 30 || (o.lods > 0 && ((o.size - 1) >> (o.lods - 1)) < 2))
    return bad(std::snprintf(text, sizeof text, "--lods %d does not fit --size %d (the coarsest level needs >= 3 x 3 texels)",
                             o.lods, o.size));
  if (o.cage < 0 || o.cage > 256) return bad(std::snprintf(text, sizeof text, "--cage %d is not in 0..256", o.cage));
  if (o.cage_tile < 2 || o.cage_tile > 1025)
    return bad(std::snprintf(text, sizeof text, "--cage-tile %d is not in 2..1025", o.cage_tile));
  return Status();
}

Result<GeometryAssets> convert_geometry(const TriMesh& mesh, const RowMat3d& S, const ConvertOptions& o,
                                        const GeometryOutputs& names, bool collection_member,
                                        const ProgressFn& progress) {
  GeometryAssets out;
  Stopwatch sample_time;
  auto sampled = sample_geometry_image(mesh, S, o.size, image_options(o));
  if (!sampled.ok()) return with_file(sampled.status(), names.source_mesh);
  out.image = std::move(sampled).value();
  out.times.sample = sample_time.seconds();
  if (!report_progress(progress, "convert", 0, -1)) return cancelled();

  Stopwatch remesh_time;
  // A single mesh's remesh keeps its holes open (the faces spanning them have no
  // counterpart); a member's stays closed (one connectivity for every member).
  out.remesh = collection_member ? geometry_image_mesh(out.image) : geometry_image_open_mesh(out.image);
  out.times.remesh = remesh_time.seconds();

  Stopwatch write_time;
  SPHEREKIT_RETURN_IF_ERROR(convert::write_geometry_image_exr(names.image, out.image, {names.source_mesh, names.sphere_map}));
  if (!names.remesh.empty()) SPHEREKIT_RETURN_IF_ERROR(formats::write_mesh(names.remesh, out.remesh));
  SPHEREKIT_ASSIGN_OR_RETURN(out.previews, write_previews(out.image, names.prefix));
  out.times.write = write_time.seconds();
  if (!report_progress(progress, "convert", 0, -1)) return cancelled();

  // For meshes with holes, the remesh faces spanning a hole are left out of the PSNR (they
  // have no counterpart in the original); one mesh's PSNR over all faces is reported beside it.
  RemeshErrorOptions psnr;
  psnr.samples = o.psnr_samples;
  psnr.threads = o.threads;
  if (o.psnr_samples > 0) {
    Stopwatch psnr_time;
    out.measured = true;
    if (collection_member) {
      out.error = remesh_error(mesh, out.remesh, psnr, geometry_image_hole_faces(out.image));
    } else {
      out.error = remesh_error(mesh, out.remesh, psnr);
      if (out.image.texels_in_holes > 0) out.error_all_faces = remesh_error(mesh, geometry_image_mesh(out.image), psnr);
    }
    out.times.psnr = psnr_time.seconds();
  }
  // glTF levels of detail: the position bits come from the error budget of the image's own
  // remesh error (when measured), the PSNR of each level is that of the decoded glTF geometry.
  // A collection member's adaptive or original levels are built for all members at once (one
  // connectivity per level: the reference's mesh laid on every member, or the common remesh;
  // convert_collection).
  const bool adaptive = o.lod_mode != convert::LodMode::Uniform;
  if (o.lods > 0 && !(adaptive && collection_member)) {
    Stopwatch gltf_time;
    convert::GltfLodOptions lo;
    lo.levels = o.lods;
    lo.budget = o.budget;
    lo.reference_rms_error = out.measured ? out.error.rms : 0;
    lo.name = names.name;
    lo.provenance = {names.source_mesh, names.lods_sphere_map.empty() ? names.sphere_map : names.lods_sphere_map};
    // One mesh's levels show its holes; a member's keep the shared connectivity. Each level
    // is fitted at its own size.
    lo.drop_hole_faces = !collection_member;
    lo.mode = o.lod_mode;  // Original only here (a single mesh)
    lo.normals = o.lod_normals;
    lo.texcoords = o.lod_texcoords;
    lo.coarse_position_bits = o.lod_coarse_position_bits;
    lo.position_bits_rule = o.lod_position_bits;
    lo.lod0_max_vertices = static_cast<int>(mesh.V.rows());
    if (o.lod_mode == convert::LodMode::Original) {
      // Draco's slowest setting (speed 0: constrained multi-parallelogram positions): 2-7% smaller
      // than level 7 on the bunny's levels, encoding a few levels still takes well under a second.
      lo.compression_level = 10;
      auto lods = convert::build_original_gltf_lods(mesh, S, out.image.size, lo, progress);
      if (!lods.ok()) return with_file(lods.status(), names.source_mesh);
      out.lods = std::move(lods).value();
    } else if (adaptive) {
      SPHEREKIT_ASSIGN_OR_RETURN(out.lods, convert::build_gltf_lods(out.image, lo, progress));
    } else {
      auto level_images = convert::lod_geometry_images(mesh, S, out.image, o.lods, image_options(o));
      if (!level_images.ok()) return with_file(level_images.status(), names.source_mesh);
      SPHEREKIT_ASSIGN_OR_RETURN(out.lods, convert::build_gltf_lods(level_images.value(), lo, progress));
    }
    SPHEREKIT_ASSIGN_OR_RETURN(out.lod_paths, convert::write_gltf_lods(names.prefix, out.lods));
    out.times.gltf = gltf_time.seconds();
    if (out.measured) {
      Stopwatch t;
      for (const convert::GltfLodLevel& level : out.lods.levels) {
        if (!report_progress(progress, "convert", 0, -1)) return cancelled();
        const convert::GltfMesh& d = level.primitive.decoded.mesh;
        // The levels' own faces (holes open or not) are what the file holds: all count.
        out.lod_errors.push_back(remesh_error(mesh, TriMesh{d.V, d.F}, psnr));
      }
      out.times.gltf_psnr = t.seconds();
    }
  }
  // Catmull-Clark cage + displacement atlas: PREFIX_cage.obj, PREFIX_disp.exr.
  if (o.cage > 0) {
    auto cage = build_cage(mesh, S, o, names, progress);
    if (!cage.ok()) return with_file(cage.status(), names.source_mesh);
    out.cage = std::move(cage).value();
  }
  return out;
}

}  // namespace spherekit::pipeline
