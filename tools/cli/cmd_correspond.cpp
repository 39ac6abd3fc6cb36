// `spherekit correspond`: surface points of one collection member mapped to another through
// the common sphere, and the measured error of that map against ground truth (the Princeton
// protocol of shared/tools/evalcorr.py).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>

#include "cli_common.h"
#include "commands.h"
#include "spherekit/pipeline/correspond.h"

namespace spherekit::cli {
namespace {

struct CorrespondArgs {
  pipeline::CorrespondJob job;
  bool json = false;
};

int run_correspond(const CorrespondArgs& a) {
  auto r = pipeline::correspond_members(a.job);
  if (!r.ok()) return print_error(r.status());
  if (!a.job.points.empty() && a.job.output.empty()) std::fputs(r->points_text.c_str(), stdout);
  if (r->points_in_holes)
    std::fprintf(stderr, "note: %d points fell into holes of %s (nearest surface point given)\n", r->points_in_holes,
                 a.job.b.c_str());
  if (r->error) {
    const CorrespondenceError& e = *r->error;
    if (a.json)
      std::printf("%s\n", pipeline::to_json(e).dump().c_str());
    else
      std::printf("%s -> %s: %d pairs, mean error %.4f, median %.4f, p90 %.4f, max %.4f; under 0.05: %.1f%%, under 0.1: %.1f%%\n",
                  a.job.a.c_str(), a.job.b.c_str(), e.pairs, e.mean, e.median, e.p90, e.max, 100 * e.under_005,
                  100 * e.under_01);
  }
  return 0;
}

}  // namespace

void register_correspond(CLI::App& app) {
  auto args = std::make_shared<CorrespondArgs>();
  CLI::App* cmd = add_command(
      app, "correspond", "Map surface points of one collection member to another through the sphere",
      "A and B are member meshes of the collection DIR ('spherekit consistent'). Each point of\n"
      "--points (`x y z` lines, snapped to the closest point of A's surface) goes through A's\n"
      "sphere map to the sphere and back through B's map onto B; the points on B are printed\n"
      "(`x y z` lines) or written to -o. With --corr A.corr.txt B.corr.txt (line k of both files:\n"
      "corresponding vertices) or --gt A.gt.txt B.gt.txt (template id per vertex), the map's\n"
      "error is measured like shared/tools/evalcorr.py: geodesic distance on B to the true\n"
      "partner / sqrt(area B), Dijkstra on B's edges plus the straight step into the triangle.",
      "  spherekit correspond cats cat0.obj cat2.obj --points picks.txt -o picks_on_cat2.txt\n"
      "  spherekit correspond cats cat0.obj cat2.obj --corr cat0.corr.txt cat2.corr.txt --json");
  cmd->add_option("DIR", args->job.collection, "collection folder")->required();
  cmd->add_option("A", args->job.a, "source mesh (a member)")->required();
  cmd->add_option("B", args->job.b, "target mesh (a member)")->required();
  cmd->add_option("--points", args->job.points, "points on A (`x y z` lines)");
  cmd->add_option("-o,--output", args->job.output, "write the points on B here (default: stdout)");
  cmd->add_option("--corr", args->job.corr, "ground truth: A.corr.txt B.corr.txt")->expected(2);
  cmd->add_option("--gt", args->job.gt, "ground truth: A.gt.txt B.gt.txt")->expected(2);
  cmd->add_option("--samples", args->job.samples, "measure at most N evenly spaced pairs (default: all)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--json", args->json, "print the error measures as one JSON line (evalcorr.py's keys)");
  cmd->callback([args] { set_exit_code(run_correspond(*args)); });
}

}  // namespace spherekit::cli
