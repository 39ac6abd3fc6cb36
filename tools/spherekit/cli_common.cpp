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
  if (quiet_) return true;
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

double cpu_seconds() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  auto secs = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); };
  return secs(usage.ru_utime) + secs(usage.ru_stime);
}

double peak_rss_mb() {
  // VmHWM ("high water mark") is the peak resident set in kB; getrusage's ru_maxrss is the
  // same number but /proc states its unit explicitly.
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmHWM:", 0) == 0) {
      long kb = 0;
      if (std::sscanf(line.c_str() + 6, "%ld", &kb) == 1) return static_cast<double>(kb) / 1024.0;
    }
  }
  return 0;
}

// ---------------------------------------------------------------------------------------
// Output helpers

Status write_json_atomic(const std::string& path, const Json& json) {
  // Non-finite doubles become null (nlohmann's choice), which every JSON reader accepts.
  return formats::write_file_atomic(path, json.dump(2) + "\n");
}

std::string strprintf(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list copy;
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  std::string out(n > 0 ? static_cast<size_t>(n) : 0, '\0');
  if (n > 0) std::vsnprintf(out.data(), out.size() + 1, format, args);
  va_end(args);
  return out;
}

std::string file_stem(const std::string& path) { return fs::path(path).stem().string(); }
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

// Every input error must name the file first; readers usually do, but not every stage does.
Status with_file(const Status& status, const std::string& path) {
  if (status.ok() || status.message().rfind(path, 0) == 0) return status;
  return status.with_context(path);
}

Result<LoadedMesh> load_mesh(const std::string& path) {
  LoadedMesh out;
  out.path = path;
  Stopwatch read_time;
  auto mesh = formats::read_mesh(path, formats::ReadOptions{}, &out.info);
  if (!mesh.ok()) return with_file(mesh.status(), path);
  out.mesh = std::move(mesh).value();
  out.read_seconds = read_time.seconds();
  Stopwatch check_time;
  out.check = check_mesh(out.mesh);
  out.check_seconds = check_time.seconds();
  return out;
}

Result<LoadedMesh> load_mesh_checked(const std::string& path, bool allow_boundary, bool repair) {
  auto loaded = load_mesh(path);
  if (!loaded.ok()) return loaded.status();
  LoadedMesh& m = loaded.value();
  if (repair && m.check.nonmanifold_vertices > 0) {
    Stopwatch t;
    m.split_vertices = repair_pinched_vertices(m.mesh);
    m.check = check_mesh(m.mesh);
    m.check_seconds += t.seconds();
  }
  Status verdict = param_verdict(m, allow_boundary);
  if (!verdict.ok()) return verdict;
  return loaded;
}

Status require_supported_coordinates(const TriMesh& mesh, const std::string& path) {
  if (mesh.V.rows() == 0) return Status::ok_status();
  const double largest = mesh.V.cwiseAbs().maxCoeff();
  if (!(largest <= kMaxCoordinate))
    return Status(ErrorCode::InvalidInput,
                  strprintf("%s: coordinates reach %.3g, beyond the supported |x| <= %.0e (lengths, areas and "
                            "stretch would overflow); scale the mesh down",
                            path.c_str(), largest, kMaxCoordinate));
  // No overflow below kMaxCoordinate: the diagonal is at most 2 sqrt(3) kMaxCoordinate.
  const double extent = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).norm();
  if (extent == 0) return Status(ErrorCode::InvalidInput, path + ": all vertices are at one point (zero extent)");
  if (extent < kMinExtent)
    return Status(ErrorCode::InvalidInput,
                  strprintf("%s: the mesh is %.3g across, below the supported %.0e (areas and stretch would "
                            "underflow); scale the mesh up",
                            path.c_str(), extent, kMinExtent));
  return Status::ok_status();
}

Status param_verdict(const LoadedMesh& m, bool allow_boundary) {
  SPHEREKIT_RETURN_IF_ERROR(with_file(require_genus0(m.check, allow_boundary), m.path));
  return require_supported_coordinates(m.mesh, m.path);
}

Status require_output_folders(const std::vector<std::string>& paths) {
  for (const std::string& path : paths) {
    if (path.empty()) continue;
    const fs::path parent = fs::path(path).parent_path();
    std::error_code ec;
    if (!parent.empty() && !fs::is_directory(parent, ec))
      return Status(ErrorCode::IoError, path + ": folder '" + parent.string() + "' does not exist");
  }
  return Status::ok_status();
}

Json mesh_check_json(const std::string& file, const MeshCheck& c) {
  Json j;
  j["file"] = file;
  j["V"] = c.vertices;
  j["F"] = c.faces;
  j["edges"] = c.edges;
  j["unreferenced_vertices"] = c.unreferenced_vertices;
  j["degenerate_faces"] = c.degenerate_faces;
  j["duplicate_faces"] = c.duplicate_faces;
  j["zero_area_faces"] = c.zero_area_faces;
  j["boundary_edges"] = c.boundary_edges;
  j["nonmanifold_edges"] = c.nonmanifold_edges;
  j["orientation_conflicts"] = c.orientation_conflicts;
  j["boundary_loops"] = c.boundary_loops;
  j["components"] = c.components;
  j["nonmanifold_vertices"] = c.nonmanifold_vertices;
  j["orientable"] = c.orientable;
  j["euler"] = c.euler;
  j["genus"] = c.genus;
  j["bbox_diag"] = c.bbox_diag;
  // Not in the manifest (its meshes are all finite and indexed correctly), but part of the
  // check: keep them after the manifest's keys.
  j["nonfinite_vertices"] = c.nonfinite_vertices;
  j["invalid_indices"] = c.invalid_indices;
  j["genus0_ok"] = c.genus0_ok();
  return j;
}

