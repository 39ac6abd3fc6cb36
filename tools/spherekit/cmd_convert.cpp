// `spherekit convert`: a mesh and its sphere map -> an octahedral geometry image (float EXR),
// optionally the remesh it defines (OBJ) and Draco glTF levels of detail, with the remesh PSNR
// against the original.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cli_common.h"
#include "commands.h"
#include "convert_common.h"
#include "spherekit/convert/displacement.h"
#include "spherekit/convert/displacement_exr.h"
#include "spherekit/convert/geometry_image_exr.h"
#include "spherekit/convert/geometry_image_png.h"
#include "spherekit/convert/subd_cage.h"
#include "spherekit/convert/gltf_lods.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/geometry_image.h"
#include "spherekit/metrics.h"
#include "spherekit/version.h"

namespace spherekit::cli {

std::string gltf_prefix(const std::string& output) {
  const std::size_t slash = output.find_last_of('/'), dot = output.find_last_of('.');
  if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) return output.substr(0, dot);
  return output;
}

std::uintmax_t file_bytes(const std::string& path) {
  std::error_code ec;
  const std::uintmax_t n = std::filesystem::file_size(path, ec);
  return ec ? 0 : n;
}

Json number_or_null(double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); }

Result<std::vector<std::string>> write_geometry_image_previews(const GeometryImage& image, const std::string& prefix) {
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

GeometryImageOptions geometry_image_options(const ConvertArgs& a) {
  GeometryImageOptions o;
  o.fit_positions = a.positions == "fit";
  return o;
}

Status check_convert_flags(const ConvertArgs& a) {
  if (!is_geometry_image_size(a.size) || a.size > 16385)
    return Status(ErrorCode::InvalidArgument, strprintf("--size %d is not 2^k+1 (e.g. 65, 129, 257, 513)", a.size));
  if (a.positions != "fit" && a.positions != "sampled")
    return Status(ErrorCode::InvalidArgument, "--positions must be fit or sampled, not '" + a.positions + "'");
  if (a.psnr_samples < 0) return Status(ErrorCode::InvalidArgument, "--psnr-samples must be >= 0");
  if (a.lods < 0 || a.lods > 30 || (a.lods > 0 && ((a.size - 1) >> (a.lods - 1)) < 2))
    return Status(ErrorCode::InvalidArgument,
                  strprintf("--lods %d does not fit --gi %d (the coarsest level needs >= 3 x 3 texels)", a.lods, a.size));
  if (a.cage < 0 || a.cage > 256)
    return Status(ErrorCode::InvalidArgument, strprintf("--cage %d is not in 0..256", a.cage));
  if (a.cage_tile < 2 || a.cage_tile > 1025)
    return Status(ErrorCode::InvalidArgument, strprintf("--cage-tile %d is not in 2..1025", a.cage_tile));
  if (a.displacement != "scalar" && a.displacement != "vector")
    return Status(ErrorCode::InvalidArgument, "--displacement must be scalar or vector, not '" + a.displacement + "'");
  if (a.collection.empty() && (a.mesh.empty() || a.sphere.empty()))
    return Status(ErrorCode::InvalidArgument, "give MESH and SPHERE, or --collection DIR");
  if (!a.collection.empty() && (!a.mesh.empty() || !a.sphere.empty()))
    return Status(ErrorCode::InvalidArgument, "--collection converts every member: give no MESH or SPHERE with it");
  if (!a.collection.empty() && !a.remesh.empty())
    return Status(ErrorCode::InvalidArgument, "--remesh is for one mesh; with --collection use --report");
  return Status();
}

// Fits the cage, samples the displacement, writes both, and measures the bare limit surface
// and the displaced surface against the mesh (hole spans left out, as for the image).
Result<CageOutput> build_cage(const TriMesh& mesh, const RowMat3d& S, const ConvertArgs& a, const std::string& prefix,
                              const ProgressFn& progress) {
  Stopwatch time;
  CageOutput out;
  auto domain = convert::cube_cage_domain(a.cage);
  if (!domain.ok()) return domain.status();
  auto limit = convert::CageLimit::create(domain.value());
  if (!limit.ok()) return limit.status();
  auto cage = convert::fit_subd_cage(mesh, S, limit.value(), domain.value(), {}, progress);
  if (!cage.ok()) return cage.status();
  convert::DisplacementOptions dopt;
  dopt.tile = a.cage_tile;
  dopt.kind = a.displacement == "vector" ? convert::DisplacementKind::Vector : convert::DisplacementKind::Scalar;
  auto disp = convert::sample_displacement(mesh, S, cage.value(), limit.value(), dopt, progress);
  if (!disp.ok()) return disp.status();
  out.cage_path = prefix + "_cage.obj";
  out.displacement_path = prefix + "_disp.exr";
  auto atlas = convert::cage_uv_atlas(disp->faces, disp->tile, convert::kDefaultDisplacementGutter);
  if (!atlas.ok()) return atlas.status();
  if (Status s = convert::write_cage_obj(out.cage_path, cage.value(), "fitted to " + a.mesh, &atlas.value()); !s.ok())
    return s;
  if (Status s = convert::write_displacement_exr(out.displacement_path, disp.value(), atlas.value(),
                                                 {a.mesh, a.sphere, out.cage_path});
      !s.ok())
    return s;
  out.n = a.cage;
  out.tile = a.cage_tile;
  out.kind = a.displacement;
  out.control_points = static_cast<int>(cage->points.rows());
  out.quads = static_cast<int>(cage->domain.quads.size());
  out.fit_rms = cage->fit_rms;
  out.max_displacement = disp->max_abs;
  out.ray_residual = disp->mean_ray_residual;
  out.samples_in_holes = disp->samples_in_holes;
  out.stored_floats = convert::stored_floats(cage.value(), disp.value());
  out.seconds = time.seconds();
  if (a.psnr_samples > 0) {
    Stopwatch t;
    RemeshErrorOptions opts;
    opts.samples = a.psnr_samples;
    std::vector<std::uint8_t> holes;
    const TriMesh displaced = convert::displaced_surface_mesh(cage.value(), limit.value(), &disp.value(), 0, &holes);
    out.displaced_error = remesh_error(mesh, displaced, opts, holes);
    const TriMesh limit_mesh = convert::displaced_surface_mesh(cage.value(), limit.value(), nullptr, a.cage_tile);
    out.limit_error = remesh_error(mesh, limit_mesh, opts, holes);
    out.measured = true;
    out.psnr_seconds = t.seconds();
  }
  return out;
}

Json cage_json(const CageOutput& c) {
  Json j;
  j["file"] = c.cage_path;
  j["displacement_file"] = c.displacement_path;
  j["domain"] = "cube, equi-angular";
  j["n"] = c.n;
  j["quads"] = c.quads;
  j["control_points"] = c.control_points;
  j["displacement"] = c.kind;
  j["tile"] = c.tile;
  j["fit_rms"] = c.fit_rms;
  j["max_displacement"] = c.max_displacement;
  if (c.kind == "scalar") j["mean_ray_residual"] = c.ray_residual;
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

namespace {

int run_convert(const ConvertArgs& a) {
  if (!a.collection.empty()) return run_convert_collection(a);
  // Flags first: a bad size must fail before anything is read or written.
  if (Status s = check_convert_flags(a); !s.ok()) return print_error(s);

  // Every output folder before any work: a bad --report path must not fail the command
  // after the image was written.
  if (Status s = require_output_folders({a.output, a.remesh, a.report}); !s.ok()) return print_error(s);

  Stopwatch wall;
  auto loaded = load_mesh(a.mesh);
  if (!loaded.ok()) return print_error(loaded.status());
  const LoadedMesh& m = loaded.value();
  // Only meshes param accepts have sphere maps; anything else would be resampled into garbage.
  if (Status s = param_verdict(m, /*allow_boundary=*/true); !s.ok()) return print_error(s);
  Stopwatch read_sphere;
  auto map = formats::read_sphere_map(a.sphere, m.mesh);
  if (!map.ok()) return print_error(with_file(map.status(), a.sphere));
  // A folded map sends texels to the wrong faces: the image would look valid and be wrong.
  // The exact predicate decides, as for param's own output.
  if (const int flipped = count_flipped_faces(m.mesh.F, map->S); flipped != 0)
    return print_error(Status(ErrorCode::InvalidInput,
                              strprintf("%s: not a bijective sphere map of %s (%d of %lld faces flipped or "
                                        "degenerate on the sphere); nothing written",
                                        a.sphere.c_str(), a.mesh.c_str(), flipped,
                                        static_cast<long long>(m.mesh.F.rows()))));
  const double read_seconds = m.read_seconds + read_sphere.seconds();

  Stopwatch sample_time;
  auto sampled = sample_geometry_image(m.mesh, map->S, a.size, geometry_image_options(a));
  if (!sampled.ok()) return print_error(with_file(sampled.status(), a.mesh));
  const GeometryImage& image = sampled.value();
  const double sample_seconds = sample_time.seconds();
  if (cancel_requested()) return print_error(cancelled_status());

  Stopwatch remesh_time;
  // A single mesh's remesh keeps its holes open (the faces spanning them have no counterpart).
  const TriMesh remesh = geometry_image_open_mesh(image);
  const double remesh_seconds = remesh_time.seconds();

  Stopwatch write_time;
  if (Status s = convert::write_geometry_image_exr(a.output, image, {a.mesh, a.sphere}); !s.ok())
    return print_error(s);
  if (!a.remesh.empty())
    if (Status s = formats::write_mesh(a.remesh, remesh); !s.ok()) return print_error(s);
  auto previews = write_geometry_image_previews(image, gltf_prefix(a.output));
  if (!previews.ok()) return print_error(previews.status());
  const double write_seconds = write_time.seconds();
  if (cancel_requested()) return print_error(cancelled_status());

  // For meshes with holes, the remesh faces spanning a hole are left out of the PSNR (they
  // have no counterpart in the original); the PSNR over all faces is reported beside it.
  RemeshError err, err_all;
  double psnr_seconds = 0;
  const bool has_holes = image.texels_in_holes > 0;
  if (a.psnr_samples > 0) {
    Stopwatch psnr_time;
    RemeshErrorOptions opts;
    opts.samples = a.psnr_samples;
    err = remesh_error(m.mesh, remesh, opts);
    if (has_holes) err_all = remesh_error(m.mesh, geometry_image_mesh(image), opts);
    psnr_seconds = psnr_time.seconds();
  }
  // glTF levels of detail: the position bits come from the error budget of the image's own
  // remesh error (when measured), the PSNR of each level is that of the decoded glTF geometry.
  convert::GltfLods lods;
  convert::GltfLodPaths lod_paths;
  std::vector<RemeshError> lod_errors;
  double gltf_seconds = 0, gltf_psnr_seconds = 0;
  if (a.lods > 0) {
    Stopwatch gltf_time;
    convert::GltfLodOptions opts;
    opts.levels = a.lods;
    opts.budget = a.budget;
    opts.reference_rms_error = a.psnr_samples > 0 ? err.rms : 0;
    opts.name = file_stem(a.mesh);
    opts.provenance = {a.mesh, a.sphere};
    // A single mesh's levels show its holes; each level is fitted at its own size.
    opts.drop_hole_faces = true;
    auto level_images = convert::lod_geometry_images(m.mesh, map->S, image, a.lods, geometry_image_options(a));
    if (!level_images.ok()) return print_error(with_file(level_images.status(), a.mesh));
    ProgressRenderer progress(a.quiet, file_stem(a.mesh));
    auto built = convert::build_gltf_lods(level_images.value(), opts, progress.callback());
    progress.finish();
    if (!built.ok()) return print_error(built.status());
    lods = std::move(built).value();
    auto written = convert::write_gltf_lods(gltf_prefix(a.output), lods);
    if (!written.ok()) return print_error(written.status());
    lod_paths = std::move(written).value();
    gltf_seconds = gltf_time.seconds();
    if (cancel_requested()) return print_error(cancelled_status());
    if (a.psnr_samples > 0) {
      Stopwatch t;
      RemeshErrorOptions opts_err;
      opts_err.samples = a.psnr_samples;
      for (const convert::GltfLodLevel& level : lods.levels) {
        const convert::GltfMesh& d = level.primitive.decoded.mesh;
        TriMesh decoded{d.V, d.F};
        // The levels leave the holes open: every face of the file counts.
        lod_errors.push_back(remesh_error(m.mesh, decoded, opts_err));
        if (cancel_requested()) return print_error(cancelled_status());
      }
      gltf_psnr_seconds = t.seconds();
    }
  }
  // Catmull-Clark cage + displacement atlas: OUT_cage.obj, OUT_disp.exr.
  CageOutput cage_out;
  if (a.cage > 0) {
    ProgressRenderer progress(a.quiet, file_stem(a.mesh));
    auto built = build_cage(m.mesh, map->S, a, gltf_prefix(a.output), progress.callback());
    progress.finish();
    if (!built.ok()) return print_error(with_file(built.status(), a.mesh));
    cage_out = std::move(built).value();
  }
  const double wall_seconds = wall.seconds();

  if (!a.report.empty()) {
    Json j;
    j["input"] = a.mesh;
    j["sphere_map"] = a.sphere;
    j["output"] = a.output;
    if (!a.remesh.empty()) j["remesh"] = a.remesh;
    j["V"] = m.mesh.V.rows();
    j["F"] = m.mesh.F.rows();
    j["size"] = a.size;
    j["positions"] = a.positions;
    j["layout"] = "octahedral";
    j["texels_in_holes"] = image.texels_in_holes;
    j["previews"] = previews.value();
    j["remesh_V"] = remesh.V.rows();
    j["remesh_F"] = remesh.F.rows();
    if (a.psnr_samples > 0) {
      j["psnr_db"] = number_or_null(err.psnr);
      j["rms"] = err.rms;
      j["rms_forward"] = err.rms_forward;
      j["rms_backward"] = err.rms_backward;
      j["max_distance"] = err.max_distance;
      j["bbox_diag"] = err.peak;
      j["psnr_excludes_hole_faces"] = has_holes;
      if (has_holes) j["psnr_db_all_faces"] = number_or_null(err_all.psnr);
      j["psnr_samples"] = a.psnr_samples;
    }
    if (a.lods > 0) {
      Json levels = Json::array();
      for (std::size_t k = 0; k < lods.levels.size(); ++k) {
        const convert::GltfLodLevel& level = lods.levels[k];
        Json l;
        l["file"] = lod_paths.levels[k];
        l["bytes"] = file_bytes(lod_paths.levels[k]);
        l["draco_bytes"] = level.primitive.bytes.size();
        l["size"] = level.image_size;
        l["V"] = level.primitive.decoded.mesh.V.rows();
        l["F"] = level.primitive.decoded.mesh.F.rows();
        l["screen_coverage"] = lods.screen_coverage[k];
        if (k < lod_errors.size()) {
          l["psnr_db"] = number_or_null(lod_errors[k].psnr);
          l["rms"] = lod_errors[k].rms;
        }
        levels.push_back(std::move(l));
      }
      j["lods"] = std::move(levels);
      j["lods_file"] = {{"file", lod_paths.combined}, {"bytes", file_bytes(lod_paths.combined)}};
      const convert::DracoQuantization& q = lods.quantization.quantization;
      j["quantization"] = {{"position_bits", q.position_bits},
                           {"normal_bits", q.normal_bits},
                           {"texcoord_bits", q.texcoord_bits},
                           {"position_step", q.position_step()},
                           {"position_max_error", lods.quantization.position_max_error},
                           {"reference_rms_error", lods.quantization.reference_rms_error},
                           {"position_error_fraction", lods.quantization.position_error_fraction}};
      j["times"]["gltf"] = gltf_seconds;
      j["times"]["gltf_psnr"] = gltf_psnr_seconds;
    }
    if (a.cage > 0) {
      j["cage"] = cage_json(cage_out);
      j["times"]["cage"] = cage_out.seconds;
      j["times"]["cage_psnr"] = cage_out.psnr_seconds;
    }
    j["times"]["read"] = read_seconds;
    j["times"]["sample"] = sample_seconds;
    j["times"]["remesh"] = remesh_seconds;
    j["times"]["write"] = write_seconds;
    j["times"]["psnr"] = psnr_seconds;
    j["times"]["wall"] = wall_seconds;
    j["version"] = kVersion;
    if (Status s = write_json_atomic(a.report, j); !s.ok()) return print_error(s);
  }
  if (!a.quiet) {
    std::printf("%s + %s -> %s (%d x %d octahedral)\n", a.mesh.c_str(), a.sphere.c_str(), a.output.c_str(), a.size,
                a.size);
    std::printf("  %lld vertices, %lld faces; remesh %lld vertices, %lld faces; %d texel%s in holes\n",
                static_cast<long long>(m.mesh.V.rows()), static_cast<long long>(m.mesh.F.rows()),
                static_cast<long long>(remesh.V.rows()), static_cast<long long>(remesh.F.rows()),
                image.texels_in_holes, image.texels_in_holes == 1 ? "" : "s");
    std::printf("  previews %s, %s\n", previews->at(0).c_str(), previews->at(1).c_str());
    if (a.psnr_samples > 0) {
      std::printf("  PSNR %.2f dB (rms %.3g, max %.3g, bbox diagonal %.4g)\n", err.psnr, err.rms, err.max_distance,
                  err.peak);
      if (has_holes)
        std::printf("  (remesh faces spanning the holes left out; with them: PSNR %.2f dB)\n", err_all.psnr);
    }
    if (a.lods > 0) {
      const convert::DracoQuantization& q = lods.quantization.quantization;
      std::printf("  glTF (Draco, %d/%d/%d bits position/normal/texcoord%s):\n", q.position_bits, q.normal_bits,
                  q.texcoord_bits, lods.quantization.reference_rms_error > 0 ? ", from the error budget" : "");
      for (std::size_t k = 0; k < lods.levels.size(); ++k) {
        const convert::GltfLodLevel& level = lods.levels[k];
        std::printf("    %s  %3d x %-3d %8lld points %8lld faces %10llu bytes", lod_paths.levels[k].c_str(),
                    level.image_size, level.image_size,
                    static_cast<long long>(level.primitive.decoded.mesh.V.rows()),
                    static_cast<long long>(level.primitive.decoded.mesh.F.rows()),
                    static_cast<unsigned long long>(file_bytes(lod_paths.levels[k])));
        if (k < lod_errors.size()) std::printf("  PSNR %.2f dB", lod_errors[k].psnr);
        std::printf("\n");
      }
      std::printf("    %s  all levels (MSFT_lod) %llu bytes\n", lod_paths.combined.c_str(),
                  static_cast<unsigned long long>(file_bytes(lod_paths.combined)));
    }
    if (a.cage > 0) {
      std::printf("  cage %s: %d quads, %d control points (fit rms %.3g); %s displacement %d x %d per quad -> %s",
                  cage_out.cage_path.c_str(), cage_out.quads, cage_out.control_points, cage_out.fit_rms,
                  cage_out.kind.c_str(), cage_out.tile, cage_out.tile, cage_out.displacement_path.c_str());
      if (cage_out.measured)
        std::printf("\n    PSNR limit surface %.2f dB, displaced %.2f dB (%lld floats stored)",
                    cage_out.limit_error.psnr, cage_out.displaced_error.psnr, cage_out.stored_floats);
      std::printf("  %.2f s\n", cage_out.seconds);
    }
    std::printf("  time: read %.2f s, sample %.3f s, remesh %.3f s, write %.2f s, PSNR %.2f s, %stotal %.2f s\n",
                read_seconds, sample_seconds, remesh_seconds, write_seconds, psnr_seconds,
                a.lods > 0 ? strprintf("glTF %.2f s + PSNR %.2f s, ", gltf_seconds, gltf_psnr_seconds).c_str() : "",
                wall_seconds);
  }
  return 0;
}

}  // namespace

void register_convert(CLI::App& app) {
  auto args = std::make_shared<ConvertArgs>();
  CLI::App* cmd = add_command(
      app, "convert", "Resample a mesh through its sphere map into an octahedral geometry image (EXR) and glTF LODs",
      "Resample a mesh through its sphere map (as written by `spherekit param`) into an N x N\n"
      "octahedral geometry image (N = 2^k+1): each texel's sphere point is located in the sphere\n"
      "map and the surface position and normal are interpolated there. Writes a float EXR\n"
      "(R,G,B = position, N.X,N.Y,N.Z = normal, face_id; ZIP; provenance in the header), and\n"
      "with --remesh the triangle mesh the image defines (holes of the mesh left open), and two\n"
      "PNG previews of the image,\n"
      "OUT_normals.png (normals as colours) and OUT_positions.png (positions in the bounding\n"
      "box as colours; texels in holes of the mesh at half brightness). Prints the remesh PSNR against the\n"
      "original (peak = bounding-box diagonal, symmetric RMS surface distance; for a mesh with\n"
      "holes without the remesh faces that have two or three texels in a hole); --report writes\n"
      "it with the timings as JSON. With --lods L it also writes L levels of detail (image sizes\n"
      "N, (N-1)/2+1, ..., each resampled and fitted at its own size; faces spanning holes of the\n"
      "mesh left out) as Draco-compressed glTF (POSITION, NORMAL, TEXCOORD_0 = texel centres\n"
      "of the image): OUT_lod0.glb ... one per level, and OUT_lods.glb with all of them (MSFT_lod,\n"
      "level 0 shown by viewers without it), OUT being -o without its extension. Position bits:\n"
      "the fewest >= --min-position-bits whose quantization error is at most a tenth of the\n"
      "measured remesh error (recorded in the glTF extras and the report, with each level's\n"
      "size and the PSNR of its decoded geometry). The mesh must be one `param` accepts and the\n"
      "map a bijection (no face flipped by the exact predicate).\n"
      "With --cage N it also fits a Catmull-Clark base cage defined on the sphere domain (the\n"
      "cube, N x N quads per face, 6N^2 quads, the same for every mesh: in a consistent\n"
      "collection cage vertex k is the same place on every member) whose limit surface\n"
      "(OpenSubdiv) best fits the mesh, writes it as OUT_cage.obj with texture coordinates, and\n"
      "samples the displacement from the limit surface to the mesh on a T x T grid per quad\n"
      "(--cage-tile T) into one float EXR texture over the cage's UVs, OUT_disp.exr, that DCC\n"
      "tools apply as is (Blender: blender -b -P scripts/blender_setup_cage.py -- OUT_cage.obj\n"
      "OUT_disp.exr OUT.blend; T = 2^L+1 for L subdivision levels; see README). It reports the PSNR of the\n"
      "bare limit surface and of the displaced one.\n"
      "With --collection DIR (instead of MESH SPHERE) every member of a consistent collection is\n"
      "converted with the same options into the folder -o: NAME.exr, NAME_normals.png,\n"
      "NAME_positions.png, NAME_lod*.glb, NAME_cage.obj,\n"
      "NAME_disp.exr per member, collection_morph.glb (one glTF, the members as morph targets),\n"
      "and convert_report.json (per member sizes and PSNRs, and per feature the texel that holds\n"
      "it in every image). All members share one layout: the same texel, cage vertex, glTF\n"
      "vertex is the same place on every member. The folder appears only when complete.\n"
      "Exit codes: 2 bad flags (e.g.\n"
      "--size not 2^k+1), 3 bad input (including a folded map), 4 I/O error.",
      "  spherekit convert bunny.obj bunny.sphere.obj -o bunny.exr\n"
      "  spherekit convert bunny.obj bunny.sphere.obj -o bunny.exr --size 129 --remesh bunny.gim.obj\n"
      "  spherekit convert igea.ply igea.sphere.obj -o igea.exr --report igea.convert.json\n"
      "  spherekit convert bunny.obj bunny.sphere.obj -o out/bunny.exr --gi 257 --lods 4\n"
      "  spherekit convert bunny.obj bunny.sphere.obj -o out/bunny.exr --cage 8 --cage-tile 33\n"
      "  spherekit convert --collection heads/ -o heads_assets/ --gi 129 --lods 3 --cage 8");
  cmd->add_option("MESH", args->mesh, "input mesh (.obj .ply .off .stl .gltf .glb)");
  cmd->add_option("SPHERE", args->sphere, "its sphere map (.obj, from `spherekit param`)");
  cmd->add_option("--collection", args->collection,
                  "instead of MESH SPHERE: convert every member of this collection folder (from `spherekit "
                  "consistent`) into the folder -o");
  cmd->add_option("-o,--output", args->output, "geometry image to write (.exr); with --collection: a folder")
      ->required();
  cmd->add_option("--size,--gi", args->size, "image size N = 2^k+1 (default 257)");
  cmd->add_option("--remesh", args->remesh, "also write the remesh defined by the image (.obj .ply)");
  cmd->add_option("--report", args->report, "also write a JSON report here");
  cmd->add_option("--positions", args->positions,
                  "texel positions: fit (least-squares fit of the surface, the lower remesh error; default) or "
                  "sampled (each texel the surface point it samples)");
  cmd->add_option("--psnr-samples", args->psnr_samples,
                  "points sampled per direction for the PSNR (0: skip it; default 400000)");
  cmd->add_option("--lods", args->lods, "also write this many glTF levels of detail (default 0: none)");
  cmd->add_option("--min-position-bits", args->budget.min_position_bits,
                  "glTF: fewest Draco position bits (default 14; more if the error budget needs them)");
  cmd->add_option("--normal-bits", args->budget.normal_bits, "glTF: Draco normal bits (default 10)");
  cmd->add_option("--min-texcoord-bits", args->budget.min_texcoord_bits,
                  "glTF: fewest Draco texture-coordinate bits (default 12)");
  cmd->add_option("--cage", args->cage,
                  "also fit a Catmull-Clark cage with N x N quads per cube face (OUT_cage.obj) and sample "
                  "its displacement map (OUT_disp.exr); default 0: none");
  cmd->add_option("--cage-tile", args->cage_tile, "displacement samples per cage-quad edge (default 17)");
  cmd->add_option("--displacement", args->displacement,
                  "scalar (along the limit normal, 1 float per sample; default) or vector (3 floats)");
  cmd->add_flag("-q,--quiet", args->quiet, "print no summary (errors still)");
  cmd->callback([args] { set_exit_code(run_convert(*args)); });
}

}  // namespace spherekit::cli
