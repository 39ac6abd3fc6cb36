// A plan of batch jobs: stages of independent tasks (one command line each) with dependencies
// between stages, run locally or on a cluster scheduler (slurm.h). The collection pipeline of
// issue 23 is such a plan (collection_plan.h): F from a subset, then every other member mapped
// to F as its own task, then conversion, then a final check.
//
// Plans are data: built by pure functions, written as JSON beside the job scripts (so that the
// final check task and a later `spherekit submit --status` read the same plan), unit-tested
// without any scheduler.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "spherekit/status.h"

namespace spherekit::scheduler {

/// How a stage waits for an earlier one (Slurm's --dependency kinds).
enum class Dependency {
  AfterOk,    ///< every task of the earlier stage completed with exit 0
  AfterCorr,  ///< task i waits for task i of the earlier stage (same task count)
};

struct JobTask {
  std::string label;               ///< e.g. the member name, for messages
  std::vector<std::string> argv;   ///< the command (argv[0] an absolute path or on PATH)
  /// Files a successful task leaves: a task is done only if it exited 0 AND these exist
  /// (a scheduler can record a task COMPLETED that never ran, SCALE.md trap 3).
  std::vector<std::string> outputs;
};

struct JobStage {
  std::string name;  ///< a plain word: job names, script and log file names
  std::vector<JobTask> tasks;
  std::vector<std::pair<Dependency, int>> after;  ///< indices of earlier stages
};

struct JobPlan {
  std::string work_dir;  ///< scripts, logs, the plan file
  int cpus_per_task = 1;
  int threads = 1;       ///< passed to each command as --threads and OMP_NUM_THREADS
  std::vector<JobStage> stages;
  /// The collection folder the plan builds and every member it must end up listing (for the
  /// final check; empty for other plans).
  std::string collection;
  std::vector<std::string> members;

  std::string log_dir() const { return work_dir + "/logs"; }
  /// Where task `t` of stage `s` writes stdout / stderr (Slurm's %a pattern, resolved).
  std::string log_path(int s, int t, const char* stream) const;
};

/// InvalidArgument unless the plan is well-formed: names plain words and unique, every stage
/// has tasks with a command, dependencies point at earlier stages, AfterCorr between stages of
/// equal task counts, cpus_per_task and threads >= 1.
Status validate_plan(const JobPlan& plan);

/// The plan as JSON text (deterministic) and back. Errors: ParseError / InvalidInput naming
/// `source`.
std::string plan_to_json(const JobPlan& plan);
Result<JobPlan> plan_from_json(const std::string& text, const std::string& source);

}  // namespace spherekit::scheduler
