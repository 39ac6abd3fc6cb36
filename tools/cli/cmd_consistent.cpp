// `spherekit consistent`: the consistent parameterization of a collection (paper §3) into a
// collection folder; `spherekit add`: a new mesh mapped to an existing collection's feature
// locations (paper §5). The jobs are spherekit::pipeline's (collection.h): this file parses
// flags, calls them and prints.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli_common.h"
#include "commands.h"
#include "help_text.h"
#include "spherekit/pipeline/collection.h"

namespace spherekit::cli {
namespace {

struct ConsistentArgs {
  pipeline::MakeCollectionJob job;
  std::string report;
  bool quiet = false;
  SphereParamOptions sphere = collection_sphere_options();
  ConstrainedFlags flags;
};

int run_consistent(const ConsistentArgs& a) {
  Stopwatch wall;
  if (Status s = require_output_folders({a.report}); !s.ok()) return print_error(s);
  pipeline::MakeCollectionJob job = a.job;
  job.options.constrained = a.flags.resolve(a.sphere);
  job.options.threads = a.sphere.threads;
  ProgressRenderer progress(a.quiet);
  // Said before the minutes of work start (the summary comes at the end), on standard output:
  // standard error holds progress and, on failure, the one error line.
  if (!a.quiet)
    std::printf("consistent parameterization of %s into %s\n",
                 job.meshes.empty() ? "the built-in samples" : (std::to_string(job.meshes.size()) + " meshes").c_str(),
                 job.output.c_str());
  std::fflush(stdout);
  auto r = [&] {
    ComputeScope graceful_cancel;
    return pipeline::make_collection(job, progress.callback(), [] { return !cancel_requested(); });
  }();
  progress.finish();
  if (cancel_requested()) return print_error(cancelled_status());
  if (!r.ok()) return print_error(r.status());
  print_collection_warning(r.value());
  const double wall_seconds = wall.seconds();
  if (!a.report.empty()) {
    Json rep = formats::collection_manifest_json(r->manifest);
    rep["output"] = job.output;
    // The manifest holds neither times nor the thread count (issue 23); the report does.
    rep["times"] = pipeline::consistent_times_json(r.value());
    rep["times"]["wall"] = wall_seconds;
    rep["options"]["threads"] = job.options.threads;
    rep["cpu_seconds"] = cpu_seconds();
    rep["peak_rss_mb"] = peak_rss_mb();
    // Given landmarks most likely on another feature (also printed as warnings).
    rep["landmark_warnings"] = r->landmark_warnings;
    if (Status s = write_json_atomic(a.report, rep); !s.ok()) return print_error(s);
  }
  if (!a.quiet) print_consistent_summary(r.value(), job.output, wall_seconds);
  return 0;
}

struct AddArgs {
  pipeline::AddToCollectionJob job;
  std::string report;
  bool quiet = false;
  SphereParamOptions sphere = collection_sphere_options();
  ConstrainedFlags flags;
};

int run_add(const AddArgs& a) {
  if (Status s = require_output_folders({a.report}); !s.ok()) return print_error(s);
  pipeline::AddToCollectionJob job = a.job;
  job.options = a.flags.resolve(a.sphere);
  job.seed_given = a.sphere.seed != SphereParamOptions{}.seed;
  ProgressRenderer progress(a.quiet, job.name.empty() ? file_stem(job.mesh) : job.name);
  auto r = [&] {
    ComputeScope graceful_cancel;
    return pipeline::add_to_collection(job, progress.callback());
  }();
  progress.finish();
  if (cancel_requested()) return print_error(cancelled_status());
  if (!r.ok()) return print_error(r.status());
  for (const std::string& w : r->landmark_warnings) std::fprintf(stderr, "spherekit: warning: %s\n", w.c_str());
  if (!a.report.empty()) {
    // Per-task measures (read by `submit --verify`): peak memory is per process.
    Json rep{{"name", r->name}, {"map", r->map_path}, {"collection", job.dir}, {"registered", r->registered}};
    if (!r->registered) rep["times"] = pipeline::map_times_json(r->map);
    rep["times"]["wall"] = r->wall_seconds;
    rep["cpu_seconds"] = cpu_seconds();
    rep["peak_rss_mb"] = peak_rss_mb();
    rep["landmark_warnings"] = r->landmark_warnings;
    if (Status s = write_json_atomic(a.report, rep); !s.ok()) return print_error(s);
  }
  if (!a.quiet) print_add_summary(r.value(), job);
  return 0;
}

}  // namespace

void register_consistent(CLI::App& app) {
  auto args = std::make_shared<ConsistentArgs>();
  CLI::App* cmd = add_command(
      app, "consistent", "Map a collection of meshes consistently onto one sphere (features coincide)",
      help::kConsistent, help::kConsistentExamples);
  cmd->add_option("MESH", args->job.meshes, "input meshes (genus 0, holes allowed)");
  cmd->add_option("-o,--output", args->job.output, "collection folder to write")->required();
  cmd->add_option("--features", args->job.features, "feature files, one per mesh in order (default: MESH stem + .lm.txt)");
  cmd->add_option("--reference", args->job.reference, "mesh giving the initial locations (file stem or index; default the first)");
  cmd->add_option("--remesh-size", args->job.options.remesh_size, "step 3 grid side (2^k+1)")
      ->capture_default_str()
      ->check(CLI::IsMember({9, 17, 33, 65, 129, 257, 513}));
  cmd->add_flag("!--no-refine-locations", args->job.options.refine_locations,
                "stop after step 2 (locations from the reference alone)");
  cmd->add_flag("!--no-refine", args->job.options.refine_locations)->group("");  // the earlier spelling
  cmd->add_flag("!--no-refine-correspondence", args->job.options.refine_correspondence,
                "keep the step-6 maps (no correspondence refinement against the reference)");
  cmd->add_option("--efficiency-retry", args->job.options.efficiency_retry,
                  "make a member's constrained map again as the unconstrained stage would where it keeps less than this "
                  "fraction of its unconstrained efficiency (0: never)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--report", args->report, "also write a JSON report here");
  cmd->add_flag("-q,--quiet", args->quiet, "print neither progress nor the summary (errors still)");
  add_sphere_param_options(*cmd, args->sphere);
  add_constrained_flags(*cmd, args->flags);
  cmd->callback([args] { set_exit_code(run_consistent(*args)); });

  auto add_args = std::make_shared<AddArgs>();
  CLI::App* add = add_command(
      app, "add", "Map a new mesh into an existing collection (its features on the collection's)",
      help::kAdd, help::kAddExamples);
  add->add_option("DIR", add_args->job.dir, "collection folder")->required();
  add->add_option("MESH", add_args->job.mesh, "mesh to add")->required();
  add->add_option("--features", add_args->job.features, "its feature file (default: MESH stem + .lm.txt)");
  add->add_option("--name", add_args->job.name, "member name (default: the mesh's file stem)");
  add->add_flag("--replace", add_args->job.replace, "map again if the collection has a member of that name");
  add->add_flag("!--no-refine-correspondence", add_args->job.refine_correspondence,
                "do not refine the new map against the reference member (done when the collection was made with it)");
  add->add_option("--map", add_args->job.map,
                  "register this sphere map (computed elsewhere, e.g. by 'param --features F.lm.txt --targets "
                  "DIR/features.txt') instead of computing one; verified: same vertices and faces, bijective by the "
                  "exact predicate, every feature on its location");
  add->add_option("--efficiency-retry", add_args->job.efficiency_retry,
                  "as for consistent (default: the collection's setting)")
      ->check(CLI::Range(0.0, 1.0))
      ->each([add_args](const std::string&) { add_args->job.efficiency_retry_given = true; });
  add->add_option("--report", add_args->report, "also write a JSON report (times, peak memory) here");
  add->add_flag("-q,--quiet", add_args->quiet, "print neither progress nor the summary (errors still)");
  add_sphere_param_options(*add, add_args->sphere);
  add_constrained_flags(*add, add_args->flags);
  add->callback([add_args] { set_exit_code(run_add(*add_args)); });
}

}  // namespace spherekit::cli
