// `spherekit submit`: a large consistent collection as independent jobs (issue 23): F from a
// subset of k members (`consistent`), every other member mapped to F as its own task (`add`),
// optional conversion, a final check; run locally (default) or as Slurm job arrays
// (--scheduler slurm). The plan, the job scripts and the state checks are the scheduler
// library's (scheduler/collection_plan.h, slurm.h, run_plan.h; submit_jobs.h: the subset choice
// and the final check); this file parses flags and prints. `submit --verify PLAN` is the last task.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli_common.h"
#include "commands.h"
#include "help_text.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/collection.h"
#include "spherekit/scheduler/submit_jobs.h"

namespace spherekit::cli {
namespace {

namespace sch = spherekit::scheduler;

struct SubmitArgs {
  std::string output, work, scheduler = "local", subset_by = "farthest", verify;
  std::vector<std::string> meshes, features;
  sch::SubsetRequest subset;  // its fields bound to the --subset* and --joint-memory-mb flags
  sch::RunRequest run;        // the Slurm flags, --poll, --timeout
  int cpus_per_task = 0, threads = 1;
  int effort = -1, remesh_size = 0;
  long long seed = -1;
  std::string convert, convert_args;
  bool quiet = false;
};

// The plan's final task: the library checks and writes submit_report.json; this prints.
int run_verify(const std::string& plan_path, bool quiet) {
  auto v = sch::verify_plan(plan_path);
  if (!v.ok()) return print_error(v.status());
  if (!v->ok()) return print_error(v->failure());
  if (!quiet)
    std::printf("%s: %zu members, every map a bijection; max task peak memory %.0f MB\n", v->collection.c_str(),
                v->listed, v->max_task_peak_rss_mb);
  return 0;
}

int run_submit(const SubmitArgs& a) {
  if (!a.verify.empty()) return run_verify(a.verify, a.quiet);
  Stopwatch wall;
  if (a.output.empty()) return print_error(Status(ErrorCode::InvalidArgument, "-o DIR is required"));
  if (a.meshes.size() < 1) return print_error(Status(ErrorCode::InvalidArgument, "no meshes"));
  if (!a.features.empty() && a.features.size() != a.meshes.size())
    return print_error(Status(ErrorCode::InvalidArgument,
                              format_text("%zu meshes but %zu --features files", a.meshes.size(), a.features.size())));
  if (Status s = formats::require_staged_folder_target(a.output, formats::kCollectionManifest); !s.ok())
    return print_error(s);
  sch::CollectionPlanOptions o;
  o.exe = sch::absolute_path("/proc/self/exe");
  o.collection = sch::absolute_path(a.output);
  o.work_dir = a.work.empty() ? o.collection + ".jobs" : sch::absolute_path(a.work);
  if (Status s = sch::add_members(o, a.meshes, a.features); !s.ok()) return print_error(s);
  const int n = static_cast<int>(o.meshes.size());
  const int remesh = a.remesh_size > 0 ? a.remesh_size : 65;
  sch::SubsetRequest req = a.subset;
  req.farthest = a.subset_by != "first";
  req.remesh_size = remesh;
  auto choice = sch::choose_subset(o, req);
  if (!choice.ok()) return print_error(choice.status());
  o.subset = choice->subset;
  const int k = static_cast<int>(o.subset.size()), k_memory = choice->k_memory;
  if (a.effort >= 0) o.map_args.insert(o.map_args.end(), {"--effort", std::to_string(a.effort)});
  if (a.seed >= 0) o.map_args.insert(o.map_args.end(), {"--seed", std::to_string(a.seed)});
  if (a.remesh_size > 0) o.consistent_args = {"--remesh-size", std::to_string(a.remesh_size)};
  if (!a.convert.empty()) {
    o.convert_output = sch::absolute_path(a.convert);
    o.convert_args = words(a.convert_args);
  }
  o.threads = a.threads;
  o.cpus_per_task = a.cpus_per_task > 0 ? a.cpus_per_task : a.threads;
  auto plan = sch::plan_collection(o);
  if (!plan.ok()) return print_error(plan.status());
  if (Status s = sch::write_plan(plan.value()); !s.ok()) return print_error(s);
  if (!a.quiet) print_submit_plan(o, k_memory, a.subset.joint_memory_mb, remesh, a.scheduler);
  ProgressFn keep_going = [](const ProgressEvent&) { return !cancel_requested(); };
  Status s;
  {
    ComputeScope graceful_cancel;
    sch::RunRequest run = a.run;
    run.slurm = a.scheduler == "slurm";
    s = sch::run_plan(plan.value(), run, keep_going);
  }
  if (!s.ok()) return print_error(s);
  if (!a.quiet) {
    auto rep = formats::read_file(o.work_dir + "/submit_report.json");
    Json j = rep.ok() ? Json::parse(rep.value(), nullptr, false) : Json();
    std::printf("collection %s: %d members (F from %d), %s, wall %.1f s, max task peak memory %.0f MB\n",
                o.collection.c_str(), n, k, a.scheduler.c_str(), wall.seconds(),
                j.is_object() ? j.value("max_task_peak_rss_mb", 0.0) : 0.0);
  }
  return 0;
}

}  // namespace

void register_submit(CLI::App& app) {
  auto args = std::make_shared<SubmitArgs>();
  CLI::App* cmd = add_command(
      app, "submit", "Build a large consistent collection as independent jobs (locally or on Slurm)",
      help::kSubmit, help::kSubmitExamples);
  cmd->add_option("MESH", args->meshes, "member meshes (each with NAME.lm.txt beside it, or --features)");
  cmd->add_option("-o,--output", args->output, "collection folder to write");
  cmd->add_option("--features", args->features, "feature files, one per mesh in order");
  cmd->add_option("--subset", args->subset.k, "k: members that decide F (default: min(n, 12, memory bound))");
  cmd->add_option("--subset-by", args->subset_by, "how to choose them: farthest (spread over shapes) or first")
      ->check(CLI::IsMember({"farthest", "first"}))
      ->capture_default_str();
  cmd->add_option("--subset-members", args->subset.members, "exactly these members (mesh file stems) decide F")
      ->delimiter(',');
  cmd->add_option("--joint-memory-mb", args->subset.joint_memory_mb, "memory the joint step may use (bounds the default k)")
      ->capture_default_str();
  cmd->add_option("--scheduler", args->scheduler, "local or slurm")->check(CLI::IsMember({"local", "slurm"}))->capture_default_str();
  cmd->add_option("--cpus-per-task", args->cpus_per_task, "Slurm --cpus-per-task (default: --threads)");
  cmd->add_option("--threads", args->threads, "threads per task (passed to every command)")->capture_default_str();
  cmd->add_option("--work", args->work, "scripts, logs, reports, plan (default: DIR.jobs beside DIR)");
  cmd->add_option("--effort", args->effort, "passed to consistent and add (0..5)");
  cmd->add_option("--seed", args->seed, "passed to consistent and add");
  cmd->add_option("--remesh-size", args->remesh_size, "passed to consistent (step 3 grid, 2^k+1)");
  cmd->add_option("--convert", args->convert, "also 'convert --collection' into this folder");
  cmd->add_option("--convert-args", args->convert_args, "its options, e.g. '--gi 129 --lods 3'");
  cmd->add_option("--partition", args->run.slurm_options.partition, "Slurm partition");
  cmd->add_option("--time", args->run.slurm_options.time_limit, "Slurm time limit per task");
  cmd->add_option("--mem", args->run.slurm_options.memory, "Slurm memory per task (e.g. 2G)");
  cmd->add_option("--sbatch-arg", args->run.slurm_options.extra_args, "any other sbatch argument (repeatable)");
  cmd->add_option("--poll", args->run.poll_seconds, "seconds between squeue polls")->capture_default_str();
  cmd->add_option("--timeout", args->run.timeout_seconds, "cancel the jobs after this many seconds (0: no limit)");
  cmd->add_option("--verify", args->verify, "check a finished plan's collection (the plan's last task)");
  cmd->add_flag("-q,--quiet", args->quiet, "print neither progress nor the summary (errors still)");
  cmd->callback([args] { set_exit_code(run_submit(*args)); });
}

}  // namespace spherekit::cli
