// `spherekit bench`: time, peak memory, efficiency and Linf stretch of `param` per mesh, side by side
// with the reference implementation: run in the same session (--reference-dir), else its
// figures recorded in shared/docs/EVALUATION.md §4.
//
// Each mesh runs in a child process (`spherekit param ... --report`), so CPU time and peak
// resident memory are the mesh's own, measured by the kernel (wait4, and the child's own
// VmHWM for ours), not accumulated over the whole benchmark or hidden by an allocator that
// keeps freed memory.
#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <thread>
#include <string>
#include <vector>

#include "cli_common.h"
#include "commands.h"
#include "sample_collection.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/file_status.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/metrics.h"
#include "spherekit/version.h"

extern char** environ;

namespace fs = std::filesystem;

namespace spherekit::cli {
namespace {

// Praun & Hoppe's SphereParam at default effort on a 2-core machine (EVALUATION.md §4):
// evaluator efficiency (holes: real faces only), total CPU seconds (PM + SP), peak MB.
struct Reference {
  const char* file;
  double efficiency;
  double cpu_seconds;
  double peak_mb;
};
constexpr Reference kReference[] = {
    {"knight.obj", 0.3095, 4.2, 5},        {"woody.obj", 0.9151, 3.5, 6},      {"spot.obj", 0.7182, 5.2, 10},
    {"max_planck.obj", 0.8993, 5.9, 14},   {"gargoyle.obj", 0.6667, 13.8, 23}, {"armadillo.obj", 0.4128, 20.0, 27},
    {"bunny.obj", 0.7064, 31.2, 69},       {"horse.obj", 0.3967, 49.5, 93},    {"igea.ply", 0.9617, 115.7, 252},
};

const Reference* find_reference(const std::string& path) {
  const std::string name = file_name(path);
  for (const Reference& r : kReference)
    if (name == r.file) return &r;
  return nullptr;
}

struct BenchArgs {
  std::vector<std::string> meshes;
  std::string meshes_dir;
  std::string output;
  std::optional<int> effort;
  std::optional<int> threads;
  std::string reference_dir, reference_script;
  bool quiet = false;  // no progress, table or summary (errors and warnings still)
};

bool has_meshes(const fs::path& dir) {
  std::error_code ec;
  return fs::is_regular_file(dir / "manifest.json", ec) || fs::is_regular_file(dir / kReference[0].file, ec);
}

// The dev meshes live in shared/meshes beside the checkout; the program cannot know where
// its sources were, so look where that folder usually is: $SPHEREKIT_SHARED_DIR, then
// upwards from the working directory (run from the checkout or a build folder), then
// upwards from the executable (build/tools/cli/spherekit -> checkout/../shared).
std::optional<fs::path> find_shared_meshes() {
  std::error_code ec;
  if (const char* env = std::getenv("SPHEREKIT_SHARED_DIR"); env && *env) {
    const fs::path p = fs::path(env) / "meshes";
    return has_meshes(p) ? std::optional<fs::path>(p) : std::nullopt;
  }
  std::vector<fs::path> starts = {fs::current_path(ec)};
  if (fs::path exe = fs::read_symlink("/proc/self/exe", ec); !ec) starts.push_back(exe.parent_path());
  for (fs::path dir : starts) {
    for (int up = 0; up < 6 && !dir.empty(); ++up, dir = dir.parent_path()) {
      if (has_meshes(dir / "shared" / "meshes")) return dir / "shared" / "meshes";
      if (dir == dir.parent_path()) break;
    }
  }
  return std::nullopt;
}

struct ChildRun {
  int exit_code = -1;
  double cpu_seconds = 0, wall_seconds = 0, peak_mb = 0;
};

// Runs program `exe` with `args` and extra environment entries `env` ("NAME=value"); stdin
// and stdout go to /dev/null (the child is --quiet anyway), stderr stays ours so its
// one-line error shows up in the bench output. `argv0` is the child's name (default `exe`).
Result<ChildRun> run_program(const fs::path& exe, const std::vector<std::string>& args,
                             const std::vector<std::string>& env = {}, const std::string& argv0 = {}) {
  std::vector<std::string> argv_strings = {argv0.empty() ? exe.string() : argv0};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& s : argv_strings) argv.push_back(s.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_strings = env;
  std::vector<char*> envp;
  for (std::string& s : env_strings) envp.push_back(s.data());
  for (char** e = environ; *e; ++e) envp.push_back(*e);
  envp.push_back(nullptr);

  // A child's ru_maxrss includes the address space it started in: posix_spawn's child shares
  // ours until exec, and exec folds that space's high-water mark into the child's peak. After
  // the bench has read and measured a large mesh (igea) every later child's peak was ours
  // (generated stress shapes: 39 MB in the bench, 22 MB alone). Resetting our high-water mark
  // to the current resident set first bounds that share by what we hold now (Linux >= 4.0).
  if (FILE* f = std::fopen("/proc/self/clear_refs", "w")) {
    std::fputs("5", f);
    std::fclose(f);
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  Stopwatch wall;
  pid_t pid = 0;
  const int err = posix_spawn(&pid, exe.c_str(), &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  if (err != 0) return Status(ErrorCode::Internal, std::string("cannot start child process: ") + std::strerror(err));

  int status = 0;
  rusage usage{};
  pid_t waited = 0;
  {
    // While we wait, a signal is forwarded to the child, which cancels and exits; then we
    // clean up and exit 130 ourselves (see install_signal_handlers).
    set_child_pid(pid);
    ComputeScope graceful_cancel;
    do {
      waited = wait4(pid, &status, 0, &usage);
    } while (waited < 0 && errno == EINTR);
    set_child_pid(0);
  }
  if (waited < 0) return Status(ErrorCode::Internal, std::string("wait4 failed: ") + std::strerror(errno));

  ChildRun run;
  run.wall_seconds = wall.seconds();
  auto secs = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); };
  run.cpu_seconds = secs(usage.ru_utime) + secs(usage.ru_stime);
  run.peak_mb = static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in kB on Linux
  if (WIFEXITED(status))
    run.exit_code = WEXITSTATUS(status);
  else if (WIFSIGNALED(status))
    run.exit_code = 128 + WTERMSIG(status);
  return run;
}

// Runs this executable with `args`, through /proc/self/exe: that is this very binary even
// when the file it was started from has been replaced since (a rebuild or a package upgrade
// during a long bench), where the link's target names a deleted file and spawning by that
// name failed ("cannot start child process") for every later mesh. The child keeps the
// file's name as argv[0].
Result<ChildRun> run_child(const std::vector<std::string>& args) {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return Status(ErrorCode::Internal, "cannot locate the spherekit executable: " + ec.message());
  std::string name = exe.string();
  if (const std::string gone = " (deleted)"; name.ends_with(gone)) name.resize(name.size() - gone.size());
  return run_program("/proc/self/exe", args, {}, name);
}

// The reference implementation measured in the same run (--reference-dir): Praun & Hoppe's
// SphereParam built by shared/anchors/mpl/build_mpl.sh into that folder, run through the
// kit's mpl_sphereparam.sh on the same mesh right after ours (alternating, so both see the
// same machine load), timed the same way, its map measured by our evaluator.
struct ReferenceKit {
  fs::path mpl_root, script;
  int threads = 2;
};

Result<ReferenceKit> find_reference_kit(const std::string& dir, const std::string& script, int threads) {
  std::error_code ec;
  ReferenceKit kit;
  kit.mpl_root = fs::absolute(dir, ec);
  if (!fs::is_regular_file(kit.mpl_root / "bin" / "unix" / "SphereParam", ec))
    return Status(ErrorCode::IoError, dir + ": no bin/unix/SphereParam (build it with shared/anchors/mpl/build_mpl.sh)");
  if (!script.empty()) {
    kit.script = script;
  } else if (auto meshes = find_shared_meshes()) {
    kit.script = meshes->parent_path() / "anchors" / "mpl" / "mpl_sphereparam.sh";
  }
  if (kit.script.empty() || !fs::is_regular_file(kit.script, ec))
    return Status(ErrorCode::IoError, "cannot find mpl_sphereparam.sh (give --reference-script)");
  kit.threads = threads > 0 ? threads : 2;
  return kit;
}

// What our evaluator measures on a written sphere map, ours or the reference's: both are
// read back from their files and evaluated on the original mesh (for a mesh with holes, its
// real faces only), as shared/tools/evalsphere.py does, so the two Linf figures are measured
// the same way (EVALUATION.md §1: normalised max singular value).
struct MapMeasures {
  double efficiency = 0, linf = 0;
  int flipped = -1;
};

Result<MapMeasures> measure_map(const TriMesh& surface, const std::string& sphere) {
  formats::ReadOptions lenient;
  lenient.polygons = formats::PolygonPolicy::Triangulate;
  auto map = formats::read_mesh(sphere, lenient);
  if (!map.ok()) return with_file(map.status(), sphere);
  if (map->V.rows() != surface.V.rows())
    return Status(ErrorCode::InvalidInput, sphere + ": the sphere map has another vertex count than the mesh");
  SPHEREKIT_ASSIGN_OR_RETURN(SphereMapMetrics e, evaluate_sphere_map(surface, map->V));
  return MapMeasures{e.efficiency, e.linf, e.flipped};
}

struct MeasuredReference {
  ChildRun run;
  MapMeasures map;
};

Result<MeasuredReference> run_reference(const ReferenceKit& kit, const TriMesh& surface, const std::string& mesh,
                                        const std::string& sphere) {
  MeasuredReference m;
  SPHEREKIT_ASSIGN_OR_RETURN(m.run, run_program("/bin/bash", {kit.script.string(), mesh, sphere},
                                                  {"MPL_ROOT=" + kit.mpl_root.string(),
                                                   "OMP_NUM_THREADS=" + std::to_string(kit.threads)}));
  if (m.run.exit_code != 0) return m;
  SPHEREKIT_ASSIGN_OR_RETURN(m.map, measure_map(surface, sphere));
  return m;
}

// Issue 20's quality rule beside the efficiency one: our Linf stretch at most this many
// times the reference's on the same mesh, measured in the same run.
constexpr double kLinfRatioLimit = 1.5;

std::string ratio(double ours, double ref) { return ref > 0 ? format_text("%.2f", ours / ref) : std::string("-"); }

int run_bench(const BenchArgs& a) {
  // The mesh list: explicit files, else the dev meshes of --meshes-dir or shared/meshes,
  // else the built-in samples (so the command always has something to measure).
  std::vector<std::string> meshes = a.meshes;
  std::string source = "command line";
  const fs::path work = fs::temp_directory_path() / ("spherekit-bench-" + std::to_string(getpid()));
  std::error_code ec;
  fs::create_directories(work, ec);
  if (ec) return print_error(Status(ErrorCode::IoError, work.string() + ": cannot create folder: " + ec.message()));
  // Remove the per-mesh outputs (and samples) on every return path.
  struct Cleanup {
    fs::path dir;
    ~Cleanup() {
      std::error_code ignored;
      fs::remove_all(dir, ignored);
    }
  } cleanup{work};

  if (meshes.empty()) {
    std::optional<fs::path> dir;
    if (!a.meshes_dir.empty()) {
      if (!fs::is_directory(a.meshes_dir, ec))
        return print_error(Status(ErrorCode::IoError, a.meshes_dir + ": not a folder"));
      dir = fs::path(a.meshes_dir);
    } else {
      dir = find_shared_meshes();
    }
    if (dir) {
      for (const Reference& r : kReference)
        if (fs::is_regular_file(*dir / r.file, ec)) meshes.push_back((*dir / r.file).string());
      source = dir->string();
    }
    if (meshes.empty()) {
      auto collection = samples::make_sample_collection();
      if (!collection.ok()) return print_error(collection.status());
      const fs::path sample_dir = work / "samples";
      fs::create_directories(sample_dir, ec);
      if (Status s = samples::write_sample_collection(sample_dir.string(), collection.value()); !s.ok())
        return print_error(s);
      for (const samples::SampleMesh& m : collection.value()) meshes.push_back((sample_dir / (m.name + ".obj")).string());
      source = "built-in samples";
    }
  }
  std::optional<ReferenceKit> kit;
  if (!a.reference_dir.empty()) {
    auto k = find_reference_kit(a.reference_dir, a.reference_script, a.threads.value_or(0));
    if (!k.ok()) return print_error(k.status());
    kit = k.value();
  }
  if (!a.quiet)
    std::printf("spherekit %s bench: %zu meshes from %s; reference: %s\n", kVersion, meshes.size(), source.c_str(),
                kit ? ("measured in this run (" + kit->mpl_root.string() + ")").c_str()
                    : "figures recorded in EVALUATION.md (another machine)");

  Table table({"mesh", "V", "F", "eff", "ref eff", "d eff", "Linf", "ref Linf", "Linf ratio", "flips", "CPU s",
               "ref CPU", "CPU ratio", "wall s", "peak MB", "ref MB", "MB ratio", "status"});
  Json rows = Json::array();
  double cpu_total = 0, ref_cpu_total = 0, cpu_total_with_ref = 0, wall_total = 0;
  double worst_mb_ratio = 0, worst_eff_delta = 1e300, worst_linf_ratio = 0;
  int worst = 0, failed = 0, flipped_total = 0, linf_compared = 0, reference_flipped_total = 0;
  Json linf_over = Json::array();  // meshes whose Linf ratio breaks the rule
  // Meshes on which the reference's script failed (no map), with how long it ran: on large
  // generated shapes SphereParam exits with an error after minutes (README, large meshes).
  Json reference_failed = Json::array();
  for (size_t i = 0; i < meshes.size(); ++i) {
    const std::string& mesh = meshes[i];
    const std::string sphere = (work / (std::to_string(i) + ".sphere.obj")).string();
    const std::string report_path = (work / (std::to_string(i) + ".json")).string();
    std::vector<std::string> args = {"param", mesh, "-o", sphere, "--report", report_path, "--quiet"};
    if (a.effort) args.insert(args.end(), {"--effort", std::to_string(*a.effort)});
    if (a.threads) args.insert(args.end(), {"--threads", std::to_string(*a.threads)});
    if (!a.quiet) std::fprintf(stderr, "[bench] %zu/%zu %s\n", i + 1, meshes.size(), mesh.c_str());

    auto child = run_child(args);
    if (!child.ok()) return print_error(child.status());
    if (cancel_requested()) return print_error(cancelled_status());
    ChildRun& c = child.value();
    // The original mesh, for measuring both maps with the same evaluator. Unreadable only
    // when our run failed on it too (then the reference, if any, cannot be measured).
    auto surface = formats::read_mesh(mesh);
    const Reference* ref = find_reference(mesh);
    Reference measured{};
    std::optional<double> ref_linf;  // only measured in this run: EVALUATION.md records none
    std::optional<int> ref_flipped;  // likewise
    Json ref_failure;                // the reference's run when it produced no map
    if (kit) {
      // Measured side by side: replaces the recorded figures for this mesh.
      if (!surface.ok()) return print_error(with_file(surface.status(), mesh));
      auto r = run_reference(*kit, surface.value(), mesh,
                             (work / (std::to_string(i) + ".reference.sphere.obj")).string());
      if (!r.ok()) return print_error(r.status());
      if (cancel_requested()) return print_error(cancelled_status());
      ref = nullptr;
      if (r->run.exit_code == 0) {
        measured = Reference{"", r->map.efficiency, r->run.cpu_seconds, r->run.peak_mb};
        ref = &measured;
        ref_linf = r->map.linf;
        ref_flipped = r->map.flipped;
      } else {
        std::fprintf(stderr, "[bench] the reference failed on %s (exit %d after %.0f s)\n", mesh.c_str(),
                     r->run.exit_code, r->run.wall_seconds);
        ref_failure = Json{{"status", "failed"},
                           {"exit_code", r->run.exit_code},
                           {"cpu_seconds", r->run.cpu_seconds},
                           {"wall_seconds", r->run.wall_seconds},
                           {"peak_mb", r->run.peak_mb}};
        reference_failed.push_back(file_name(mesh));
      }
    }
    Json row{{"mesh", mesh}, {"exit_code", c.exit_code}, {"cpu_seconds", c.cpu_seconds},
             {"wall_seconds", c.wall_seconds}, {"peak_mb", c.peak_mb}};
    if (!ref_failure.is_null()) row["reference"] = ref_failure;
    const std::string ref_eff_cell = ref ? format_text("%.4f", ref->efficiency) : ref_failure.is_null() ? "-" : "failed";
    cpu_total += c.cpu_seconds;
    wall_total += c.wall_seconds;

    Json report;
    std::optional<MapMeasures> ours;
    if (c.exit_code == 0) {
      auto text = formats::read_file(report_path);
      if (text.ok()) report = Json::parse(text.value(), nullptr, /*allow_exceptions=*/false);
      if (surface.ok()) {
        auto m = measure_map(surface.value(), sphere);
        if (m.ok())
          ours = m.value();
        else
          std::fprintf(stderr, "[bench] %s\n", m.status().message().c_str());
      }
    }
    if (c.exit_code != 0 || report.is_discarded() || !report.is_object() || !ours) {
      ++failed;
      worst = worse_exit_code(worst, c.exit_code != 0 ? c.exit_code : error_code_exit_code(ErrorCode::Internal));
      row["status"] = "failed";
      table.add_row({file_name(mesh), "", "", "", ref_eff_cell, "", "",
                     ref_linf ? format_text("%.2f", *ref_linf) : "-", "", "", format_text("%.1f", c.cpu_seconds),
                     ref ? format_text("%.1f", ref->cpu_seconds) : "-", "", format_text("%.1f", c.wall_seconds),
                     format_text("%.0f", c.peak_mb), ref ? format_text("%.0f", ref->peak_mb) : "-", "",
                     format_text("FAILED (exit %d)", c.exit_code)});
      rows.push_back(std::move(row));
      continue;
    }
    // Our peak: what param measures of its own address space (VmHWM), exact; wait4's holds
    // at least our current resident set (run_program).
    if (const double own = report.value("peak_rss_mb", 0.0); own > 0) {
      c.peak_mb = own;
      row["peak_mb"] = own;
    }
    const double eff = report.value("efficiency", 0.0);
    const int flips = report.value("flipped_faces", -1);
    flipped_total += flips;
    row["status"] = "ok";
    row["V"] = report.value("V", 0);
    row["F"] = report.value("F", 0);
    row["efficiency"] = eff;
    row["linf"] = ours->linf;
    row["flipped_faces"] = flips;
    row["winding"] = report.value("winding", 0.0);
    row["times"] = report.value("times", Json::object());
    if (ref) {
      row["reference"] = Json{{"efficiency", ref->efficiency}, {"cpu_seconds", ref->cpu_seconds}, {"peak_mb", ref->peak_mb}};
      row["efficiency_delta"] = eff - ref->efficiency;
      row["cpu_ratio"] = c.cpu_seconds / ref->cpu_seconds;
      row["peak_mb_ratio"] = c.peak_mb / ref->peak_mb;
      ref_cpu_total += ref->cpu_seconds;
      cpu_total_with_ref += c.cpu_seconds;
      worst_mb_ratio = std::max(worst_mb_ratio, c.peak_mb / ref->peak_mb);
      worst_eff_delta = std::min(worst_eff_delta, eff - ref->efficiency);
    }
    if (ref_flipped) {
      row["reference"]["flipped_faces"] = *ref_flipped;
      reference_flipped_total += std::max(0, *ref_flipped);
    }
    if (ref_linf) {
      const double linf_ratio = ours->linf / *ref_linf;
      row["reference"]["linf"] = *ref_linf;
      row["linf_ratio"] = linf_ratio;
      ++linf_compared;
      worst_linf_ratio = std::max(worst_linf_ratio, linf_ratio);
      if (!(linf_ratio <= kLinfRatioLimit)) linf_over.push_back(file_name(mesh));
    }
    table.add_row({file_name(mesh), std::to_string(report.value("V", 0)), std::to_string(report.value("F", 0)),
                   format_text("%.4f", eff), ref_eff_cell,
                   ref ? format_text("%+.4f", eff - ref->efficiency) : "-", format_text("%.2f", ours->linf),
                   ref_linf ? format_text("%.2f", *ref_linf) : "-", ref_linf ? ratio(ours->linf, *ref_linf) : "-",
                   std::to_string(flips), format_text("%.2f", c.cpu_seconds),
                   ref ? format_text("%.1f", ref->cpu_seconds) : "-", ref ? ratio(c.cpu_seconds, ref->cpu_seconds) : "-",
                   format_text("%.2f", c.wall_seconds), format_text("%.0f", c.peak_mb),
                   ref ? format_text("%.0f", ref->peak_mb) : "-", ref ? ratio(c.peak_mb, ref->peak_mb) : "-", "ok"});
    rows.push_back(std::move(row));
  }

  const bool any_ref = ref_cpu_total > 0;
  if (!a.quiet) {
    std::printf("\n");
    table.print();
    std::printf("\ntotal CPU %.1f s, wall %.1f s", cpu_total, wall_total);
    if (any_ref)
      std::printf("; on meshes with reference figures: CPU %.1f s vs %.1f s (ratio %.2f), worst efficiency delta "
                  "%+.4f, worst memory ratio %.2f",
                  cpu_total_with_ref, ref_cpu_total, cpu_total_with_ref / ref_cpu_total, worst_eff_delta,
                  worst_mb_ratio);
    std::printf("\n%d failed, %d flipped faces in total\n", failed, flipped_total);
    if (kit) {
      std::string names;
      for (const Json& name : reference_failed) names += (names.empty() ? "" : ", ") + name.get<std::string>();
      std::printf("reference: %d flipped faces in its maps; failed on %zu meshes%s\n", reference_flipped_total,
                  reference_failed.size(), names.empty() ? "" : (" (" + names + ")").c_str());
    }
    if (linf_compared > 0) {
      std::string over;
      for (const Json& name : linf_over) over += (over.empty() ? "" : ", ") + name.get<std::string>();
      std::printf("Linf rule (ours <= %.1fx the reference's): %s, %zu of %d meshes above, worst ratio %.2f%s\n",
                  kLinfRatioLimit, linf_over.empty() ? "pass" : "FAIL", linf_over.size(), linf_compared,
                  worst_linf_ratio, linf_over.empty() ? "" : ("; above on " + over).c_str());
    }
  }

  if (!a.output.empty()) {
    Json j;
    j["version"] = kVersion;
    j["source"] = source;
    j["options"] = Json{{"effort", a.effort ? Json(*a.effort) : Json("default")},
                        {"threads", a.threads ? Json(*a.threads) : Json("default")}};
    j["hardware_threads"] = std::thread::hardware_concurrency();
    j["rows"] = std::move(rows);
    Json totals{{"meshes", meshes.size()}, {"failed", failed}, {"flipped_faces", flipped_total},
                {"cpu_seconds", cpu_total}, {"wall_seconds", wall_total}};
    if (any_ref) {
      totals["cpu_seconds_with_reference"] = cpu_total_with_ref;
      totals["reference_cpu_seconds"] = ref_cpu_total;
      totals["cpu_ratio"] = cpu_total_with_ref / ref_cpu_total;
      totals["worst_efficiency_delta"] = worst_eff_delta;
      totals["worst_peak_mb_ratio"] = worst_mb_ratio;
    }
    if (kit) {
      totals["reference_flipped_faces"] = reference_flipped_total;
      totals["reference_failed"] = std::move(reference_failed);
    }
    if (linf_compared > 0) {
      totals["linf_compared"] = linf_compared;
      totals["worst_linf_ratio"] = worst_linf_ratio;
      totals["linf_ratio_limit"] = kLinfRatioLimit;
      totals["linf_rule_pass"] = linf_over.empty();
      totals["linf_over_limit"] = std::move(linf_over);
    }
    j["totals"] = std::move(totals);
    if (Status s = write_json_atomic(a.output, j); !s.ok()) return print_error(s);
    if (!a.quiet) std::printf("wrote %s\n", a.output.c_str());
  }
  return worst;
}

}  // namespace

void register_bench(CLI::App& app) {
  auto args = std::make_shared<BenchArgs>();
  CLI::App* cmd = add_command(
      app, "bench", "Time, memory, efficiency and Linf of param per mesh vs. the reference",
      "Benchmark `param`: run it on each mesh in a child process (so CPU time and peak memory are\n"
      "per mesh) and print a table of vertices, faces, efficiency, Linf stretch, flipped faces,\n"
      "CPU and wall seconds and peak MB, with the reference implementation's figures and the\n"
      "ratios ours/reference: measured in the same run with --reference-dir (alternating ours and\n"
      "its runs mesh by mesh; both maps' Linf by the same evaluator, with a pass/fail line for\n"
      "Linf <= 1.5x the reference's; its maps' flipped faces; a mesh it fails on is listed with\n"
      "how long it ran), else the figures recorded in EVALUATION.md §4 on another machine (no\n"
      "Linf there). Default meshes: the dev meshes (knight ... igea.ply) found in\n"
      "--meshes-dir, else in $SPHEREKIT_SHARED_DIR/meshes or a shared/meshes folder above the\n"
      "working directory or the executable; else the built-in samples.",
      "  spherekit bench -o bench.json\n"
      "  spherekit bench --meshes-dir ../shared/meshes --effort 2 --threads 2 -o bench.json\n"
      "  spherekit bench spot.obj gargoyle.obj\n"
      "  spherekit bench --reference-dir $HOME/mpl --threads 1 -o bench.json");
  cmd->add_option("MESH", args->meshes, "meshes to run (default: the dev meshes)");
  cmd->add_option("--meshes-dir", args->meshes_dir, "folder holding the dev meshes (knight.obj ... igea.ply)");
  cmd->add_option("--effort", args->effort, "passed to param (default: param's)")->check(CLI::Range(0, 5));
  cmd->add_option("--threads", args->threads, "passed to param (default: param's)")->check(CLI::NonNegativeNumber);
  cmd->add_option("-o,--output", args->output, "write all rows and totals as JSON here");
  cmd->add_option("--reference-dir", args->reference_dir,
                  "MPL folder built by shared/anchors/mpl/build_mpl.sh: run the reference on each mesh right after "
                  "ours and compare with what it measures here, not with recorded figures");
  cmd->add_option("--reference-script", args->reference_script,
                  "mpl_sphereparam.sh (default: shared/anchors/mpl/ beside the dev meshes)");
  cmd->add_flag("-q,--quiet", args->quiet, "print neither progress nor the table (errors and warnings still)");
  cmd->callback([args] { set_exit_code(run_bench(*args)); });
}

}  // namespace spherekit::cli
