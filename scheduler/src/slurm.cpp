// Slurm job scripts, sbatch arguments and the parsing of Slurm's answers (slurm.h).
#include "spherekit/scheduler/slurm.h"

#include <cstdlib>
#include <sstream>

#include "spherekit/scheduler/run_plan.h"

namespace spherekit::scheduler {
namespace {

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r\n"), b = s.find_last_not_of(" \t\r\n");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

bool parse_int(const std::string& s, int& v) {
  if (s.empty()) return false;
  char* end = nullptr;
  const long x = std::strtol(s.c_str(), &end, 10);
  if (*end != '\0') return false;
  v = static_cast<int>(x);
  return true;
}

}  // namespace

std::string shell_word(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string stage_script(const JobPlan& plan, int s, const SlurmOptions& o) {
  const JobStage& st = plan.stages[static_cast<size_t>(s)];
  std::string t;
  t += "#!/bin/bash\n";
  t += "# spherekit job plan " + shell_word(plan.work_dir) + ", stage " + st.name + " (" +
       std::to_string(st.tasks.size()) + " task" + (st.tasks.size() == 1 ? "" : "s") + ")\n";
  t += "#SBATCH --job-name=" + o.job_prefix + "-" + st.name + "\n";
  t += "#SBATCH --array=0-" + std::to_string(st.tasks.size() - 1) + "\n";
  t += "#SBATCH --ntasks=1\n";
  t += "#SBATCH --cpus-per-task=" + std::to_string(plan.cpus_per_task) + "\n";
  // %a: the array index, so that every task has its own two logs (the names log_path gives).
  t += "#SBATCH --output=" + plan.log_dir() + "/" + st.name + "_%a.out\n";
  t += "#SBATCH --error=" + plan.log_dir() + "/" + st.name + "_%a.err\n";
  if (!o.partition.empty()) t += "#SBATCH --partition=" + o.partition + "\n";
  if (!o.time_limit.empty()) t += "#SBATCH --time=" + o.time_limit + "\n";
  if (!o.memory.empty()) t += "#SBATCH --mem=" + o.memory + "\n";
  t += "set -u\n";
  // Threads: the commands get --threads; libraries that read OMP_NUM_THREADS (Eigen) too,
  // or every task would use every core of its node (SCALE.md trap 8).
  t += "export OMP_NUM_THREADS=" + std::to_string(plan.threads) + "\n";
  t += "case \"${SLURM_ARRAY_TASK_ID:-}\" in\n";
  for (size_t i = 0; i < st.tasks.size(); ++i) {
    t += "  " + std::to_string(i) + ") exec";
    for (const std::string& w : st.tasks[i].argv) t.append(" ").append(shell_word(w));
    t += " ;;\n";
  }
  t.append("  *) echo \"no task '${SLURM_ARRAY_TASK_ID:-}' in stage ").append(st.name).append("\" >&2; exit 2 ;;\n");
  t += "esac\n";
  return t;
}

std::vector<std::string> sbatch_arguments(const JobPlan& plan, int s, const std::vector<std::string>& job_ids,
                                          const std::string& script_path) {
  const JobStage& st = plan.stages[static_cast<size_t>(s)];
  std::vector<std::string> a = {"--parsable"};
  if (!st.after.empty()) {
    std::string dep;
    for (const auto& [kind, earlier] : st.after)
      dep.append(dep.empty() ? "" : ",")
          .append(kind == Dependency::AfterCorr ? "aftercorr:" : "afterok:")
          .append(job_ids[static_cast<size_t>(earlier)]);
    a.push_back("--dependency=" + dep);
    // Without it a task whose dependency failed stays PENDING forever (SCALE.md trap 4).
    a.push_back("--kill-on-invalid-dep=yes");
  }
  a.push_back(script_path);
  return a;
}

Result<std::string> parse_sbatch_job_id(const std::string& output) {
  std::string line = trim(output);
  if (const size_t nl = line.find_last_of('\n'); nl != std::string::npos) line = trim(line.substr(nl + 1));
  const std::string id = line.substr(0, line.find(';'));
  int v = 0;
  if (!parse_int(id, v) || v <= 0)
    return Status(ErrorCode::InvalidInput, "sbatch: no job id in its output '" + trim(output) + "'");
  return id;
}

Result<std::vector<TaskState>> parse_scontrol_jobs(const std::string& text) {
  std::vector<TaskState> out;
  std::istringstream in(text);
  std::string record, line;
  auto flush = [&]() -> Status {
    if (trim(record).empty()) return Status();
    TaskState t;
    std::string job_id, array_job, array_task, exit_code;
    std::istringstream words(record);
    for (std::string w; words >> w;) {
      const size_t eq = w.find('=');
      if (eq == std::string::npos) continue;
      const std::string k = w.substr(0, eq), v = w.substr(eq + 1);
      if (k == "JobId") job_id = v;
      else if (k == "ArrayJobId") array_job = v;
      else if (k == "ArrayTaskId") array_task = v;
      else if (k == "JobState") t.state = v;
      else if (k == "Reason") t.reason = v;
      else if (k == "ExitCode") exit_code = v;
    }
    record.clear();
    if (job_id.empty() || t.state.empty())
      return Status(ErrorCode::InvalidInput, "scontrol: a job record without JobId or JobState");
    t.job_id = array_job.empty() ? job_id : array_job;
    if (array_job.empty()) t.task = 0;
    else if (!parse_int(array_task, t.task)) t.task = -1;  // "3-11", "4,6%2": several pending tasks
    const size_t colon = exit_code.find(':');
    if (!exit_code.empty() && (!parse_int(exit_code.substr(0, colon), t.exit_code) ||
                               (colon != std::string::npos && !parse_int(exit_code.substr(colon + 1), t.signal))))
      return Status(ErrorCode::InvalidInput, "scontrol: unreadable ExitCode '" + exit_code + "'");
    out.push_back(t);
    return Status();
  };
  while (std::getline(in, line)) {
    if (trim(line).empty()) {
      SPHEREKIT_RETURN_IF_ERROR(flush());
      continue;
    }
    record += " " + line;
  }
  SPHEREKIT_RETURN_IF_ERROR(flush());
  return out;
}

bool is_final_state(const std::string& state) {
  for (const char* f : {"COMPLETED", "FAILED", "CANCELLED", "TIMEOUT", "OUT_OF_MEMORY", "NODE_FAIL", "PREEMPTED",
                        "BOOT_FAIL", "DEADLINE"})
    if (state.rfind(f, 0) == 0) return true;  // "CANCELLED by 0"
  return false;
}

bool squeue_says_done(int exit_code, const std::string& output) {
  // Ids already purged from the controller: squeue refuses them ("Invalid job id").
  if (exit_code != 0) return output.find("Invalid job id") != std::string::npos;
  return trim(output).empty();
}

Status check_stage(const JobPlan& plan, int s, const std::vector<TaskState>& states,
                   const std::function<bool(const std::string&)>& file_exists) {
  const JobStage& st = plan.stages[static_cast<size_t>(s)];
  int failed = 0;
  std::string first;
  for (size_t i = 0; i < st.tasks.size(); ++i) {
    const JobTask& task = st.tasks[i];
    std::string why;
    const TaskState* rec = nullptr;
    for (const TaskState& t : states)
      if (t.task == static_cast<int>(i)) rec = &t;
    if (!rec) {
      why = "no record of the task (never ran?)";
    } else if (rec->state != "COMPLETED" || rec->exit_code != 0 || rec->signal != 0) {
      why = rec->state + " exit " + std::to_string(rec->exit_code) + ":" + std::to_string(rec->signal) +
            (rec->reason.empty() || rec->reason == "None" ? "" : " (" + rec->reason + ")");
    } else {
      for (const std::string& f : task.outputs)
        if (!file_exists(f)) {
          // SCALE.md trap 3: recorded COMPLETED with exit 0, but it did not do its work.
          why = "COMPLETED but its output " + f + " is missing";
          break;
        }
    }
    if (why.empty()) continue;
    if (failed++ == 0)
      first = "stage " + st.name + ": task " + std::to_string(i) + " (" + task.label + ") " + why + "; log " +
              plan.log_path(s, static_cast<int>(i), "err");
  }
  if (failed == 0) return Status();
  return Status(ErrorCode::SolverFailed,
                first + (failed > 1 ? " (" + std::to_string(failed) + " of " + std::to_string(st.tasks.size()) +
                                          " tasks failed)"
                                    : std::string()));
}

}  // namespace spherekit::scheduler
