// `spherekit run`: the main job (spherekit::pipeline's run_main_job, main_job.h). Checks,
// parameterizes and evaluates every input mesh (the built-in samples when none is given),
// converts each map, maps a collection consistently, converts it and runs the applications,
// and writes report.json and the results page. This file parses flags, calls the job and
// prints what it tells as it goes.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli_common.h"
#include "commands.h"
#include "spherekit/pipeline/main_job.h"

namespace spherekit::cli {
namespace {

struct RunArgs {
  pipeline::MainJob job;
  bool quiet = false;
};

// Prints each stage's summary as the job reports it (as the stage's own command would).
class RunPrinter : public pipeline::MainJobObserver {
 public:
  explicit RunPrinter(bool quiet) : quiet_(quiet) {}
  int worst = 0;

  ProgressFn progress(const std::string& prefix) override {
    renderer_ = std::make_unique<ProgressRenderer>(quiet_, prefix);
    return renderer_->callback();
  }
  bool keep_going() override { return !cancel_requested(); }
  void samples_written(const std::string& dir) override {
    std::printf("Built-in samples written to %s\n", dir.c_str());
  }
  void failed(const Status& error) override {
    finish();
    worst = worse_exit_code(worst, print_error(error));
  }
  void note(const std::string& text) override {
    finish();
    std::fprintf(stderr, "spherekit: note: %s\n", text.c_str());
  }
  void heading(const std::string& text) override {
    finish();
    if (!quiet_) std::printf("\n%s\n", text.c_str());
    std::fflush(stdout);
  }
  void collection_made(const pipeline::MakeCollectionResult& r, const std::string& output) override {
    finish();
    print_collection_warning(r);
    if (!quiet_) print_consistent_summary(r, output, r.wall_seconds);
  }
  void correspondence(const Json& col) override {
    std::printf("correspondence vs. ground truth over %d ordered pairs: mean error %.4f, %.1f%% under 0.05, %.1f%% "
                "under 0.1 (geodesic / sqrt(area))\n",
                col.value("pairs", 0), col.value("mean_error", 0.0), 100 * col.value("under_0.05", 0.0),
                100 * col.value("under_0.1", 0.0));
  }
  void assets_converted(const pipeline::ConvertCollectionResult& r) override {
    finish();
    if (!quiet_) print_collection_summary(r);
  }
  void transferred(const pipeline::TransferResult& r, const pipeline::TransferJob& job) override {
    if (!quiet_) print_transfer_summary(r, job);
  }
  void round_trip(const std::string& a, const std::string& b, double error) override {
    if (!quiet_)
      std::printf("colour round trip %s -> %s -> %s: mean error %.4f (RGB in [0, 1])\n", a.c_str(), b.c_str(), a.c_str(),
                  error);
  }
  void morphed(const pipeline::MorphResult& r, const pipeline::MorphJob& job) override {
    finish();
    if (!quiet_) print_morph_summary(r, job);
  }
  void pca_done(const pipeline::PcaResult& r, const pipeline::PcaJob& job) override {
    finish();
    if (!quiet_) print_pca_summary(r, job);
  }
  void finish() {
    if (renderer_) renderer_->finish();
    renderer_.reset();
  }

 private:
  bool quiet_;
  std::unique_ptr<ProgressRenderer> renderer_;
};

int run_main(const RunArgs& a) {
  RunPrinter printer(a.quiet);
  auto r = [&] {
    ComputeScope graceful_cancel;
    return pipeline::run_main_job(a.job, printer);
  }();
  printer.finish();
  if (cancel_requested()) return print_error(cancelled_status());
  if (!r.ok()) return print_error(r.status());
  for (const std::string& w : r->warnings) std::fprintf(stderr, "spherekit: warning: %s\n", w.c_str());
  std::printf("\n");
  Table table(r->table_columns);
  for (const auto& row : r->table) table.add_row(row);
  table.print();
  std::printf("\n%d of %d meshes mapped in %.1f s; sphere maps, geometry images, %sreport.json in:\n%s\n"
              "results page: %s/index.html\n",
              r->meshes - r->failed, r->meshes, r->wall_seconds,
              r->collection_done ? "the collection's assets and applications, " : "", r->output_dir.c_str(),
              r->output_dir.c_str());
  return printer.worst;
}

}  // namespace

void register_run(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* cmd = add_command(
      app, "run", "The main job: check, map and measure meshes (default: built-in samples)",
      "The main job. For each MESH (default: the built-in sample collection, written first to\n"
      "OUT/input): check it, map it bijectively onto the sphere (as `param`), write\n"
      "OUT/<name>.sphere.obj, measure the map (as `eval`), build its 129 x 129 octahedral\n"
      "geometry image OUT/<name>.gim129.exr with the remesh PSNR (100000 samples per direction),\n"
      "PNG previews and 3 Draco glTF levels of detail (as `convert --size 129 --lods 3`).\n"
      "Then, for the samples, or for two or more meshes that each have a feature file beside\n"
      "them (NAME.lm.txt, as `consistent` reads them): map them consistently into\n"
      "OUT/collection (as `consistent`); convert every member into OUT/assets (as `convert\n"
      "--collection`: images, previews, LODs, Catmull-Clark cage 8 with 9 x 9 scalar\n"
      "displacement, the morph-target glTF); and run the applications into OUT/apps (colours\n"
      "and normals transferred from the first member, a morph of the first two, PCA with the\n"
      "compression experiment). For the samples it also measures the correspondence against\n"
      "their ground truth. Finally it writes OUT/report.json and OUT/index.html, a results page\n"
      "(3-D viewer of the glTF files with levels of detail and morph sliders, the images, plots\n"
      "and tables) that works opened from disk or served; its 3-D viewer needs three.js from npm\n"
      "(scripts/setup_viewer.sh; without it the page says so and shows the rest).\n"
      "A mesh that fails is reported and skipped; the exit code is then that of the worst failure.\n",
      "  spherekit run                              # built-in samples -> ./spherekit-out\n"
      "  spherekit run spot.obj bunny.obj -o maps   # your meshes -> ./maps\n"
      "  spherekit run ../shared/meshes/*.obj --effort 3");
  cmd->add_option("MESH", args->job.meshes, "input meshes (default: the built-in samples)");
  cmd->add_option("-o,--output", args->job.output, "output folder (created if missing)")->capture_default_str();
  cmd->add_flag("-q,--quiet", args->quiet, "no progress output (the table is still printed)");
  add_sphere_param_options(*cmd, args->job.options);
  cmd->callback([args] { set_exit_code(run_main(*args)); });
}

}  // namespace spherekit::cli
