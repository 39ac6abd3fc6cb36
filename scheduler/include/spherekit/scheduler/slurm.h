// The Slurm back end of a JobPlan: one sbatch job array per stage with dependencies between
// them, and the checks that decide whether the whole plan succeeded. Everything here is text
// in, text out (scripts, sbatch arguments, parsing squeue/scontrol output), so it is tested
// without Slurm; run_plan.h drives the commands.
//
// Facts it relies on (measured, shared/docs/SCALE.md): a task whose dependency failed stays
// PENDING forever unless submitted with --kill-on-invalid-dep=yes; a job can be recorded
// COMPLETED with exit 0 without having run (proctrack/cgroup in a container), so success is
// job states AND output files; without slurmdbd, `scontrol show job` is the record of
// finished jobs (for MinJobAge, 300 s by default).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "spherekit/scheduler/job_plan.h"

namespace spherekit::scheduler {

struct SlurmOptions {
  std::string partition;               ///< --partition (empty: the cluster's default)
  std::string time_limit;              ///< --time (empty: the partition's)
  std::string memory;                  ///< --mem per task, e.g. "2G" (empty: the default)
  std::vector<std::string> extra_args; ///< more sbatch arguments, passed as given
  std::string job_prefix = "spherekit";
};

/// The batch script of stage `s`: an array of its tasks (`--array=0-(n-1)`, also for one
/// task, so that every stage is an array and aftercorr applies), --cpus-per-task, one
/// stdout and one stderr log per task, OMP_NUM_THREADS, and a `case` on
/// SLURM_ARRAY_TASK_ID that runs the task's command (every word shell-quoted).
std::string stage_script(const JobPlan& plan, int s, const SlurmOptions& options);

/// sbatch's arguments (after "sbatch") to submit the script at `script_path` for stage `s`,
/// given the job ids of the stages submitted before it: --parsable, and with dependencies
/// --dependency=afterok:ID,aftercorr:ID --kill-on-invalid-dep=yes.
std::vector<std::string> sbatch_arguments(const JobPlan& plan, int s, const std::vector<std::string>& job_ids,
                                          const std::string& script_path);

/// The job id in `sbatch --parsable` output ("123" or "123;cluster"). Errors: InvalidInput.
Result<std::string> parse_sbatch_job_id(const std::string& output);

/// One task's record.
struct TaskState {
  std::string job_id;     ///< the array's job id (ArrayJobId)
  int task = -1;          ///< ArrayTaskId; -1 for a record of several pending tasks ("3-11")
  std::string state;      ///< JobState, e.g. COMPLETED, FAILED, PENDING, CANCELLED
  std::string reason;     ///< Reason, e.g. DependencyNeverSatisfied
  int exit_code = 0;      ///< ExitCode's first number
  int signal = 0;         ///< ExitCode's second number
};

/// The records of `scontrol show job ID` output (one per task; blank-line separated, fields
/// `Key=Value`). A record without ArrayJobId is a plain job (task 0). Errors: InvalidInput.
Result<std::vector<TaskState>> parse_scontrol_jobs(const std::string& text);

/// Whether a JobState is final (COMPLETED, FAILED, CANCELLED, TIMEOUT, OUT_OF_MEMORY,
/// NODE_FAIL, PREEMPTED, BOOT_FAIL, DEADLINE).
bool is_final_state(const std::string& state);

/// Whether `squeue -h -j IDS -o %i` output (or its error for purged ids) says that none of
/// the jobs is queued or running any more.
bool squeue_says_done(int exit_code, const std::string& output);

/// Stage `s` succeeded: every task has a record, COMPLETED, exit 0:0, and its outputs exist
/// (`file_exists`). Otherwise SolverFailed naming the stage, the first failed task (its label,
/// state, exit code, and its log) and how many failed.
Status check_stage(const JobPlan& plan, int s, const std::vector<TaskState>& states,
                   const std::function<bool(const std::string&)>& file_exists);

}  // namespace spherekit::scheduler
