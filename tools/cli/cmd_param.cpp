// `spherekit param`: one mesh -> its stretch-minimizing bijective sphere map
// (parameterize_sphere, Praun & Hoppe 2003), written only when it is a bijection.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>

#include "cli_common.h"
#include "commands.h"
#include "spherekit/pipeline/param.h"

namespace spherekit::cli {
namespace {

struct ParamArgs {
  pipeline::ParamJob job;
  std::string report;
  bool quiet = false;
  ConstrainedFlags flags;
  bool regularizer_given = false;  // --regularizer-weight on the command line
  bool hole_shape_given = false;   // --hole-shape-weight on the command line
};

void print_summary(const pipeline::ParamResult& p) {
  const pipeline::ParamJob& a = p.job;
  const double cpu = cpu_seconds(), peak_mb = peak_rss_mb();
  if (p.constrained) {
    const ConstrainedParamResult& r = *p.constrained;
    std::printf("%s -> %s (%d features on their targets)\n", a.mesh.c_str(), a.output.c_str(), p.features);
    std::printf("  network: %d paths, total length %.4g, max length/geodesic %.3f, %d swirls fixed, %d flips, %d Steiner vertices%s\n",
                r.network.paths, r.network.total_length, r.network.max_ratio, r.network.swirls_fixed, r.network.edge_flips,
                r.network.steiner_vertices,
                r.network.auxiliary_features ? format_text(", %d auxiliary features", r.network.auxiliary_features).c_str() : "");
    std::printf("  efficiency %.4f, L2 stretch %.4f, flipped faces %d, winding %.6f, max feature error %.2g rad\n",
                r.efficiency, r.l2_stretch, r.flipped_faces, r.winding, r.max_feature_angle);
    std::printf("  time: network %.2f s, simplify %.2f s, refine %.2f s, total %.2f s (wall %.2f s, CPU %.2f s), peak memory %.0f MB\n",
                r.times.network, r.times.simplify, r.times.refine, r.times.total, p.wall_seconds, cpu, peak_mb);
    return;
  }
  const SphereParamResult& r = *p.unconstrained;
  std::printf("%s -> %s\n", a.mesh.c_str(), a.output.c_str());
  std::printf("  %d vertices, %d faces, %d hole%s filled; base %d vertices, %d optimization passes\n",
              p.input.check.vertices, p.input.check.faces, r.holes_filled, r.holes_filled == 1 ? "" : "s",
              r.base_vertices, r.optimization_passes);
  std::printf("  efficiency %.4f, L2 stretch %.4f, Linf stretch %.4g, flipped faces %d, winding %.6f\n", r.efficiency,
              r.l2_stretch, r.linf_stretch, r.flipped_faces, r.winding);
  std::printf("  time: simplify %.2f s, refine %.2f s, total %.2f s (wall %.2f s, CPU %.2f s), peak memory %.0f MB\n",
              r.times.simplify, r.times.refine, r.times.total, p.wall_seconds, cpu, peak_mb);
}

int run_param(const ParamArgs& a) {
  if (Status s = require_output_folders({a.job.output, a.report, a.job.dump_network}); !s.ok()) return print_error(s);
  pipeline::ParamJob job = a.job;
  job.constrained = a.flags.constrained;
  // A constrained map is a collection stage's map (one `consistent` or `add` would make):
  // it takes the collection stages' anti-cruft and hole shape weights unless the flags say
  // otherwise (and, like them, no coarse-layout precision, SphereParamOptions::precise_layout,
  // and no simplification in blocks, block_vertices).
  if (!job.features.empty() && !a.regularizer_given) job.options.regularizer_weight = kCollectionRegularizerWeight;
  if (!job.features.empty() && !a.hole_shape_given) job.options.hole_shape_weight = kCollectionHoleShapeWeight;
  if (!job.features.empty()) job.options.precise_layout = false;
  if (!job.features.empty()) job.options.block_vertices = 0;
  ProgressRenderer progress(a.quiet);
  auto r = [&] {
    ComputeScope graceful_cancel;
    return pipeline::map_mesh(job, progress.callback());
  }();
  progress.finish();
  if (cancel_requested()) return print_error(cancelled_status());
  if (!r.ok()) return print_error(r.status());
  if (!a.report.empty())
    if (Status s = write_json_atomic(a.report, pipeline::to_json(r.value())); !s.ok()) return print_error(s);
  if (!a.quiet) print_summary(r.value());
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
      "a summary to stdout; --report writes the measures, per-stage times and peak memory as JSON.\n"
      "\n"
      "With --features F.lm.txt (`name vertex` lines) and --targets T.txt (`name x y z` unit\n"
      "vectors, same names) the map is constrained (Asirvatham, Praun, Hoppe 2005 §4): every\n"
      "feature vertex lands exactly on its target. A path network links the features on the\n"
      "mesh and on the sphere; --dump-network writes it (mesh paths and sphere arcs) as OBJ\n"
      "polylines, and the report gives its total length, worst length/geodesic ratio and the\n"
      "swirls it fixed.",
      "  spherekit param spot.obj -o spot.sphere.obj\n"
      "  spherekit param bunny.obj -o bunny.sphere.obj --report bunny.json --effort 3\n"
      "  spherekit param igea.ply -o igea.sphere.obj --threads 2 --quiet\n"
      "  spherekit param cat2.obj --features cat2.lm.txt --targets cat0.targets.txt -o cat2.sphere.obj");
  cmd->add_option("MESH", args->job.mesh, "input mesh (.obj .ply .off .stl .gltf .glb)")->required();
  cmd->add_option("-o,--output", args->job.output, "sphere map to write (.obj)")->required();
  cmd->add_option("--report", args->report, "also write a JSON report here");
  cmd->add_flag("-q,--quiet", args->quiet, "print neither progress nor the summary (errors still)");
  add_sphere_param_options(*cmd, args->job.options);
  cmd->add_option("--features", args->job.features, "feature vertices (`name vertex` lines): constrained map");
  cmd->add_option("--targets", args->job.targets, "their sphere points (`name x y z` unit vectors)");
  cmd->add_option("--dump-network", args->job.dump_network, "write the path network here (.obj polylines)");
  add_constrained_flags(*cmd, args->flags);
  cmd->get_option("--regularizer-weight")
      ->description("weight of the term against collapsed sphere triangles (shape-defining); with --features "
                    "the collection stages' 1e-4 unless given");
  cmd->get_option("--hole-shape-weight")
      ->description("weight of the shape term that keeps hole faces from becoming slivers (shape-defining); with "
                    "--features the collection stages' 0.3 unless given");
  cmd->callback([args, cmd] {
    args->regularizer_given = cmd->count("--regularizer-weight") + cmd->count("--regularizer_weight") > 0;
    args->hole_shape_given = cmd->count("--hole-shape-weight") + cmd->count("--hole_shape_weight") > 0;
    set_exit_code(run_param(*args));
  });
}

}  // namespace spherekit::cli
