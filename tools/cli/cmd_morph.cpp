// `spherekit morph`: a morph sequence between two members of a collection, from their
// consistent remeshes (identical connectivity), blended in a feature-aligned frame; written as
// a glTF whose morph targets are the frames (with an animation playing them) and as one OBJ
// per frame. The algorithm is convert/morph.h.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>

#include "cli_common.h"
#include "commands.h"
#include "spherekit/pipeline/apps.h"

namespace spherekit::cli {
namespace {

struct MorphArgs {
  pipeline::MorphJob job;
  bool no_align = false;
  bool quiet = false;
};

int run_morph(MorphArgs& a) {
  a.job.align = !a.no_align;
  ProgressRenderer progress(a.quiet, "morph");
  auto r = [&] {
    ComputeScope graceful_cancel;
    return pipeline::morph_members(a.job, progress.callback(), [] { return !cancel_requested(); });
  }();
  progress.finish();
  if (!r.ok()) return print_error(cancel_requested() ? cancelled_status() : r.status());
  if (!a.quiet) print_morph_summary(r.value(), a.job);
  return 0;
}

}  // namespace

void register_morph(CLI::App& app) {
  auto args = std::make_shared<MorphArgs>();
  CLI::App* cmd = add_command(
      app, "morph", "Morph sequence between two collection members (glTF morph targets + OBJ frames)",
      "A and B are members of the collection DIR (by name or mesh file). Both are remeshed\n"
      "through their geometry images (--size, the same texels for every member, so the remeshes\n"
      "share their connectivity) and blended: frame(t) = H_t((1-t) A + t H^-1(B)), H the\n"
      "similarity that best maps A's features onto B's (rigid with --rigid, identity with\n"
      "--no-align), H_t its interpolation from the identity. The first and last frames are the\n"
      "remeshes of A and B exactly. Writes the folder OUT: morph.glb (base = frame 0, one morph\n"
      "target per further frame, an animation 'morph' of --seconds playing them), frame_000.obj\n"
      "... and morph.json (times, alignment, files). OUT is replaced only when it is empty or a\n"
      "previous morph output.",
      "  spherekit morph cats cat0 cat2 -o cat0_to_cat2\n"
      "  spherekit morph heads alice.obj bob.obj -o morph --frames 17 --size 129 --rigid");
  cmd->add_option("DIR", args->job.collection, "collection folder")->required();
  cmd->add_option("A", args->job.a, "first member (name or mesh file)")->required();
  cmd->add_option("B", args->job.b, "last member (name or mesh file)")->required();
  cmd->add_option("-o,--output", args->job.output, "output folder")->required();
  cmd->add_option("--frames", args->job.frames, "frames including both ends (>= 2)")
      ->check(CLI::Range(2, 1000))->capture_default_str();
  cmd->add_option("--size", args->job.size, "geometry-image size of the remeshes, 2^k+1")->capture_default_str();
  cmd->add_flag("--no-align", args->no_align, "blend linearly, without the feature alignment");
  cmd->add_flag("--rigid", args->job.rigid, "align without scaling");
  cmd->add_option("--seconds", args->job.seconds, "length of the glTF animation")
      ->check(CLI::PositiveNumber)->capture_default_str();
  add_threads_option(*cmd, args->job.threads);
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing but errors");
  cmd->callback([args] { set_exit_code(run_morph(*args)); });
}

}  // namespace spherekit::cli
