// The data jobs of `spherekit submit` (issue 23) that read meshes and maps or touch the work
// folder: the subset that decides F (feature-layout descriptors, farthest points), resetting
// the work folder, and the plan's final check (every planned member listed, every listed map a
// bijection of its mesh by the exact predicate, the tasks' own measures gathered). The CLI
// parses flags and prints; these read files and return values.
#pragma once

#include <string>
#include <vector>

#include "spherekit/scheduler/collection_plan.h"
#include "spherekit/scheduler/run_plan.h"
#include "spherekit/status.h"

namespace spherekit::scheduler {

/// feature_layout_descriptor() of every member: one read of each mesh and its feature file.
/// The feature order is the first file's. Errors: the mesh's or feature file's, named; a
/// member lacking a feature of the first (InvalidInput).
Result<std::vector<std::vector<double>>> feature_layouts(const std::vector<std::string>& meshes,
                                                         const std::vector<std::string>& features);

/// `p` made absolute and canonical as far as it exists (no error: the path as best known).
std::string absolute_path(const std::string& p);

/// Appends the members given by mesh paths: absolute paths, each mesh's feature file
/// `features[i]` or else NAME.lm.txt beside it, names the file stems. Errors: IoError naming
/// the first mesh that is not a regular file (options then partly filled: discard them).
Status add_members(CollectionPlanOptions& options, const std::vector<std::string>& meshes,
                   const std::vector<std::string>& features);

/// How the members that decide F are chosen (submit's --subset, --subset-members, --subset-by).
struct SubsetRequest {
  int k = 0;                         ///< 0: min(n, 12, what fits joint_memory_mb)
  std::vector<std::string> members;  ///< exactly these names (overrides k and by)
  bool farthest = true;              ///< false: the first k
  double joint_memory_mb = 2048;
  int remesh_size = 65;
};
struct SubsetChoice {
  std::vector<int> subset;  ///< indices into options.names
  int k_memory = 1;         ///< the largest k that fits the memory bound
};
/// Fills the choice for `options` (meshes, features, names set). Errors: a name not a member
/// (InvalidArgument), feature_layouts' errors.
Result<SubsetChoice> choose_subset(const CollectionPlanOptions& options, const SubsetRequest& request);

/// Empties WORK/reports and removes WORK/submit_report.json (an earlier run's reports would
/// pass for this run's outputs), then writes WORK/plan.json (plan_to_json, atomically).
/// Errors: IoError naming the folder or file.
Status write_plan(const JobPlan& plan);

/// How to run a plan: here, one task after another (run_plan_local), or as Slurm job arrays
/// (run_plan_slurm, polling with a real sleep), both with the process runner.
struct RunRequest {
  bool slurm = false;
  SlurmOptions slurm_options;
  double poll_seconds = 2, timeout_seconds = 0;
};
Status run_plan(const JobPlan& plan, const RunRequest& request, const ProgressFn& progress);

/// One task's measures from its own report (peak memory is per process).
struct TaskMeasure {
  std::string stage, task;
  double peak_rss_mb = 0, wall_seconds = 0;
};

struct PlanVerification {
  std::string collection, work_dir;
  size_t members = 0;                ///< planned
  size_t listed = 0;                 ///< in the manifest
  std::vector<std::string> missing;  ///< planned but not listed
  std::vector<std::string> broken;   ///< "NAME: problem" per listed member whose map fails
  std::vector<TaskMeasure> tasks;    ///< from every task's reports/*.json that parses
  double max_task_peak_rss_mb = 0;
  bool ok() const { return missing.empty() && broken.empty(); }
  /// The first problem (missing before broken) as SolverFailed naming the collection; OK when ok().
  Status failure() const;
};

/// The report `submit_report.json` holds (2-space indented JSON, newline at the end).
std::string to_json(const PlanVerification& verification);

/// Reads the plan (plan_to_json's text) and its collection, checks every member and writes
/// to_json() to WORK/submit_report.json (atomically) whatever the verdict. Errors (unreadable
/// plan or collection, the report not written) are the Status; a finished check that found
/// problems is a value with ok() false.
Result<PlanVerification> verify_plan(const std::string& plan_path);

}  // namespace spherekit::scheduler
