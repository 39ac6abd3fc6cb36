// `spherekit landmarks`: corresponding landmarks proposed for a set of meshes (issue 25).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>

#include "cli_common.h"
#include "commands.h"
#include "spherekit/pipeline/landmarks.h"

namespace spherekit::cli {
namespace {

std::string fmt2(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", x);
  return buf;
}

struct LandmarksArgs {
  pipeline::LandmarksJob job;
  std::string report;
  bool quiet = false;
};

int run_landmarks(const LandmarksArgs& a) {
  if (Status s = require_output_folders({a.report}); !s.ok()) return print_error(s);
  ProgressRenderer progress(a.quiet);
  auto r = [&] {
    ComputeScope graceful_cancel;
    return pipeline::propose_landmark_files(a.job, progress.callback());
  }();
  progress.finish();
  if (cancel_requested()) return print_error(cancelled_status());
  if (!r.ok()) return print_error(r.status());
  if (!a.report.empty())
    if (Status s = write_json_atomic(a.report, pipeline::to_json(a.job, *r)); !s.ok()) return print_error(s);
  if (a.quiet) return 0;
  const auto& p = r->proposal;
  std::printf("%zu landmarks (%d extremities) on %zu meshes, %.2f s\n", p.names.size(), p.extremities,
              a.job.meshes.size(), r->seconds);
  if (p.unstable_dropped > 0 || p.fine_matched > 0)
    std::printf("  %d unstable extremities left out (another peak as high beyond the tip), %d finer peaks matched\n",
                p.unstable_dropped, p.fine_matched);
  if (p.mismatch_dropped > 0)
    std::printf("  %d extremities left out: matched to another feature on some mesh (most of their distances wrong there)\n",
                p.mismatch_dropped);
  if (p.rim_matched > 0)
    std::printf("  %d points on the rims of corresponding openings; %d extremities left out (their distances to them disagree)\n",
                p.rim_matched, p.rim_outliers_dropped);
  for (std::size_t i = 0; i < a.job.meshes.size(); ++i) {
    const auto& m = p.members[i];
    double low = 1;
    for (double c : p.confidence[i]) low = std::min(low, c);
    // A left/right settled by orientation but not clearly (a weak sphere signal, or a runner-up
    // within the margin) is also flagged ambiguous: give the numbers that say why.
    std::string settled;
    if (m.mirror_resolved) {
      settled = ", left/right settled by orientation";
      if (m.mirror_ambiguous && m.sphere_checked)
        settled += " not clearly (sphere agreement " + fmt2(m.sphere_agreement) +
                   (m.sphere_runner_up > -2 ? ", runner-up " + fmt2(m.sphere_runner_up) : std::string()) + ")";
    }
    std::printf("  %s -> %s: cost %.4f, lowest confidence %.2f%s%s%s\n", a.job.meshes[i].c_str(), r->files[i].c_str(),
                m.cost, low, settled.c_str(),
                m.mirrored ? ", its cheapest match only reflected (a mirror image, or a pose of a near-symmetric shape: check)" : "", m.mirror_ambiguous ? ", left/right AMBIGUOUS: check on the page" : "");
  }
  return 0;
}

}  // namespace

void register_landmarks(CLI::App& app) {
  auto args = std::make_shared<LandmarksArgs>();
  CLI::App* cmd = add_command(
      app, "landmarks", "Propose corresponding landmarks for a set of meshes (NAME.lm.txt files)",
      "Finds the extremities of every mesh (maxima of the average geodesic distance: limb tips,\n"
      "head, tail, ears), matches them across the meshes by their pairwise geodesic distances\n"
      "(relative differences, normalised by sqrt(area)) and the area of their geodesic discs,\n"
      "settles left/right by sphere maps (each near-equal assignment becomes a constrained map;\n"
      "the one carrying the reference's shape best onto the member's wins: a left/right swap\n"
      "turns the body round; without sphere maps, or for meshes that are not genus 0, by the\n"
      "turns of matched triples), leaves out extremities whose peak is as high as another one beyond\n"
      "the tip (a head peaking at the nose on one mesh and at an ear on another) and matches that\n"
      "region's finer peaks (--fine-radius: ear tips) among themselves instead, adds each limb's\n"
      "most isolated tip (a hand's thumb: it fixes the arm's twist), adds the finer\n"
      "peaks elsewhere the sphere maps carry onto each other, optionally adds --extra-points\n"
      "further points (farthest-point sampling, located by their distances to the matched ones,\n"
      "front told from back by the turns of those seen from the point), and writes one\n"
      "`NAME.lm.txt` per mesh (beside it, or\n"
      "in --output-dir), the format `consistent` reads. --report writes every match's confidence;\n"
      "members whose left/right cannot be told are flagged there and in the summary.",
      "  spherekit landmarks cats/*.obj --report landmarks.json\n"
      "  spherekit landmarks a.obj b.obj c.obj --output-dir lm --extra-points 6\n"
      "  spherekit consistent -o coll a.obj b.obj c.obj --features lm/a.lm.txt lm/b.lm.txt lm/c.lm.txt");
  cmd->add_option("MESH", args->job.meshes, "input meshes")->required();
  cmd->add_option("--output-dir", args->job.output_dir, "write the .lm.txt files here (default: beside each mesh)");
  cmd->add_option("--report", args->report, "also write a JSON report here ('-': standard output)");
  cmd->add_flag("-q,--quiet", args->quiet, "print neither progress nor the summary (errors still)");
  auto& o = args->job.options;
  cmd->add_option("--extra-points", o.extra_points, "further points by farthest-point sampling")->check(CLI::Range(0, 1000));
  cmd->add_option("--max-extremities", o.max_extremities, "at most this many extremities per mesh")->check(CLI::Range(3, 16));
  cmd->add_option("--agd-sources", o.agd_sources, "sources of the average-geodesic-distance estimate")->check(CLI::Range(4, 1000));
  cmd->add_option("--extremity-radius", o.extremity_radius, "an extremity dominates this geodesic disc (x sqrt(area))")
      ->check(CLI::Range(0.001, 0.999));
  cmd->add_option("--tip-drop", o.tip_drop,
                  "move each extremity to the centre of its tip region: AGD within this of its peak (x sqrt(area); 0: the peak)")
      ->check(CLI::Range(0.0, 0.999));
  cmd->add_option("--fine-radius", o.fine_radius,
                  "finer AGD peaks (this disc radius, x sqrt(area)): an unstable extremity's, and others through the sphere maps; 0: off")
      ->check(CLI::Range(0.0, 0.999));
  cmd->add_flag("--no-rim-points{false}", o.rim_points,
                "no points on the rims of openings every mesh has (ends and side middles of eye and mouth holes)");
  cmd->add_flag("--no-sphere-orientation{false}", o.sphere_orientation,
                "settle left/right by the turns of matched triples only, without sphere maps");
  cmd->add_option("--sphere-effort", o.sphere_effort, "effort of the sphere maps that settle left/right")->check(CLI::Range(0, 5));
  cmd->add_option("--threads", o.threads, "worker threads of those maps, 0 = all cores (results do not depend on it)")
      ->check(CLI::NonNegativeNumber);
  cmd->callback([args] { set_exit_code(run_landmarks(*args)); });
}

}  // namespace spherekit::cli
