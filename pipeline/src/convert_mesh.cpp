// convert_mesh(): one mesh and its sphere map through the conversion pipeline, and the report
// `convert --report` writes (convert.h).
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "spherekit/check_mesh.h"
#include "spherekit/file_status.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/pipeline/convert.h"
#include "spherekit/pipeline/json.h"
#include "spherekit/version.h"
#include "stopwatch.h"

namespace fs = std::filesystem;

namespace spherekit::pipeline {

Result<ConvertMeshResult> convert_mesh(const ConvertMeshJob& job, const ProgressFn& progress) {
  SPHEREKIT_RETURN_IF_ERROR(check_convert_options(job.options));
  // The image is OpenEXR whatever the name says; `-o out.png` wrote EXR data named .png.
  if (formats::file_extension(job.output) != "exr")
    return Status(ErrorCode::Unsupported, job.output + ": geometry images are written as .exr files");
  Stopwatch wall;
  ConvertMeshResult out;
  out.job = job;
  auto mesh = formats::read_mesh(job.mesh);
  if (!mesh.ok()) return with_file(mesh.status(), job.mesh);
  // Only meshes param accepts have sphere maps; anything else would be resampled into garbage.
  SPHEREKIT_RETURN_IF_ERROR(with_file(require_param_accepts(mesh.value(), check_mesh(mesh.value())), job.mesh));
  const double read_mesh_seconds = wall.seconds();
  Stopwatch read_sphere;
  auto map = formats::read_sphere_map(job.sphere, mesh.value());
  if (!map.ok()) return with_file(map.status(), job.sphere);
  // A folded map sends texels to the wrong faces: the image would look valid and be wrong.
  // The exact predicate decides, as for param's own output.
  if (const int flipped = count_flipped_faces(mesh->F, map->S); flipped != 0) {
    char text[160];
    std::snprintf(text, sizeof text, " (%d of %lld faces flipped or degenerate on the sphere); nothing written", flipped,
                  static_cast<long long>(mesh->F.rows()));
    return Status(ErrorCode::InvalidInput, job.sphere + ": not a bijective sphere map of " + job.mesh + text);
  }
  out.read_seconds = read_mesh_seconds + read_sphere.seconds();
  out.vertices = mesh->V.rows();
  out.faces = mesh->F.rows();
  GeometryOutputs names;
  names.image = job.output;
  names.prefix = output_prefix(job.output);
  names.remesh = job.remesh;
  names.name = fs::path(job.mesh).stem().string();
  names.source_mesh = job.mesh;
  names.sphere_map = job.sphere;
  SPHEREKIT_ASSIGN_OR_RETURN(out.assets,
                             convert_geometry(mesh.value(), map->S, job.options, names, /*collection_member=*/false, progress));
  out.wall_seconds = wall.seconds();
  return out;
}

Json lod_quantization_json(const convert::GltfLodLevel& level) {
  const convert::QuantizationChoice& c = level.quantization;
  Json j;
  j["position_bits"] = c.quantization.position_bits;
  j["position_max_error"] = c.position_max_error;
  j["reference_rms_error"] = c.reference_rms_error;
  j["decided_by"] = c.rate_distortion ? "rate-distortion" : c.reference_rms_error > 0 ? "error budget" : "minimum bits";
  if (level.mesh.UV.rows() > 0) j["texcoord_bits"] = c.quantization.texcoord_bits;
  if (level.mesh.N.rows() > 0) j["normal_bits"] = c.quantization.normal_bits;
  return j;
}

Json to_json(const CageAssets& c) {
  Json j;
  j["file"] = c.cage_path;
  j["displacement_file"] = c.displacement_path;
  j["domain"] = "cube, equi-angular";
  j["n"] = c.n;
  j["quads"] = c.quads;
  j["control_points"] = c.control_points;
  j["displacement"] = displacement_kind_name(c.kind);
  j["tile"] = c.tile;
  j["fit_rms"] = c.fit_rms;
  j["max_displacement"] = c.max_displacement;
  if (c.kind == convert::DisplacementKind::Scalar) j["mean_ray_residual"] = c.ray_residual;
  j["samples_in_holes"] = c.samples_in_holes;
  j["stored_floats"] = c.stored_floats;
  j["bytes"] = file_bytes(c.cage_path) + file_bytes(c.displacement_path);
  if (c.measured) {
    j["psnr_db_limit"] = number_or_null(c.limit_error.psnr);
    j["psnr_db"] = number_or_null(c.displaced_error.psnr);
    j["rms"] = c.displaced_error.rms;
  }
  return j;
}

Json to_json(const ConvertMeshResult& r) {
  const ConvertMeshJob& a = r.job;
  const GeometryAssets& g = r.assets;
  Json j;
  j["input"] = a.mesh;
  j["sphere_map"] = a.sphere;
  j["output"] = a.output;
  if (!a.remesh.empty()) j["remesh"] = a.remesh;
  j["V"] = r.vertices;
  j["F"] = r.faces;
  j["size"] = a.options.size;
  j["positions"] = texel_positions_name(a.options.positions);
  j["layout"] = "octahedral";
  j["texels_in_holes"] = g.image.texels_in_holes;
  j["previews"] = g.previews;
  j["remesh_V"] = g.remesh.V.rows();
  j["remesh_F"] = g.remesh.F.rows();
  if (g.measured) {
    j["psnr_db"] = number_or_null(g.error.psnr);
    j["rms"] = g.error.rms;
    j["rms_forward"] = g.error.rms_forward;
    j["rms_backward"] = g.error.rms_backward;
    j["max_distance"] = g.error.max_distance;
    j["bbox_diag"] = g.error.peak;
    const bool has_holes = g.image.texels_in_holes > 0;
    j["psnr_excludes_hole_faces"] = has_holes;
    if (has_holes && g.error_all_faces) j["psnr_db_all_faces"] = number_or_null(g.error_all_faces->psnr);
    j["psnr_samples"] = a.options.psnr_samples;
  }
  if (a.options.lods > 0) {
    Json levels = Json::array();
    for (std::size_t k = 0; k < g.lods.levels.size(); ++k) {
      const convert::GltfLodLevel& level = g.lods.levels[k];
      Json l;
      l["file"] = g.lod_paths.levels[k];
      l["bytes"] = file_bytes(g.lod_paths.levels[k]);
      l["draco_bytes"] = level.primitive.bytes.size();
      l["size"] = level.image_size;
      l["V"] = level.primitive.decoded.mesh.V.rows();
      l["F"] = level.primitive.decoded.mesh.F.rows();
      l["screen_coverage"] = g.lods.screen_coverage[k];
      if (k < g.lod_errors.size()) {
        l["psnr_db"] = number_or_null(g.lod_errors[k].psnr);
        l["rms"] = g.lod_errors[k].rms;
      }
      l["quantization"] = lod_quantization_json(level);
      levels.push_back(std::move(l));
    }
    j["lods"] = std::move(levels);
    j["lods_file"] = {{"file", g.lod_paths.combined}, {"bytes", file_bytes(g.lod_paths.combined)}};
    const convert::DracoQuantization& q = g.lods.quantization.quantization;
    j["quantization"] = {{"position_bits", q.position_bits},
                         {"normal_bits", q.normal_bits},
                         {"texcoord_bits", q.texcoord_bits},
                         {"position_step", q.position_step()},
                         {"position_max_error", g.lods.quantization.position_max_error},
                         {"reference_rms_error", g.lods.quantization.reference_rms_error},
                         {"position_error_fraction", g.lods.quantization.position_error_fraction}};
    j["times"]["gltf"] = g.times.gltf;
    j["times"]["gltf_psnr"] = g.times.gltf_psnr;
  }
  if (g.cage) {
    j["cage"] = to_json(*g.cage);
    j["times"]["cage"] = g.cage->seconds;
    j["times"]["cage_psnr"] = g.cage->psnr_seconds;
  }
  j["times"]["read"] = r.read_seconds;
  j["times"]["sample"] = g.times.sample;
  j["times"]["remesh"] = g.times.remesh;
  j["times"]["write"] = g.times.write;
  j["times"]["psnr"] = g.times.psnr;
  j["times"]["wall"] = r.wall_seconds;
  j["version"] = kVersion;
  return j;
}

}  // namespace spherekit::pipeline
