// `spherekit eval-surface`: the distance between two surfaces by the routine every PSNR in
// SphereKit's reports uses (remesh_error, geometry_image.h), so that a mesh made elsewhere (e.g.
// Blender's evaluation of a cage + displacement texture, scripts/blender_setup_cage.py) is
// measured exactly as convert measures its own outputs.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>

#include "cli_common.h"
#include "commands.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/geometry_image.h"

namespace spherekit::cli {
namespace {

struct EvalSurfaceArgs {
  std::string original, other;
  int samples = 400000;
  unsigned long long seed = 1;
  bool json = false;
};

int run_eval_surface(const EvalSurfaceArgs& a) {
  if (a.samples < 1000 || a.samples > 100000000)
    return print_error(Status(ErrorCode::InvalidArgument, format_text("--samples %d is not in 1000..1e8", a.samples)));
  formats::ReadOptions lenient;
  lenient.polygons = formats::PolygonPolicy::Triangulate;
  auto original = formats::read_mesh(a.original, lenient);
  if (!original.ok()) return print_error(with_file(original.status(), a.original));
  auto other = formats::read_mesh(a.other, lenient);
  if (!other.ok()) return print_error(with_file(other.status(), a.other));
  for (const auto* m : {&original, &other})
    if ((*m)->F.rows() == 0)
      return print_error(Status(ErrorCode::InvalidInput, (m == &original ? a.original : a.other) + ": no faces"));
  RemeshErrorOptions opts;
  opts.samples = a.samples;
  opts.seed = a.seed;
  const RemeshError e = remesh_error(original.value(), other.value(), opts);
  if (a.json) {
    Json j = {{"original", a.original}, {"other", a.other}, {"samples", a.samples}, {"seed", a.seed},
              {"peak", e.peak}, {"rms_forward", e.rms_forward}, {"rms_backward", e.rms_backward}, {"rms", e.rms},
              {"max_distance", e.max_distance}, {"psnr_db", number_or_null(e.psnr)}};
    std::printf("%s\n", j.dump().c_str());
  } else {
    std::printf("%s against %s: PSNR %.2f dB (peak %.6g = bounding-box diagonal, RMS %.4g: forward %.4g, backward "
                "%.4g; max %.4g)\n",
                a.other.c_str(), a.original.c_str(), e.psnr, e.peak, e.rms, e.rms_forward, e.rms_backward,
                e.max_distance);
  }
  return 0;
}

}  // namespace

void register_eval_surface(CLI::App& app) {
  auto args = std::make_shared<EvalSurfaceArgs>();
  CLI::App* cmd = add_command(
      app, "eval-surface", "Distance and PSNR between two surfaces, as convert measures its outputs",
      "Measures OTHER against ORIGINAL with the routine of every PSNR in convert's reports: points\n"
      "sampled uniformly by area on each surface (--samples per direction, deterministic in --seed),\n"
      "exact point-to-triangle distances to the other, d = the larger of the two RMS distances,\n"
      "PSNR = 20 log10(bounding-box diagonal of ORIGINAL / d). Polygon meshes are fan-triangulated.\n"
      "Use it on a mesh another tool made from SphereKit's assets, e.g. Blender's evaluated cage +\n"
      "displacement (blender -b -P scripts/blender_setup_cage.py -- ... --export-obj EVAL.obj).",
      "  spherekit eval-surface spot.obj spot_eval.obj\n"
      "  spherekit eval-surface spot.obj spot_eval.obj --samples 100000 --json");
  cmd->add_option("ORIGINAL", args->original, "the reference surface (its diagonal is the peak)")->required();
  cmd->add_option("OTHER", args->other, "the surface to measure")->required();
  cmd->add_option("--samples", args->samples, "points sampled per direction (default 400000)");
  cmd->add_option("--seed", args->seed, "sampling seed (default 1)");
  cmd->add_flag("--json", args->json, "print one JSON line instead of text");
  cmd->callback([args] { set_exit_code(run_eval_surface(*args)); });
}

}  // namespace spherekit::cli
