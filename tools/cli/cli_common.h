// What every subcommand shares: error printing and exit codes, cancellation by signal,
// progress rendering, timing and memory measurement, JSON reports, and loading a mesh
// with its structural check. The libraries print nothing; all output goes through here.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "spherekit/check_mesh.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/mesh.h"
#include "spherekit/metrics.h"
#include "spherekit/progress.h"
#include "spherekit/constrained_param.h"
#include "spherekit/sphere_param.h"
#include "spherekit/file_status.h"
#include "spherekit/format_text.h"
#include "spherekit/pipeline/json.h"
#include "spherekit/pipeline/mesh_input.h"
#include "spherekit/pipeline/paths.h"
#include "spherekit/pipeline/process_stats.h"
#include "spherekit/status.h"

namespace CLI {
class App;
}

namespace spherekit::cli {

// Reports keep the order in which keys are written, so they read like the summaries.
using Json = nlohmann::ordered_json;
using pipeline::constrained_options_json;
using pipeline::feature_network_json;
using pipeline::file_bytes;
using pipeline::mesh_check_json;
using pipeline::source_faces_json;
using pipeline::number_or_null;
using pipeline::require_output_folders;
using pipeline::sphere_map_metrics_json;
using pipeline::sphere_param_options_json;
using pipeline::sphere_param_result_json;

// ---------------------------------------------------------------------------------------
// Exit codes and error messages

/// Usage errors (bad flags) exit with this code; library errors use error_code_exit_code().
inline constexpr int kUsageExitCode = 2;
/// `check`: some mesh was read but is not acceptable for parameterization.
inline constexpr int kRejectedExitCode = 3;

/// Records the exit code main() returns once the subcommand's callback has finished.
void set_exit_code(int code);
int exit_code();

/// Prints `spherekit: error: <message>` as exactly one line on stderr (newlines in the
/// message are folded) and returns the exit code for the status.
int print_error(const Status& status);

/// The Cancelled status commands return when a signal arrived.
Status cancelled_status();

/// The larger of two exit codes: a run over several meshes reports its worst failure.
inline int worse_exit_code(int a, int b) { return a > b ? a : b; }

// ---------------------------------------------------------------------------------------
// Cancellation (SIGINT / SIGTERM)

/// Installs the SIGINT/SIGTERM handlers. Outside a ComputeScope a signal removes the
/// temporary files of unfinished atomic writes and exits 130 at once. Inside one, the first
/// signal only sets the cancel flag, so the library stops at its next progress call and
/// returns Cancelled; if it does not within a few seconds, or on a second signal, the
/// process exits as above. Either way no partial output is ever left behind.
void install_signal_handlers();

/// True once SIGINT/SIGTERM arrived.
bool cancel_requested();

/// Marks a library computation that polls the progress callback (graceful cancellation).
/// Scopes nest: leaving an inner one keeps the outer one in force.
class ComputeScope {
 public:
  ComputeScope();
  ~ComputeScope();
  ComputeScope(const ComputeScope&) = delete;
  ComputeScope& operator=(const ComputeScope&) = delete;

 private:
  int previous_;
};

/// The child process `bench` is waiting for (0: none); a signal forwards SIGTERM to it.
void set_child_pid(pid_t pid);

// ---------------------------------------------------------------------------------------
// Progress

/// Renders ProgressEvents on stderr. On a terminal: one line rewritten in place with the
/// latest percentage of every stage seen, `[prefix] simplify 100% | refine 45% | optimize 3%
/// (level N)`, because stages interleave (an optimize pass per refine level) and showing only
/// the latest would flicker between them. Otherwise (logs, CI): `[prefix stage] 45% (level N)`
/// when a stage first appears and each time it passes another 10 %, so logs stay short.
/// Quiet renderers print nothing but still cancel.
class ProgressRenderer {
 public:
  /// `prefix` (e.g. the mesh name) is shown before the stage name.
  explicit ProgressRenderer(bool quiet, std::string prefix = {});
  ~ProgressRenderer();
  ProgressRenderer(const ProgressRenderer&) = delete;
  ProgressRenderer& operator=(const ProgressRenderer&) = delete;

  /// The callback to hand to a library stage. It returns false (cancel) once a signal
  /// arrived. Valid while this renderer lives.
  ProgressFn callback();
  /// Ends the in-place terminal line so that what follows starts on a fresh line.
  void finish();

 private:
  bool on_event(const ProgressEvent& event);
  void draw_terminal_line();

  bool quiet_;
  bool tty_;
  std::string prefix_;
  std::vector<std::pair<std::string, int>> percent_;  // terminal: latest percent per stage, in order seen
  std::map<std::string, int> last_decile_;             // logs: last 10 % step printed, per stage
  bool line_open_ = false;
  bool stale_ = false;  // terminal: a change was not drawn yet (throttled)
  int level_ = 0;
  std::chrono::steady_clock::time_point last_draw_{};
};

// ---------------------------------------------------------------------------------------
// Timing and memory

/// Wall-clock seconds since construction (steady clock: immune to clock changes).
class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

using pipeline::cpu_seconds;
using pipeline::peak_rss_mb;

// ---------------------------------------------------------------------------------------
// Output helpers

/// Writes `json` (indented, trailing newline) to `path` atomically. Errors: IoError.
Status write_json_atomic(const std::string& path, const Json& json);


/// File name without folder and last extension ("a/b/spot.obj" -> "spot").
std::string file_stem(const std::string& path);
/// The whitespace-separated words of `s` (a flag holding another command's options).
std::vector<std::string> words(const std::string& s);
/// File name without folder ("a/b/spot.obj" -> "spot.obj").
std::string file_name(const std::string& path);

/// A plain-text table: columns are right-aligned except the first.
class Table {
 public:
  explicit Table(std::vector<std::string> header);
  void add_row(std::vector<std::string> row);
  /// Prints the header, a rule and all rows to stdout.
  void print() const;

 private:
  std::vector<std::vector<std::string>> rows_;
};

// ---------------------------------------------------------------------------------------
// Input

using pipeline::load_mesh;
using pipeline::load_mesh_checked;
using pipeline::LoadedMesh;
using pipeline::param_verdict;

// ---------------------------------------------------------------------------------------
// Subcommands and options shared by param, run and bench

/// Adds a subcommand whose help reads: `summary` (also shown in `spherekit --help`), usage,
/// options, then `paragraph` (what it does, outputs, exit codes) and `examples` (one per line).
CLI::App* add_command(CLI::App& app, const std::string& name, const std::string& summary,
                      const std::string& paragraph, const std::string& examples);

/// --threads N into `threads` (0: all cores); one wording for every command.
void add_threads_option(CLI::App& command, int& threads);
/// Adds one flag per SphereParamOptions field, named exactly like the field (DESIGN 3.4),
/// bound to `options` (which must outlive parsing).
void add_sphere_param_options(CLI::App& command, SphereParamOptions& options);

/// The constrained stage's flags (param, consistent, add): its options, resolved against the
/// sphere options.
struct ConstrainedFlags {
  ConstrainedParamOptions constrained;
  ConstrainedParamOptions resolve(const SphereParamOptions& sphere) const;
};
/// Adds --steiner-penalty, --min-angle-deg, --no-unswirl, --no-edge-flips, --no-sidedness, --no-arc-ranking
/// (hidden aliases: --min-angle, --no-flips).
void add_constrained_flags(CLI::App& command, ConstrainedFlags& flags);

}  // namespace spherekit::cli
