// `spherekit param`: one mesh -> its stretch-minimizing bijective sphere map
// (parameterize_sphere, Praun & Hoppe 2003), written only when it is a bijection.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>

#include "cli_common.h"
#include "commands.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/sphere_param.h"
#include "spherekit/version.h"

namespace spherekit::cli {
namespace {

struct ParamArgs {
  std::string mesh;
  std::string output;
  std::string report;
  bool quiet = false;
  SphereParamOptions options;
};

void print_summary(const ParamArgs& a, const LoadedMesh& m, const SphereParamResult& r, double wall, double cpu,
                   double peak_mb) {
  std::printf("%s -> %s\n", a.mesh.c_str(), a.output.c_str());
  std::printf("  %d vertices, %d faces, %d hole%s filled; base %d vertices, %d optimization passes\n",
              m.check.vertices, m.check.faces, r.holes_filled, r.holes_filled == 1 ? "" : "s", r.base_vertices,
              r.optimization_passes);
  std::printf("  efficiency %.4f, L2 stretch %.4f, Linf stretch %.4g, flipped faces %d, winding %.6f\n", r.efficiency,
              r.l2_stretch, r.linf_stretch, r.flipped_faces, r.winding);
  std::printf("  time: simplify %.2f s, refine %.2f s, total %.2f s (wall %.2f s, CPU %.2f s), peak memory %.0f MB\n",
              r.times.simplify, r.times.refine, r.times.total, wall, cpu, peak_mb);
}

int run_param(const ParamArgs& a) {
  Stopwatch wall;
  auto loaded = load_mesh_checked(a.mesh, /*allow_boundary=*/true, /*repair=*/false);
  if (!loaded.ok()) return print_error(loaded.status());
  const LoadedMesh& m = loaded.value();

  ProgressRenderer progress(a.quiet);
  Result<SphereParamResult> result = [&] {
    ComputeScope graceful_cancel;
    return parameterize_sphere(m.mesh, a.options, progress.callback());
  }();
  progress.finish();
  if (!result.ok()) return print_error(with_file(result.status(), a.mesh));
  if (cancel_requested()) return print_error(cancelled_status());
  const SphereParamResult& r = result.value();

  // A map that is not a bijection is a failure, never an output: later stages (resampling,
  // correspondence) silently produce garbage from a folded map.
  if (r.flipped_faces != 0)
    return print_error(Status(ErrorCode::SolverFailed,
                              strprintf("%s: the map has %d flipped faces (not bijective); nothing written",
                                        a.mesh.c_str(), r.flipped_faces)));

  Stopwatch write_time;
  if (Status s = formats::write_sphere_map(a.output, m.mesh, r.map); !s.ok()) return print_error(s);
  const double write_seconds = write_time.seconds();

  const double wall_seconds = wall.seconds();
  const double cpu = cpu_seconds();
  const double peak_mb = peak_rss_mb();
  if (!a.report.empty()) {
    Json j;
    j["input"] = a.mesh;
    j["output"] = a.output;
    j["V"] = m.check.vertices;
    j["F"] = m.check.faces;
    const Json measures = sphere_param_result_json(r);  // named: items() does not extend its lifetime
    for (const auto& [key, value] : measures.items()) j[key] = value;
    j["times"]["read"] = m.read_seconds;
    j["times"]["write"] = write_seconds;
    j["times"]["wall"] = wall_seconds;
    j["cpu_seconds"] = cpu;
    j["peak_rss_mb"] = peak_mb;
    j["options"] = sphere_param_options_json(a.options);
    j["version"] = kVersion;
    j["provenance"] = Json{{"library_version", r.map.provenance.library_version},
                           {"method", r.map.provenance.method},
                           {"options_digest", r.map.provenance.options_digest},
                           {"seed", r.map.provenance.seed}};
    if (Status s = write_json_atomic(a.report, j); !s.ok()) return print_error(s);
  }
  if (!a.quiet) print_summary(a, m, r, wall_seconds, cpu, peak_mb);
  return 0;
}

}  // namespace

void register_param(CLI::App& app) {
  auto args = std::make_shared<ParamArgs>();
  CLI::App* cmd = add_command(
      app, "param", "Map a genus-0 mesh bijectively onto the unit sphere (stretch-minimizing)",
      "Map a genus-0 triangle mesh bijectively onto the unit sphere, minimizing the L2 stretch of\n"
      "the map sphere -> surface (Praun & Hoppe 2003: progressive mesh down to a tetrahedron, then\n"
      "coarse-to-fine vertex splits with stretch optimization). Holes are closed with low-weight\n"
      "faces that do not appear in the output. The sphere map is an OBJ with the mesh's vertex\n"
      "order and faces whose vertices are the unit-sphere points. It is written only if the map is\n"
      "a bijection (0 flipped faces by exact predicate; otherwise exit 5). Progress goes to stderr,\n"
      "a summary to stdout; --report writes the measures, per-stage times and peak memory as JSON.",
      "  spherekit param spot.obj -o spot.sphere.obj\n"
      "  spherekit param bunny.obj -o bunny.sphere.obj --report bunny.json --effort 3\n"
      "  spherekit param igea.ply -o igea.sphere.obj --threads 2 --quiet");
  cmd->add_option("MESH", args->mesh, "input mesh (.obj .ply .off .stl .gltf .glb)")->required();
  cmd->add_option("-o,--output", args->output, "sphere map to write (.obj)")->required();
  cmd->add_option("--report", args->report, "also write a JSON report here");
  cmd->add_flag("-q,--quiet", args->quiet, "print neither progress nor the summary (errors still)");
  add_sphere_param_options(*cmd, args->options);
  cmd->callback([args] { set_exit_code(run_param(*args)); });
}

}  // namespace spherekit::cli
