// `spherekit convert`: a mesh and its sphere map -> an octahedral geometry image (float EXR),
// optionally the remesh it defines (OBJ), with the remesh PSNR against the original.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "cli_common.h"
#include "commands.h"
#include "spherekit/convert/geometry_image_exr.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/geometry_image.h"
#include "spherekit/version.h"

namespace spherekit::cli {
namespace {

struct ConvertArgs {
  std::string mesh;
  std::string sphere;
  std::string output;
  std::string remesh;
  std::string report;
  int size = 257;
  int psnr_samples = RemeshErrorOptions{}.samples;
  bool quiet = false;
};

Json number_or_null(double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); }

int run_convert(const ConvertArgs& a) {
  // Flags first: a bad size must fail before anything is read or written.
  if (!is_geometry_image_size(a.size) || a.size > 16385)
    return print_error(Status(ErrorCode::InvalidArgument,
                              strprintf("--size %d is not 2^k+1 (e.g. 65, 129, 257, 513)", a.size)));
  if (a.psnr_samples < 0)
    return print_error(Status(ErrorCode::InvalidArgument, "--psnr-samples must be >= 0"));

  Stopwatch wall;
  auto loaded = load_mesh(a.mesh);
  if (!loaded.ok()) return print_error(loaded.status());
  const LoadedMesh& m = loaded.value();
  Stopwatch read_sphere;
  auto map = formats::read_sphere_map(a.sphere, m.mesh);
  if (!map.ok()) return print_error(with_file(map.status(), a.sphere));
  const double read_seconds = m.read_seconds + read_sphere.seconds();

  Stopwatch sample_time;
  auto sampled = sample_geometry_image(m.mesh, map->S, a.size);
  if (!sampled.ok()) return print_error(with_file(sampled.status(), a.mesh));
  const GeometryImage& image = sampled.value();
  const double sample_seconds = sample_time.seconds();
  if (cancel_requested()) return print_error(cancelled_status());

  Stopwatch remesh_time;
  const TriMesh remesh = geometry_image_mesh(image);
  const double remesh_seconds = remesh_time.seconds();

  Stopwatch write_time;
  if (Status s = convert::write_geometry_image_exr(a.output, image, {a.mesh, a.sphere}); !s.ok())
    return print_error(s);
  if (!a.remesh.empty())
    if (Status s = formats::write_mesh(a.remesh, remesh); !s.ok()) return print_error(s);
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
    err = remesh_error(m.mesh, remesh, opts, geometry_image_hole_faces(image));
    if (has_holes) err_all = remesh_error(m.mesh, remesh, opts);
    psnr_seconds = psnr_time.seconds();
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
    j["layout"] = "octahedral";
    j["texels_in_holes"] = image.texels_in_holes;
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
    if (a.psnr_samples > 0) {
      std::printf("  PSNR %.2f dB (rms %.3g, max %.3g, bbox diagonal %.4g)\n", err.psnr, err.rms, err.max_distance,
                  err.peak);
      if (has_holes)
        std::printf("  (remesh faces spanning the holes left out; with them: PSNR %.2f dB)\n", err_all.psnr);
    }
    std::printf("  time: read %.2f s, sample %.3f s, remesh %.3f s, write %.2f s, PSNR %.2f s, total %.2f s\n",
                read_seconds, sample_seconds, remesh_seconds, write_seconds, psnr_seconds, wall_seconds);
  }
  return 0;
}

}  // namespace

void register_convert(CLI::App& app) {
  auto args = std::make_shared<ConvertArgs>();
  CLI::App* cmd = add_command(
      app, "convert", "Resample a mesh through its sphere map into an octahedral geometry image (EXR)",
      "Resample a mesh through its sphere map (as written by `spherekit param`) into an N x N\n"
      "octahedral geometry image (N = 2^k+1): each texel's sphere point is located in the sphere\n"
      "map and the surface position and normal are interpolated there. Writes a float EXR\n"
      "(R,G,B = position, N.X,N.Y,N.Z = normal, face_id; ZIP; provenance in the header), and\n"
      "with --remesh the triangle mesh the image defines. Prints the remesh PSNR against the\n"
      "original (peak = bounding-box diagonal, symmetric RMS surface distance); --report writes\n"
      "it with the timings as JSON. Exit codes: 2 bad flags (e.g. --size not 2^k+1), 3 bad\n"
      "input, 4 I/O error.",
      "  spherekit convert bunny.obj bunny.sphere.obj -o bunny.exr\n"
      "  spherekit convert bunny.obj bunny.sphere.obj -o bunny.exr --size 129 --remesh bunny.gim.obj\n"
      "  spherekit convert igea.ply igea.sphere.obj -o igea.exr --report igea.convert.json");
  cmd->add_option("MESH", args->mesh, "input mesh (.obj .ply .off .stl .gltf .glb)")->required();
  cmd->add_option("SPHERE", args->sphere, "its sphere map (.obj, from `spherekit param`)")->required();
  cmd->add_option("-o,--output", args->output, "geometry image to write (.exr)")->required();
  cmd->add_option("--size", args->size, "image size N = 2^k+1 (default 257)");
  cmd->add_option("--remesh", args->remesh, "also write the remesh defined by the image (.obj .ply)");
  cmd->add_option("--report", args->report, "also write a JSON report here");
  cmd->add_option("--psnr-samples", args->psnr_samples,
                  "points sampled per direction for the PSNR (0: skip it; default 400000)");
  cmd->add_flag("-q,--quiet", args->quiet, "print no summary (errors still)");
  cmd->callback([args] { set_exit_code(run_convert(*args)); });
}

}  // namespace spherekit::cli