// ---------------------------------------------------------------------------------------
// Options

CLI::App* add_command(CLI::App& app, const std::string& name, const std::string& summary,
                      const std::string& paragraph, const std::string& examples) {
  CLI::App* cmd = app.add_subcommand(name, summary);
  cmd->footer(paragraph + "\n\nExamples:\n" + examples);
  return cmd;
}

void add_sphere_param_options(CLI::App& command, SphereParamOptions& o) {
  // One line per field; flag name = field name, so the two cannot drift (DESIGN 3.4).
  command.add_option("--effort", o.effort, "0..5: speed/quality preset (more passes and iterations)")
      ->check(CLI::Range(0, 5))->capture_default_str();
  command.add_option("--seed", o.seed, "seed of every random choice (results are deterministic)")
      ->capture_default_str();
  command.add_option("--threads", o.threads, "worker threads, 0 = all cores (results do not depend on it)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  command.add_option("--regularizer_weight", o.regularizer_weight,
                     "weight of the term against collapsed sphere triangles (shape-defining)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  command.add_option("--hole_weight", o.hole_weight, "stretch weight of the faces that close holes (shape-defining)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  command.add_option("--hole_shape_weight", o.hole_shape_weight,
                     "weight of the shape term that keeps hole faces from becoming slivers (shape-defining)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
}

Json sphere_param_options_json(const SphereParamOptions& o) {
  Json j;
  j["effort"] = o.effort;
  j["seed"] = o.seed;
  j["threads"] = o.threads;
  j["regularizer_weight"] = o.regularizer_weight;
  j["hole_weight"] = o.hole_weight;
  j["hole_shape_weight"] = o.hole_shape_weight;
  return j;
}

ConstrainedParamOptions ConstrainedFlags::resolve(const SphereParamOptions& sphere) const {
  ConstrainedParamOptions o = constrained;
  o.sphere = sphere;
  o.unswirl = !no_unswirl;
  o.edge_flips = !no_flips;
  o.sidedness = !no_sidedness;
  return o;
}

void add_constrained_flags(CLI::App& cmd, ConstrainedFlags& f) {
  cmd.add_option("--steiner-penalty", f.constrained.steiner_penalty, "cost factor of paths through edge midpoints")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 100.0));
  cmd.add_option("--min-angle", f.constrained.min_angle_deg, "defer arcs making smaller angles (degrees)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 60.0));
  cmd.add_flag("--no-unswirl", f.no_unswirl, "skip the unswirl operator");
  cmd.add_flag("--no-flips", f.no_flips, "skip path edge flips");
  cmd.add_flag("--no-sidedness", f.no_sidedness, "skip the sidedness tests");
}

Json constrained_options_json(const ConstrainedParamOptions& o) {
  Json j = sphere_param_options_json(o.sphere);
  j["steiner_penalty"] = o.steiner_penalty;
  j["min_angle_deg"] = o.min_angle_deg;
  j["extremity_fraction"] = o.extremity_fraction;
  j["unswirl"] = o.unswirl;
  j["edge_flips"] = o.edge_flips;
  j["sidedness"] = o.sidedness;
  return j;
}

Json feature_network_json(const FeatureNetworkReport& n) {
  return Json{{"auxiliary_features", n.auxiliary_features},
              {"paths", n.paths},
              {"total_path_length", n.total_length},
              {"max_length_ratio", n.max_ratio},
              {"swirls_fixed", n.swirls_fixed},
              {"edge_flips", n.edge_flips},
              {"deferred", n.deferred},
              {"steiner_vertices", n.steiner_vertices},
              {"flips_untangled", n.flips_after_steiner_removal},
              {"attempts", n.attempts}};
}

Json sphere_param_result_json(const SphereParamResult& r) {
  Json j;
  j["holes_filled"] = r.holes_filled;
  j["efficiency"] = r.efficiency;
  j["l2_stretch"] = r.l2_stretch;
  j["linf_stretch"] = r.linf_stretch;
  j["flipped_faces"] = r.flipped_faces;
  j["winding"] = r.winding;
  j["base_vertices"] = r.base_vertices;
  j["optimization_passes"] = r.optimization_passes;
  j["times"] = Json{{"check", r.times.check},
                    {"simplify", r.times.simplify},
                    {"refine", r.times.refine},
                    {"total", r.times.total}};
  return j;
}

Json sphere_map_metrics_json(const SphereMapMetrics& m, bool with_targets) {
  Json j;
  j["vertices"] = m.vertices;
  j["faces"] = m.faces;
  j["radius_dev"] = m.radius_dev;
  j["flipped"] = m.flipped_majority;
  j["degenerate"] = m.degenerate_tol;
  j["closed"] = m.closed;
  if (m.closed) {
    j["winding"] = m.winding;
    j["fold_excess"] = m.fold_excess;
  }
  j["efficiency"] = m.efficiency;
  j["linf"] = m.linf;
  j["conformal_mean"] = m.conformal_mean;
  j["conformal_p95"] = m.conformal_p95;
  j["area_log_mean"] = m.area_log_mean;
  if (with_targets) j["feature_err_deg"] = m.feature_err_deg ? Json(*m.feature_err_deg) : Json(nullptr);
  j["flipped_exact"] = m.flipped;
  j["degenerate_exact"] = m.degenerate;
  j["l2_stretch"] = m.l2_stretch;
  return j;
}

}  // namespace spherekit::cli
