// Shared plumbing of the `spherekit` subcommands; see cli_common.h.
#include "cli_common.h"

#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdarg>
#include <cstdio>
#include <sstream>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "spherekit/formats/atomic_file.h"

namespace fs = std::filesystem;

namespace spherekit::cli {

// ---------------------------------------------------------------------------------------
// Exit codes and error messages

namespace {
int g_exit_code = 0;
}  // namespace

void set_exit_code(int code) { g_exit_code = code; }
int exit_code() { return g_exit_code; }

int print_error(const Status& status) {
  // One line per error, so scripts and log scrapers can rely on `grep error:`.
  std::string message = status.message().empty() ? error_code_name(status.code()) : status.message();
  std::replace(message.begin(), message.end(), '\n', ' ');
  std::replace(message.begin(), message.end(), '\r', ' ');
  std::fflush(stdout);
  std::fprintf(stderr, "spherekit: error: %s\n", message.c_str());
  std::fflush(stderr);
  return error_code_exit_code(status.code());
}

// ---------------------------------------------------------------------------------------
// Cancellation

namespace {

// Seconds the library gets to notice the cancel flag before the process is ended hard.
// Progress is reported per level and per pass, which is well under this on the meshes we
// know; a stuck stage must still not make Ctrl-C useless.
constexpr unsigned kGracefulCancelSeconds = 3;

volatile std::sig_atomic_t g_cancel = 0;
volatile std::sig_atomic_t g_in_compute = 0;
volatile std::sig_atomic_t g_child_pid = 0;  // pid_t fits: both are int on Linux
volatile std::sig_atomic_t g_stderr_tty = 0;

// Only async-signal-safe calls here (write, kill, _exit; remove_pending_temp_files is
// documented as such).
[[noreturn]] void exit_cancelled() noexcept {
  formats::remove_pending_temp_files();
  const pid_t child = static_cast<pid_t>(g_child_pid);
  if (child > 0) kill(child, SIGTERM);
  static const char kTty[] = "\nspherekit: error: cancelled\n";
  static const char kPlain[] = "spherekit: error: cancelled\n";
  if (g_stderr_tty) {
    [[maybe_unused]] ssize_t n = write(STDERR_FILENO, kTty, sizeof(kTty) - 1);
  } else {
    [[maybe_unused]] ssize_t n = write(STDERR_FILENO, kPlain, sizeof(kPlain) - 1);
  }
  _exit(error_code_exit_code(ErrorCode::Cancelled));
}

extern "C" void on_signal(int sig) {
  if (sig == SIGALRM || g_cancel || !g_in_compute) exit_cancelled();
  g_cancel = 1;
  // A child (bench) may not share our process group's Ctrl-C, e.g. after `kill -TERM`.
  const pid_t child = static_cast<pid_t>(g_child_pid);
  if (child > 0) kill(child, SIGTERM);
  alarm(kGracefulCancelSeconds);
}

}  // namespace

void install_signal_handlers() {
  g_stderr_tty = isatty(STDERR_FILENO) ? 1 : 0;
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGALRM, &action, nullptr);
}

bool cancel_requested() { return g_cancel != 0; }

Status cancelled_status() { return Status(ErrorCode::Cancelled, "cancelled"); }

ComputeScope::ComputeScope() : previous_(g_in_compute) { g_in_compute = 1; }
ComputeScope::~ComputeScope() { g_in_compute = previous_; }

void set_child_pid(pid_t pid) { g_child_pid = static_cast<std::sig_atomic_t>(pid); }

// ---------------------------------------------------------------------------------------
// Progress

ProgressRenderer::ProgressRenderer(bool quiet, std::string prefix)
    : quiet_(quiet), tty_(isatty(STDERR_FILENO) != 0), prefix_(std::move(prefix)) {}

ProgressRenderer::~ProgressRenderer() { finish(); }

ProgressFn ProgressRenderer::callback() {
  return [this](const ProgressEvent& event) { return on_event(event); };
}

