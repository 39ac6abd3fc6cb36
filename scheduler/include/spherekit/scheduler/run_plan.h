// Running a JobPlan: locally (every task in order, in this process's children) or on Slurm
// (sbatch per stage, squeue until nothing is queued, then scontrol and the output files).
// Both leave the same per-task logs (job_plan.h log_path) and decide success the same way:
// exit 0 and the task's output files present. Commands are run through a CommandRunner, so
// that tests can drive the Slurm path with a fake cluster.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "spherekit/progress.h"
#include "spherekit/scheduler/job_plan.h"
#include "spherekit/scheduler/slurm.h"

namespace spherekit::scheduler {

struct CommandResult {
  int exit_code = -1;  ///< 128 + signal when killed by one; -1 when it could not start
  std::string out;     ///< stdout when not sent to a file
};

/// Runs argv; stdout goes to `out_path` (or is captured when empty), stderr to `err_path`
/// (or is captured with stdout when empty). Errors: IoError when the program cannot start.
using CommandRunner = std::function<Result<CommandResult>(const std::vector<std::string>& argv,
                                                          const std::string& out_path, const std::string& err_path)>;

/// The real one: fork + exec, waiting for the child.
CommandRunner process_runner();

/// Every task of every stage in plan order; a task whose dependency failed is not run. The
/// tasks of one stage all run even when one fails (as an array would). Errors: SolverFailed
/// naming the first failed task and its log; Cancelled when `progress` returns false.
Status run_plan_local(const JobPlan& plan, const CommandRunner& run, const ProgressFn& progress = {});

/// What run_plan_slurm did, for the report.
struct SlurmRun {
  std::vector<std::string> job_ids;  ///< per stage
  std::vector<std::vector<TaskState>> states;
};

/// Writes the stage scripts into plan.work_dir/slurm/, submits them with dependencies, polls
/// `squeue` every `poll_seconds` (through `sleep`) until no job of the plan is queued (or
/// `timeout_seconds` pass: then the jobs are cancelled), then checks every stage
/// (check_stage). Errors: IoError (scripts), SolverFailed (sbatch refused, a task failed),
/// Cancelled (progress returned false: the jobs are cancelled with scancel).
Status run_plan_slurm(const JobPlan& plan, const SlurmOptions& options, const CommandRunner& run,
                      const std::function<void(double)>& sleep, double poll_seconds, double timeout_seconds,
                      SlurmRun* record = nullptr, const ProgressFn& progress = {});

/// `s` as one POSIX shell word (single quotes).
std::string shell_word(const std::string& s);

}  // namespace spherekit::scheduler
