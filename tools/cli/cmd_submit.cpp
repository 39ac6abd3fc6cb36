// `spherekit submit`: a large consistent collection as independent jobs (issue 23): F from a
// subset of k members (`consistent`), every other member mapped to F as its own task (`add`),
// optional conversion, a final check; run locally (default) or as Slurm job arrays
// (--scheduler slurm). The plan, the job scripts and the state checks are the scheduler
// library's (scheduler/collection_plan.h, slurm.h, run_plan.h); this file parses flags,
// picks the subset and prints. `submit --verify PLAN` is the plan's final task.
#include <CLI/CLI.hpp>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_common.h"
#include "commands.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/collection.h"
#include "spherekit/formats/feature_io.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/metrics.h"
#include "spherekit/scheduler/collection_plan.h"
#include "spherekit/scheduler/run_plan.h"

namespace fs = std::filesystem;

namespace spherekit::cli {
namespace {

namespace sch = spherekit::scheduler;

struct SubmitArgs {
  std::string output, work, scheduler = "local", subset_by = "farthest", verify;
  std::vector<std::string> meshes, features, subset_members;
  int subset = 0;
  double joint_memory_mb = 2048;
  int cpus_per_task = 0, threads = 1;
  int effort = -1, remesh_size = 0;
  long long seed = -1;
  std::string convert, convert_args;
  std::string partition, time_limit, memory;
  std::vector<std::string> sbatch_args;
  double poll = 2, timeout = 0;
  bool quiet = false;
};

std::string abs_path(const std::string& p) {
  std::error_code ec;
  return fs::weakly_canonical(fs::absolute(p, ec), ec).string();
}

std::vector<std::string> words(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

// Feature layout descriptors (collection_plan.h) of every member, for the farthest-point
// subset: one read of each mesh and feature file.
Result<std::vector<std::vector<double>>> layout_descriptors(const std::vector<std::string>& meshes,
                                                            const std::vector<std::string>& features) {
  std::vector<std::vector<double>> out;
  std::vector<std::string> names;
  for (size_t i = 0; i < meshes.size(); ++i) {
    SPHEREKIT_ASSIGN_OR_RETURN(TriMesh mesh, formats::read_mesh(meshes[i]));
    auto lms = formats::read_landmarks(features[i], static_cast<int>(mesh.V.rows()));
    if (!lms.ok()) return with_file(lms.status(), features[i]);
    if (names.empty())
      for (const Landmark& l : lms.value()) names.push_back(l.name);
    std::vector<double> p;
    for (const std::string& n : names) {
      auto it = std::find_if(lms->begin(), lms->end(), [&](const Landmark& l) { return l.name == n; });
      if (it == lms->end())
        return Status(ErrorCode::InvalidInput, features[i] + ": no feature '" + n + "' (" + features[0] + " has it)");
      for (int a = 0; a < 3; ++a) p.push_back(mesh.V(it->vertex, a));
    }
    out.push_back(sch::feature_layout_descriptor(p));
  }
  return out;
}

int run_verify(const std::string& plan_path, bool quiet) {
  auto text = formats::read_file(plan_path);
  if (!text.ok()) return print_error(text.status());
  auto plan = sch::plan_from_json(text.value(), plan_path);
  if (!plan.ok()) return print_error(plan.status());
  auto col = formats::read_collection(plan->collection);
  if (!col.ok()) return print_error(col.status());
  Json report;
  report["collection"] = plan->collection;
  std::vector<std::string> listed, missing, broken;
  for (const formats::CollectionMember& e : col->manifest.members) listed.push_back(e.name);
  for (const std::string& m : plan->members)
    if (std::find(listed.begin(), listed.end(), m) == listed.end()) missing.push_back(m);
  // Every map once, at the end: present, of its mesh, a bijection by the exact predicate.
  for (const formats::CollectionMember& e : col->manifest.members) {
    const std::string& name = e.name;
    auto mesh = formats::read_mesh(e.source.value_or(""));
    if (!mesh.ok()) { broken.push_back(name + ": " + mesh.status().message()); continue; }
    auto map = formats::read_sphere_map((fs::path(plan->collection) / e.map).string(), mesh.value());
    if (!map.ok()) { broken.push_back(name + ": " + map.status().message()); continue; }
    if (const int f = count_flipped_faces(mesh->F, map->S); f != 0) broken.push_back(name + ": " + std::to_string(f) + " flipped faces");
  }
  // Per-task measures from the tasks' own reports (peak memory is per process).
  Json tasks = Json::array();
  double max_peak = 0;
  for (const auto& st : plan->stages)
    for (const auto& t : st.tasks)
      for (const std::string& out : t.outputs) {
        if (out.size() < 5 || out.compare(out.size() - 5, 5, ".json") != 0 || out.find("/reports/") == std::string::npos)
          continue;
        auto r = formats::read_file(out);
        if (!r.ok()) continue;
        Json j = Json::parse(r.value(), nullptr, false);
        if (j.is_discarded()) continue;
        const double peak = j.value("peak_rss_mb", 0.0);
        max_peak = std::max(max_peak, peak);
        double wall = 0;
        if (j.contains("times") && j["times"].is_object()) wall = j["times"].value("wall", 0.0);
        tasks.push_back({{"stage", st.name}, {"task", t.label}, {"peak_rss_mb", peak}, {"wall_seconds", wall}});
      }
  report["members"] = plan->members.size();
  report["listed"] = listed.size();
  report["missing"] = missing;
  report["broken"] = broken;
  report["tasks"] = tasks;
  report["max_task_peak_rss_mb"] = max_peak;
  report["ok"] = missing.empty() && broken.empty();
  if (Status s = write_json_atomic(plan->work_dir + "/submit_report.json", report); !s.ok()) return print_error(s);
  if (!missing.empty())
    return print_error(Status(ErrorCode::SolverFailed, plan->collection + ": " + std::to_string(missing.size()) +
                                                           " planned members are not in the manifest (first: " +
                                                           missing[0] + ")"));
  if (!broken.empty()) return print_error(Status(ErrorCode::SolverFailed, plan->collection + ": " + broken[0]));
  if (!quiet)
    std::printf("%s: %zu members, every map a bijection; max task peak memory %.0f MB\n", plan->collection.c_str(),
                listed.size(), max_peak);
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
  o.exe = abs_path("/proc/self/exe");
  o.collection = abs_path(a.output);
  o.work_dir = a.work.empty() ? o.collection + ".jobs" : abs_path(a.work);
  for (size_t i = 0; i < a.meshes.size(); ++i) {
    std::error_code ec;
    if (!fs::is_regular_file(a.meshes[i], ec))
      return print_error(Status(ErrorCode::IoError, a.meshes[i] + ": cannot open (no such file)"));
    o.meshes.push_back(abs_path(a.meshes[i]));
    const fs::path p(a.meshes[i]);
    o.features.push_back(abs_path(a.features.empty() ? (p.parent_path() / (p.stem().string() + ".lm.txt")).string()
                                                     : a.features[i]));
    o.names.push_back(file_stem(a.meshes[i]));
  }
  const int n = static_cast<int>(o.meshes.size());
  const int remesh = a.remesh_size > 0 ? a.remesh_size : 65;
  // k: as given, else as many as the joint step's memory allows, at most 12 (the step-2/6
  // maps of the subset run in one job, so a larger k lengthens the critical path).
  const int k_memory = sch::largest_subset_for_memory(a.joint_memory_mb * 1024 * 1024, remesh);
  int k = a.subset > 0 ? std::min(a.subset, n) : std::min({n, 12, k_memory});
  if (!a.subset_members.empty()) {
    for (const std::string& m : a.subset_members) {
      auto it = std::find(o.names.begin(), o.names.end(), m);
      if (it == o.names.end())
        return print_error(Status(ErrorCode::InvalidArgument, "--subset-members: '" + m + "' is not one of the meshes"));
      o.subset.push_back(static_cast<int>(it - o.names.begin()));
    }
    k = static_cast<int>(o.subset.size());
  } else if (a.subset_by == "first") {
    for (int i = 0; i < k; ++i) o.subset.push_back(i);
  } else {
    auto d = layout_descriptors(o.meshes, o.features);
    if (!d.ok()) return print_error(d.status());
    o.subset = sch::farthest_point_subset(d.value(), k);
  }
  if (a.effort >= 0) o.map_args.insert(o.map_args.end(), {"--effort", std::to_string(a.effort)});
  if (a.seed >= 0) o.map_args.insert(o.map_args.end(), {"--seed", std::to_string(a.seed)});
  if (a.remesh_size > 0) o.consistent_args = {"--remesh-size", std::to_string(a.remesh_size)};
  if (!a.convert.empty()) {
    o.convert_output = abs_path(a.convert);
    o.convert_args = words(a.convert_args);
  }
  o.threads = a.threads;
  o.cpus_per_task = a.cpus_per_task > 0 ? a.cpus_per_task : a.threads;
  auto plan = sch::plan_collection(o);
  if (!plan.ok()) return print_error(plan.status());
  std::error_code ec;
  fs::create_directories(o.work_dir + "/reports", ec);
  if (ec) return print_error(Status(ErrorCode::IoError, o.work_dir + ": cannot create (" + ec.message() + ")"));
  // Reports of an earlier run would pass for this run's outputs.
  fs::remove_all(o.work_dir + "/reports", ec);
  fs::remove(o.work_dir + "/submit_report.json", ec);
  fs::create_directories(o.work_dir + "/reports", ec);
  if (Status s = formats::write_file_atomic(o.work_dir + "/plan.json", sch::plan_to_json(plan.value())); !s.ok())
    return print_error(s);
  if (!a.quiet) {
    std::string names;
    for (int i : o.subset) names += (names.empty() ? "" : " ") + o.names[static_cast<size_t>(i)];
    std::fprintf(stderr,
                 "submit: %d members; F from %d (%s), joint-step quadrics %.0f MB (k <= %d fit in %.0f MB); "
                 "%d maps as independent tasks; scheduler %s; plan %s/plan.json\n",
                 n, k, names.c_str(), sch::joint_quadric_bytes(k, remesh) / (1024 * 1024), k_memory, a.joint_memory_mb,
                 n - k, a.scheduler.c_str(), o.work_dir.c_str());
  }
  ProgressFn keep_going = [](const ProgressEvent&) { return !cancel_requested(); };
  Status s;
  {
    ComputeScope graceful_cancel;
    if (a.scheduler == "slurm") {
      sch::SlurmOptions so;
      so.partition = a.partition;
      so.time_limit = a.time_limit;
      so.memory = a.memory;
      so.extra_args = a.sbatch_args;
      s = sch::run_plan_slurm(
          plan.value(), so, sch::process_runner(),
          [](double sec) { std::this_thread::sleep_for(std::chrono::duration<double>(sec)); }, a.poll, a.timeout,
          nullptr, keep_going);
    } else {
      s = sch::run_plan_local(plan.value(), sch::process_runner(), keep_going);
    }
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
      "A collection too large for one 'consistent' run: the feature locations F come from a subset of\n"
      "k members (steps 1-5, 'consistent'), then every other member is mapped to F as its own task\n"
      "('add', the paper's §5; concurrent tasks update the manifest under the folder's lock), then\n"
      "optionally 'convert --collection', then a final check (every member listed, every map a\n"
      "bijection). The result equals 'consistent' on the subset followed by 'add' of the rest.\n"
      "k: the joint step keeps one quadric of d(d+1)/2 doubles (d = 3k) per remesh vertex, about\n"
      "8 N^2 (3k)(3k+1)/2 bytes for an N x N remesh: 60 MB at k = 20, 1.5 GB at k = 100 (N = 65).\n"
      "Default k = min(n, 12, what fits --joint-memory-mb); the subset is spread over the shapes\n"
      "(farthest points of the feature-layout descriptor) or --subset-by first or --subset-members.\n"
      "--scheduler local (default) runs the tasks here, one after another; --scheduler slurm submits\n"
      "one job array per stage (sbatch --array, --dependency=afterok --kill-on-invalid-dep=yes,\n"
      "--cpus-per-task, --threads and OMP_NUM_THREADS in each task), waits, and exits non-zero when\n"
      "any task failed (job states from scontrol AND every task's output files). Scripts, per-task\n"
      "logs (logs/STAGE_I.out/.err), per-task reports and the plan go to --work (default DIR.jobs).",
      "  spherekit submit -o lib meshes/*.obj --subset 16 --effort 1\n"
      "  spherekit submit -o lib meshes/*.obj --scheduler slurm --cpus-per-task 2 --threads 2 \\\n"
      "      --partition batch --time 1:00:00 --convert lib-assets --convert-args '--gi 129 --lods 3'\n"
      "  spherekit submit --verify lib.jobs/plan.json        # the final task: check the result");
  cmd->add_option("MESH", args->meshes, "member meshes (each with NAME.lm.txt beside it, or --features)");
  cmd->add_option("-o,--output", args->output, "collection folder to write");
  cmd->add_option("--features", args->features, "feature files, one per mesh in order");
  cmd->add_option("--subset", args->subset, "k: members that decide F (default: min(n, 12, memory bound))");
  cmd->add_option("--subset-by", args->subset_by, "how to choose them: farthest (spread over shapes) or first")
      ->check(CLI::IsMember({"farthest", "first"}))
      ->capture_default_str();
  cmd->add_option("--subset-members", args->subset_members, "exactly these members (mesh file stems) decide F")
      ->delimiter(',');
  cmd->add_option("--joint-memory-mb", args->joint_memory_mb, "memory the joint step may use (bounds the default k)")
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
  cmd->add_option("--partition", args->partition, "Slurm partition");
  cmd->add_option("--time", args->time_limit, "Slurm time limit per task");
  cmd->add_option("--mem", args->memory, "Slurm memory per task (e.g. 2G)");
  cmd->add_option("--sbatch-arg", args->sbatch_args, "any other sbatch argument (repeatable)");
  cmd->add_option("--poll", args->poll, "seconds between squeue polls")->capture_default_str();
  cmd->add_option("--timeout", args->timeout, "cancel the jobs after this many seconds (0: no limit)");
  cmd->add_option("--verify", args->verify, "check a finished plan's collection (the plan's last task)");
  cmd->add_flag("-q,--quiet", args->quiet, "print neither progress nor the summary (errors still)");
  cmd->callback([args] { set_exit_code(run_submit(*args)); });
}

}  // namespace spherekit::cli