void ProgressRenderer::draw_terminal_line() {
  std::string text = prefix_.empty() ? std::string() : "[" + prefix_ + "] ";
  for (size_t i = 0; i < percent_.size(); ++i)
    text += (i ? " | " : "") + percent_[i].first + " " + std::to_string(percent_[i].second) + "%";
  std::fprintf(stderr, "\r\033[K%s (level %d)", text.c_str(), level_);
  std::fflush(stderr);
  line_open_ = true;
  stale_ = false;
}

void ProgressRenderer::finish() {
  if (stale_) draw_terminal_line();  // show the final state, not the last throttled one
  if (line_open_) {
    std::fputc('\n', stderr);
    std::fflush(stderr);
    line_open_ = false;
  }
}

bool ProgressRenderer::on_event(const ProgressEvent& event) {
  if (cancel_requested()) return false;
  // Heartbeats (negative fraction) only give the chance to cancel between stages.
  if (quiet_ || event.fraction < 0) return true;
  const double fraction = std::isfinite(event.fraction) ? std::clamp(event.fraction, 0.0, 1.0) : 0.0;
  const int percent = static_cast<int>(fraction * 100.0);
  if (tty_) {
    auto it = std::find_if(percent_.begin(), percent_.end(), [&](const auto& p) { return p.first == event.stage; });
    const bool changed = it == percent_.end() || it->second != percent;
    if (it == percent_.end())
      percent_.emplace_back(std::string(event.stage), percent);
    else
      it->second = percent;
    level_ = event.level;
    stale_ = stale_ || changed;
    // Redraw only when something visible changed, at most ~20 times a second: the
    // library may call back thousands of times per level.
    const auto now = std::chrono::steady_clock::now();
    if (stale_ && now - last_draw_ >= std::chrono::milliseconds(50)) {
      last_draw_ = now;
      draw_terminal_line();
    }
  } else {
    const int decile = percent / 10;
    auto [it, first_time] = last_decile_.try_emplace(std::string(event.stage), decile);
    if (!first_time && decile <= it->second) return true;
    it->second = decile;
    const std::string label = prefix_.empty() ? it->first : prefix_ + " " + it->first;
    std::fprintf(stderr, "[%s] %3d%% (level %d)\n", label.c_str(), percent, event.level);
    std::fflush(stderr);
  }
  return true;
}

// ---------------------------------------------------------------------------------------
// Timing and memory

// ---------------------------------------------------------------------------------------
// Output helpers

Status write_json_atomic(const std::string& path, const Json& json) {
  // Non-finite doubles become null (nlohmann's choice), which every JSON reader accepts.
  const std::string text = json.dump(2) + "\n";
  // "-" is standard output, as for every Unix tool (`--report -`): a script pipes the report on.
  if (path == "-") {
    if (std::fwrite(text.data(), 1, text.size(), stdout) != text.size() || std::fflush(stdout) != 0)
      return Status(ErrorCode::IoError, "standard output: cannot write the report");
    return Status();
  }
  return formats::write_file_atomic(path, text);
}


std::string file_stem(const std::string& path) { return fs::path(path).stem().string(); }
std::vector<std::string> words(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}
std::string file_name(const std::string& path) { return fs::path(path).filename().string(); }

Table::Table(std::vector<std::string> header) { rows_.push_back(std::move(header)); }

void Table::add_row(std::vector<std::string> row) {
  row.resize(rows_.front().size());
  rows_.push_back(std::move(row));
}

