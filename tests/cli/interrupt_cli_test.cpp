// Interrupting the `spherekit` program (issue 8): SIGINT in the middle of a computation ends
// the command with the cancellation exit code (130, status.h), the one-line message
// `spherekit: error: cancelled`, no output file or folder, no temporary file or staging folder
// left in the target folder, and existing outputs untouched.
//
// The signal is sent once the child has printed a chosen progress line (e.g. the start of the
// refinement), not after a fixed delay, so the interruption lands mid-computation whatever the
// machine's load. A command that nevertheless completes before the signal arrives (exit 0) is
// retried on a bigger job; if even that completes, the test warns, and still checks that no
// temporary file was left.
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "test_paths.h"

namespace fs = std::filesystem;
using spherekit::test::slurp;

namespace {

constexpr int kCancelledExit = 130;  // ErrorCode::Cancelled in status.h

// Generous bounds that only stop a hung test; they are not what the test measures.
constexpr auto kStartDeadline = std::chrono::seconds(300);
constexpr auto kStopDeadline = std::chrono::seconds(60);

struct Interrupted {
  bool reached_marker = false;  // the marker line appeared before the child ended
  bool signalled = false;       // SIGINT was sent while the child was still running
  int exit_code = -1;           // -1: killed by a signal or not waited for
  std::string err;
};

// Runs SPHEREKIT_EXE with `args` (stdout to `out_file`, stderr read here), sends SIGINT as
// soon as a stderr line contains `marker`, and waits for the child to end.
Interrupted run_and_interrupt(const std::vector<std::string>& args, const std::string& marker,
                              const std::string& out_file) {
  Interrupted result;
  int pipe_fd[2];
  REQUIRE(::pipe(pipe_fd) == 0);
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    // Child: stdin /dev/null, stdout to the file, stderr into the pipe. SIGINT unblocked and
    // at its default: a test runner started in the background may have it ignored or blocked,
    // which the child would inherit (spherekit installs its own handler anyway).
    const int in = ::open("/dev/null", O_RDONLY);
    const int out = ::open(out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (in < 0 || out < 0) ::_exit(127);
    ::dup2(in, STDIN_FILENO);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(pipe_fd[1], STDERR_FILENO);
    ::close(pipe_fd[0]);
    ::close(pipe_fd[1]);
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigprocmask(SIG_UNBLOCK, &set, nullptr);
    ::signal(SIGINT, SIG_DFL);
    std::vector<char*> argv;
    std::string exe = SPHEREKIT_EXE;
    argv.push_back(exe.data());
    std::vector<std::string> copy = args;
    for (std::string& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(exe.c_str(), argv.data());
    ::_exit(127);
  }
  ::close(pipe_fd[1]);

  // Reads what is available on the pipe (waiting up to `ms`); false at end of file.
  auto pump = [&](int ms) {
    pollfd p{pipe_fd[0], POLLIN, 0};
    if (::poll(&p, 1, ms) <= 0) return true;
    char buf[4096];
    const ssize_t n = ::read(pipe_fd[0], buf, sizeof buf);
    if (n < 0) return errno == EINTR || errno == EAGAIN;
    if (n == 0) return false;
    result.err.append(buf, static_cast<size_t>(n));
    return true;
  };
  auto marker_seen = [&] {
    // Only complete lines: a marker cut in half must not count.
    const size_t end = result.err.rfind('\n');
    return end != std::string::npos && result.err.substr(0, end).find(marker) != std::string::npos;
  };

  bool open = true;
  const auto start = std::chrono::steady_clock::now();
  while (open && !marker_seen() && std::chrono::steady_clock::now() - start < kStartDeadline) open = pump(100);
  result.reached_marker = marker_seen();

  int status = 0;
  bool waited = ::waitpid(pid, &status, WNOHANG) == pid;
  if (!waited && !result.reached_marker) {
    // No marker after kStartDeadline: a hung child. The caller reports the missing marker.
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
    waited = true;
    status = -1;
  } else if (!waited) {
    // Still running: interrupt it. (A child that has exited is a zombie, which kill would
    // "signal" without effect; hence the waitpid first.)
    result.signalled = ::kill(pid, SIGINT) == 0;
  }
  if (!waited) {
    const auto stop_start = std::chrono::steady_clock::now();
    while (!waited) {
      if (open) open = pump(50);
      else ::usleep(20000);
      const pid_t done = ::waitpid(pid, &status, WNOHANG);
      if (done == pid) waited = true;
      if (!waited && std::chrono::steady_clock::now() - stop_start > kStopDeadline) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, &status, 0);
        waited = true;
        status = -1;  // not a normal exit: reported below as exit_code -1
        FAIL_CHECK("the child did not end within " << kStopDeadline.count() << " s after SIGINT; stderr:\n"
                                                   << result.err);
      }
    }
  }
  while (open) open = pump(100);  // the rest of stderr (the child has exited)
  ::close(pipe_fd[0]);
  if (status != -1 && WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
  return result;
}

std::vector<std::string> entries(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string last_line(const std::string& s) {
  std::string t = s;
  while (!t.empty() && t.back() == '\n') t.pop_back();
  const size_t nl = t.rfind('\n');
  return nl == std::string::npos ? t : t.substr(nl + 1);
}

std::string make_samples(const std::string& dir, const std::string& name, int vertices) {
  const std::string s = dir + "/" + name;
  const auto r = spherekit::test::run_cli(SPHEREKIT_EXE,
                                          "samples -o " + spherekit::test::shell_quote(s) +
                                              " --members 2 --vertices " + std::to_string(vertices),
                                          dir);
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  return s;
}

/// One interruption attempt: the command and the stderr text after which to signal it.
struct Attempt {
  std::function<std::vector<std::string>()> args;  // may prepare inputs first (bigger samples)
  std::string marker;
};

// Runs the attempts in order until one is still running when SIGINT arrives; returns its
// outcome, or the last one's (exit 0, with a warning) when every command finished first.
// `reset` restores the target folder after a command that completed.
Interrupted interrupt_first_running(const std::vector<Attempt>& attempts, const std::string& capture_dir,
                                    const std::function<void()>& reset) {
  Interrupted r;
  for (size_t i = 0; i < attempts.size(); ++i) {
    r = run_and_interrupt(attempts[i].args(), attempts[i].marker, capture_dir + "/stdout.txt");
    INFO("attempt " << i << ", stderr:\n" << r.err);
    REQUIRE(r.reached_marker);  // the command started its computation at all
    if (r.exit_code != 0) return r;
    WARN("attempt " << i << " finished before SIGINT arrived (exit 0): nothing was interrupted");
    if (i + 1 < attempts.size()) reset();
  }
  // Not a return: the caller's checks of the finished run still apply.
  spherekit::test::note_skip("the cancellation checks: every job finished before SIGINT arrived");
  WARN("SKIPPED the cancellation checks: every job finished before SIGINT arrived");
  return r;
}

// The last stderr line is the one error line; it says "cancelled" ("spherekit: error:
// cancelled", or naming the mesh when the library stage reports the cancellation itself:
// "spherekit: error: FILE: cancelled during optimization").
void require_cancel_message(const std::string& err) {
  const std::string line = last_line(err);
  CHECK(line.rfind("spherekit: error: ", 0) == 0);
  CHECK(line.find("cancelled") != std::string::npos);
  size_t errors = 0;
  for (size_t at = err.find("error:"); at != std::string::npos; at = err.find("error:", at + 1)) ++errors;
  CHECK(errors == 1);
}

// Temporary files (".NAME.tmp.PID.N") and staging folders (".NAME.partial.PID",
// ".NAME.old.PID") all start with a dot; none may be left, whatever happened.
void require_no_hidden_entries(const std::string& dir) {
  for (const std::string& name : entries(dir)) {
    INFO("left in " << dir << ": " << name);
    CHECK(name[0] != '.');
  }
}

}  // namespace

TEST_CASE("interrupt: SIGINT during param leaves no map, no temporary file, the old report", "[cli][interrupt]") {
  const std::string dir = spherekit::test::temp_dir("interrupt_param");
  const std::string target = dir + "/target";
  fs::create_directories(target);
  const std::string old_report = "old report, must survive\n";
  auto reset = [&] {
    fs::remove_all(target);
    fs::create_directories(target);
    std::ofstream(target + "/report.json") << old_report;
  };
  reset();
  const std::vector<std::string> before = entries(target);

  auto param = [&](const std::string& samples, int vertices, const std::string& effort) {
    return [=] {
      const std::string s = make_samples(dir, samples, vertices);
      return std::vector<std::string>{"param", s + "/sample_b.obj", "-o", target + "/map.sphere.obj", "--report",
                                      target + "/report.json", "--effort", effort, "--threads", "1"};
    };
  };
  // Signalled when the refinement starts (seconds of work left); the retry is ~10 times
  // bigger and uses the slowest effort.
  const Interrupted r = interrupt_first_running(
      {{param("samples", 3000, "2"), "[refine]"}, {param("big", 30000, "5"), "[refine]"}}, dir, reset);
  INFO("stderr:\n" << r.err);
  if (r.exit_code != 0) {
    CHECK(r.signalled);
    CHECK(r.exit_code == kCancelledExit);
    require_cancel_message(r.err);
    CHECK_FALSE(fs::exists(target + "/map.sphere.obj"));
    CHECK(slurp(target + "/report.json") == old_report);
    CHECK(entries(target) == before);
  }
  require_no_hidden_entries(target);
}

TEST_CASE("interrupt: SIGINT during consistent leaves no collection and no staging folder",
          "[cli][interrupt][collection]") {
  const std::string dir = spherekit::test::temp_dir("interrupt_consistent");
  // The collection folder's parent holds only it and the report: the staging
  // (".col.partial.PID") and old (".col.old.PID") folders would be created there.
  const std::string target = dir + "/target";
  const std::string col = target + "/col";
  auto reset = [&] {
    fs::remove_all(target);
    fs::create_directories(target);
  };
  reset();

  auto consistent = [&](const std::string& samples, int vertices, const std::string& effort) {
    return [=] {
      const std::string s = make_samples(dir, samples, vertices);
      return std::vector<std::string>{"consistent", "-o", col, s + "/sample_a.obj", s + "/sample_b.obj",
                                      "--effort", effort, "--remesh-size", "33", "--threads", "2",
                                      "--report", target + "/report.json"};
    };
  };
  // Signalled when step 2 (the parallel constrained maps) starts: steps 2 to 6 remain.
  const Interrupted r = interrupt_first_running(
      {{consistent("samples", 1000, "2"), "[step 2"}, {consistent("big", 20000, "5"), "[step 2"}}, dir, reset);
  INFO("stderr:\n" << r.err);
  if (r.exit_code != 0) {
    CHECK(r.signalled);
    CHECK(r.exit_code == kCancelledExit);
    require_cancel_message(r.err);
    CHECK_FALSE(fs::exists(col));
    CHECK(entries(target).empty());
  }
  require_no_hidden_entries(target);
}

TEST_CASE("interrupt: SIGINT as consistent finishes leaves the whole collection or none of it",
          "[cli][interrupt][collection]") {
  // Signalled when the last step reports 100%: the signal lands in the last computations, in
  // the writing of the staging folder or in the swap, depending on the machine. Whatever
  // the moment, there is no staging or old folder left, and a collection folder, if any, is
  // complete.
  const std::string dir = spherekit::test::temp_dir("interrupt_consistent_end");
  const std::string s = make_samples(dir, "samples", 600);
  const std::string target = dir + "/target", col = target + "/col";
  fs::create_directories(target);
  const Interrupted r = run_and_interrupt({"consistent", "-o", col, s + "/sample_a.obj", s + "/sample_b.obj",
                                           "--effort", "1", "--remesh-size", "17"},
                                          "[step 6] 100%", dir + "/stdout.txt");
  INFO("stderr:\n" << r.err);
  REQUIRE(r.reached_marker);
  CHECK((r.exit_code == 0 || r.exit_code == kCancelledExit));
  if (r.exit_code == kCancelledExit) require_cancel_message(r.err);
  require_no_hidden_entries(target);
  if (fs::exists(col)) {
    CHECK(entries(col) ==
          std::vector<std::string>{"collection.json", "features.txt", "sample_a.sphere.obj", "sample_b.sphere.obj"});
  } else {
    CHECK(r.exit_code == kCancelledExit);
  }
  CHECK(entries(target) == (fs::exists(col) ? std::vector<std::string>{"col"} : std::vector<std::string>{}));
}
