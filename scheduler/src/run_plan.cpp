// Running a JobPlan locally or through Slurm (run_plan.h).
#include "spherekit/scheduler/run_plan.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "spherekit/formats/atomic_file.h"

namespace fs = std::filesystem;

namespace spherekit::scheduler {
namespace {

bool file_exists(const std::string& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

Status make_dirs(const std::string& d) {
  std::error_code ec;
  fs::create_directories(d, ec);
  if (ec) return Status(ErrorCode::IoError, d + ": cannot create folder (" + ec.message() + ")");
  return Status();
}

}  // namespace

CommandRunner process_runner() {
  return [](const std::vector<std::string>& argv, const std::string& out_path,
            const std::string& err_path) -> Result<CommandResult> {
    int pipe_fd[2] = {-1, -1};
    if (out_path.empty() && ::pipe2(pipe_fd, O_CLOEXEC) != 0)
      return Status(ErrorCode::IoError, argv[0] + ": cannot create a pipe (" + std::strerror(errno) + ")");
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    const pid_t pid = ::fork();
    if (pid < 0) return Status(ErrorCode::IoError, argv[0] + ": cannot fork (" + std::strerror(errno) + ")");
    if (pid == 0) {
      // The child: only async-signal-safe calls until exec.
      const int in = ::open("/dev/null", O_RDONLY);
      if (in >= 0) ::dup2(in, 0);
      int out = out_path.empty() ? pipe_fd[1] : ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      int err = err_path.empty() ? out : ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (out < 0 || err < 0) ::_exit(127);
      ::dup2(out, 1);
      ::dup2(err, 2);
      ::execvp(args[0], args.data());
      ::_exit(127);
    }
    CommandResult r;
    if (out_path.empty()) {
      ::close(pipe_fd[1]);
      char buf[4096];
      for (;;) {
        const ssize_t n = ::read(pipe_fd[0], buf, sizeof buf);
        if (n > 0) r.out.append(buf, static_cast<size_t>(n));
        else if (n == 0 || errno != EINTR) break;
      }
      ::close(pipe_fd[0]);
    }
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : WIFSIGNALED(status) ? 128 + WTERMSIG(status) : -1;
    return r;
  };
}

Status run_plan_local(const JobPlan& plan, const CommandRunner& run, const ProgressFn& progress) {
  SPHEREKIT_RETURN_IF_ERROR(validate_plan(plan));
  SPHEREKIT_RETURN_IF_ERROR(make_dirs(plan.log_dir()));
  std::vector<std::vector<char>> ok(plan.stages.size());
  Status first_failure;
  int done = 0, total = 0;
  for (const JobStage& st : plan.stages) total += static_cast<int>(st.tasks.size());
  for (size_t s = 0; s < plan.stages.size(); ++s) {
    const JobStage& st = plan.stages[s];
    ok[s].assign(st.tasks.size(), 0);
    for (size_t i = 0; i < st.tasks.size(); ++i) {
      if (!report_progress(progress, st.name, static_cast<int>(i), static_cast<double>(done) / total))
        return Status(ErrorCode::Cancelled, "cancelled");
      ++done;
      // As Slurm's afterok / aftercorr: run only when what it waits for succeeded.
      bool ready = true;
      for (const auto& [kind, earlier] : st.after) {
        const auto& e = ok[static_cast<size_t>(earlier)];
        if (kind == Dependency::AfterCorr) ready = ready && e[i];
        else
          for (char x : e) ready = ready && x;
      }
      if (!ready) continue;
      const std::string out = plan.log_path(static_cast<int>(s), static_cast<int>(i), "out");
      const std::string err = plan.log_path(static_cast<int>(s), static_cast<int>(i), "err");
      auto r = run(st.tasks[i].argv, out, err);
      std::string why;
      if (!r.ok()) why = r.status().message();
      else if (r->exit_code != 0) why = "exit " + std::to_string(r->exit_code);
      else
        for (const std::string& f : st.tasks[i].outputs)
          if (why.empty() && !file_exists(f)) why = "exit 0 but its output " + f + " is missing";
      if (why.empty()) {
        ok[s][i] = 1;
      } else if (first_failure.ok()) {
        first_failure = Status(ErrorCode::SolverFailed, "stage " + st.name + ": task " + std::to_string(i) + " (" +
                                                            st.tasks[i].label + ") failed: " + why + "; log " + err);
      }
    }
  }
  return first_failure;
}

Status run_plan_slurm(const JobPlan& plan, const SlurmOptions& options, const CommandRunner& run,
                      const std::function<void(double)>& sleep, double poll_seconds, double timeout_seconds,
                      SlurmRun* record, const ProgressFn& progress) {
  SPHEREKIT_RETURN_IF_ERROR(validate_plan(plan));
  SPHEREKIT_RETURN_IF_ERROR(make_dirs(plan.log_dir()));
  const std::string script_dir = plan.work_dir + "/slurm";
  SPHEREKIT_RETURN_IF_ERROR(make_dirs(script_dir));
  SlurmRun local;
  SlurmRun& rec = record ? *record : local;
  rec = SlurmRun{};
  auto cancel_all = [&] {
    if (rec.job_ids.empty()) return;
    std::vector<std::string> argv = {"scancel"};
    for (const std::string& id : rec.job_ids) argv.push_back(id);
    (void)run(argv, "", "");
  };
  for (size_t s = 0; s < plan.stages.size(); ++s) {
    const std::string script = script_dir + "/" + plan.stages[s].name + ".sh";
    SPHEREKIT_RETURN_IF_ERROR(formats::write_file_atomic(script, stage_script(plan, static_cast<int>(s), options)));
    std::vector<std::string> argv = {"sbatch"};
    for (const std::string& a : options.extra_args) argv.push_back(a);
    for (const std::string& a : sbatch_arguments(plan, static_cast<int>(s), rec.job_ids, script)) argv.push_back(a);
    auto r = run(argv, "", "");
    if (!r.ok() || r->exit_code != 0) {
      cancel_all();
      return Status(ErrorCode::SolverFailed, "sbatch refused stage " + plan.stages[s].name + ": " +
                                                 (r.ok() ? r->out : r.status().message()));
    }
    auto id = parse_sbatch_job_id(r->out);
    if (!id.ok()) {
      cancel_all();
      return Status(ErrorCode::SolverFailed, id.status().message());
    }
    rec.job_ids.push_back(id.value());
  }
  // Polling squeue (with a bound) instead of `sbatch --wait`, which backs off to tens of
  // seconds and returns 0 for a job cancelled by a failed dependency (SCALE.md trap 4).
  std::string ids;
  for (const std::string& id : rec.job_ids) ids += (ids.empty() ? "" : ",") + id;
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    auto q = run({"squeue", "-h", "-j", ids, "-o", "%i %T"}, "", "");
    if (q.ok() && squeue_says_done(q->exit_code, q->out)) break;
    const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!report_progress(progress, "slurm", 0, -1)) {
      cancel_all();
      return Status(ErrorCode::Cancelled, "cancelled (jobs " + ids + " cancelled)");
    }
    if (timeout_seconds > 0 && waited > timeout_seconds) {
      cancel_all();
      return Status(ErrorCode::SolverFailed, "jobs " + ids + " not finished after " +
                                                 std::to_string(static_cast<int>(timeout_seconds)) + " s (cancelled)");
    }
    sleep(poll_seconds);
  }
  Status first;
  for (size_t s = 0; s < plan.stages.size(); ++s) {
    auto shown = run({"scontrol", "show", "job", rec.job_ids[s]}, "", "");
    std::vector<TaskState> states;
    if (shown.ok() && shown->exit_code == 0) {
      auto parsed = parse_scontrol_jobs(shown->out);
      if (parsed.ok()) states = std::move(parsed).value();
    }
    rec.states.push_back(states);
    if (Status st = check_stage(plan, static_cast<int>(s), states, file_exists); !st.ok() && first.ok()) first = st;
  }
  return first;
}

}  // namespace spherekit::scheduler