void Table::print() const {
  std::vector<size_t> width(rows_.front().size(), 0);
  for (const auto& row : rows_)
    for (size_t c = 0; c < row.size(); ++c) width[c] = std::max(width[c], row[c].size());
  auto print_row = [&](const std::vector<std::string>& row) {
    std::string line;
    for (size_t c = 0; c < row.size(); ++c) {
      const std::string pad(width[c] - row[c].size(), ' ');
      if (c > 0) line += "  ";
      line += c == 0 ? row[c] + pad : pad + row[c];
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    std::printf("%s\n", line.c_str());
  };
  print_row(rows_.front());
  size_t total = 0;
  for (size_t w : width) total += w;
  total += 2 * (width.size() - 1);
  std::printf("%s\n", std::string(total, '-').c_str());
  for (size_t r = 1; r < rows_.size(); ++r) print_row(rows_[r]);
}

// ---------------------------------------------------------------------------------------
// Input


// ---------------------------------------------------------------------------------------
// Options

CLI::App* add_command(CLI::App& app, const std::string& name, const std::string& summary,
                      const std::string& paragraph, const std::string& examples) {
  CLI::App* cmd = app.add_subcommand(name, summary);
  cmd->footer(paragraph + "\n\nExamples:\n" + examples);
  return cmd;
}

// An old spelling of a flag, still accepted but not shown in --help.
template <class T>
void add_hidden_alias(CLI::App& command, const std::string& name, T& value) {
  command.add_option(name, value)->group("");
}

void add_threads_option(CLI::App& command, int& threads) {
  command.add_option("--threads", threads, "worker threads, 0 = all cores (results do not depend on it)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
}

void add_sphere_param_options(CLI::App& command, SphereParamOptions& o) {
  // One line per field; flag name = field name in kebab case, so the two cannot drift
  // (DESIGN 3.4). The snake-case spellings of earlier versions stay as hidden aliases.
  command.add_option("--effort", o.effort, "0..5: speed/quality preset (more passes and iterations)")
      ->check(CLI::Range(0, 5))->capture_default_str();
  command.add_option("--seed", o.seed, "seed of every random choice (results are deterministic)")
      ->capture_default_str();
  add_threads_option(command, o.threads);
  command.add_option("--regularizer-weight", o.regularizer_weight,
                     "weight of the term against collapsed sphere triangles (shape-defining)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  command.add_option("--hole-weight", o.hole_weight, "stretch weight of the faces that close holes (shape-defining)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  command.add_option("--hole-shape-weight", o.hole_shape_weight,
                     "weight of the shape term that keeps hole faces from becoming slivers (shape-defining)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  command.add_option("--block-vertices", o.block_vertices,
                     "simplify meshes of 1.5x this many vertices in blocks of about this many first, in parallel; 0: one greedy (shape-defining)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  add_hidden_alias(command, "--regularizer_weight", o.regularizer_weight);
  add_hidden_alias(command, "--hole_weight", o.hole_weight);
  add_hidden_alias(command, "--hole_shape_weight", o.hole_shape_weight);
}

ConstrainedParamOptions ConstrainedFlags::resolve(const SphereParamOptions& sphere) const {
  ConstrainedParamOptions o = constrained;
  o.sphere = sphere;
  return o;
}

void add_constrained_flags(CLI::App& cmd, ConstrainedFlags& f) {
  ConstrainedParamOptions& o = f.constrained;
  cmd.add_option("--steiner-penalty", o.steiner_penalty, "cost factor of paths through edge midpoints")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 100.0));
  cmd.add_option("--min-angle-deg", o.min_angle_deg, "defer arcs making smaller angles (degrees)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 60.0));
  // Switches of fields that default to true: --no-FIELD.
  cmd.add_flag("!--no-unswirl", o.unswirl, "skip the unswirl operator");
  cmd.add_flag("!--no-edge-flips", o.edge_flips, "skip path edge flips");
  cmd.add_flag("!--no-sidedness", o.sidedness, "skip the sidedness tests");
  cmd.add_flag("!--no-arc-ranking", o.arc_ranking, "rank candidate paths by surface length alone, not with their arcs");
  cmd.add_flag("--as-unconstrained", o.as_unconstrained,
               "simplify and optimize as the unconstrained stage does (keeps thin limbs' share of the sphere)");
  cmd.add_option("--min-angle", o.min_angle_deg)->check(CLI::Range(0.0, 60.0))->group("");
  cmd.add_flag("!--no-flips", o.edge_flips)->group("");
}

}  // namespace spherekit::cli
