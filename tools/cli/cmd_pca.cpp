// `spherekit pca`: the average shape and principal components of a collection (paper Fig. 1),
// the reconstruction error versus the number of components, and the compression experiment
// (PCA model versus Draco on each shape). The algorithms are convert/shape_pca.h and
// convert/shape_compression.h; this file reads, calls, tabulates, plots and writes.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>

#include "cli_common.h"
#include "commands.h"
#include "spherekit/pipeline/apps.h"

namespace spherekit::cli {
namespace {

struct PcaArgs {
  pipeline::PcaJob job;
  bool no_compression = false;
  bool quiet = false;
};


int run_pca(PcaArgs& a) {
  a.job.compression = !a.no_compression;
  ProgressRenderer progress(a.quiet, "pca");
  auto r = [&] {
    ComputeScope graceful_cancel;
    return pipeline::shape_pca(a.job, progress.callback(), [] { return !cancel_requested(); });
  }();
  progress.finish();
  if (!r.ok()) return print_error(cancel_requested() ? cancelled_status() : r.status());
  if (!a.quiet) print_pca_summary(r.value(), a.job);
  return 0;
}

}  // namespace

void register_pca(CLI::App& app) {
  auto args = std::make_shared<PcaArgs>();
  CLI::App* cmd = add_command(
      app, "pca", "Average shape and principal components of a collection, error and compression tables",
      "Every member of the collection DIR is remeshed through its geometry image (--size; the\n"
      "remeshes share one connectivity and their vertices correspond) and the remeshes' PCA is\n"
      "taken (paper Fig. 1). Writes the folder OUT: mean.obj, pcK_plus.obj / pcK_minus.obj (the\n"
      "mean +- 2 standard deviations along component K), pca.glb (base = mean, one morph target\n"
      "per component at one standard deviation), pca_errors.csv and pca_errors.png (RMS vertex\n"
      "error and PSNR of every member reconstructed from 0..r components), compression.csv and\n"
      "compression.png (bytes per shape versus error: the PCA model at float32 / 16 / 12 bits\n"
      "against Draco on each remesh alone at 8..16 bits) and pca.json with everything. OUT is\n"
      "replaced only when it is empty or a previous pca output.",
      "  spherekit pca cats -o cats_pca\n"
      "  spherekit pca heads -o heads_pca --size 129 --no-compression");
  cmd->add_option("DIR", args->job.collection, "collection folder")->required();
  cmd->add_option("-o,--output", args->job.output, "output folder")->required();
  cmd->add_option("--size", args->job.size, "geometry-image size of the remeshes, 2^k+1")->capture_default_str();
  cmd->add_flag("--no-compression", args->no_compression, "skip the compression experiment");
  add_threads_option(*cmd, args->job.threads);
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing but errors");
  cmd->callback([args] { set_exit_code(run_pca(*args)); });
}

}  // namespace spherekit::cli
