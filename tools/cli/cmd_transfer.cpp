// `spherekit transfer`: per-vertex colours, normals (as a normal map), texture coordinates or a
// texture image from one member of a collection to another through the common sphere
// (Asirvatham, Praun, Hoppe 2005, Fig. 6). The algorithms are in
// convert/attribute_transfer.h; this file reads, calls and writes.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>

#include "cli_common.h"
#include "commands.h"
#include "spherekit/pipeline/apps.h"

namespace spherekit::cli {
namespace {

struct TransferArgs {
  pipeline::TransferJob job;
  std::string what;
  bool no_align = false;
  std::string report;
  bool quiet = false;
};

int run_transfer(TransferArgs& a) {
  const pipeline::TransferWhat kinds[] = {pipeline::TransferWhat::Colors, pipeline::TransferWhat::Normals,
                                          pipeline::TransferWhat::UV, pipeline::TransferWhat::Texture};
  for (pipeline::TransferWhat k : kinds)
    if (a.what == pipeline::transfer_what_name(k)) a.job.what = k;
  a.job.align = !a.no_align;
  if (Status s = require_output_folders({a.job.output, a.report}); !s.ok()) return print_error(s);
  auto r = pipeline::transfer_attributes(a.job);
  if (!r.ok()) return print_error(r.status());
  if (!a.report.empty())
    if (Status s = write_json_atomic(a.report, r->report); !s.ok()) return print_error(s);
  if (!a.quiet) print_transfer_summary(r.value(), a.job);
  return 0;
}

}  // namespace

void register_transfer(CLI::App& app) {
  auto args = std::make_shared<TransferArgs>();
  CLI::App* cmd = add_command(
      app, "transfer", "Transfer colours, normals, texture coordinates or a texture between collection members",
      "A and B are members of the collection DIR ('spherekit consistent'), by name or mesh file.\n"
      "Every vertex of B is located on the common sphere in A's map and A's attribute is\n"
      "interpolated there (paper Fig. 6):\n"
      "  colors   A's vertex colours (PLY red/green/blue, OBJ 'v x y z r g b') -> OUT (.ply/.obj)\n"
      "  uv       A's texture coordinates (per face corner, charts kept apart at seams) -> OUT.obj\n"
      "  texture  the same plus OUT.mtl and OUT_texture.EXT, a copy of A's image (--texture, else\n"
      "           map_Kd of A's material library), so B shows A's texture\n"
      "  normals  A's normals as an object-space normal map in the geometry-image domain the\n"
      "           members share (OUT_normals.png, --size texels), on B's consistent remesh\n"
      "           (OUT.obj with texel-centre texture coordinates and the normals as 'vn', OUT.mtl);\n"
      "           rotated by the rotation aligning A's features with B's unless --no-align\n"
      "The attributes are read from A's mesh file, or from --attributes (same vertices as A).\n"
      "Outputs are written together or not at all; --report writes the numbers as JSON.",
      "  spherekit transfer heads --from alice --to bob --what colors -o bob_colored.ply\n"
      "  spherekit transfer heads --from alice --to bob --what texture -o bob_textured.obj\n"
      "  spherekit transfer heads --from alice --to bob --what normals -o bob_normals.obj --size 257");
  cmd->add_option("DIR", args->job.collection, "collection folder")->required();
  cmd->add_option("--from", args->job.from, "source member A (name or mesh file)")->required();
  cmd->add_option("--to", args->job.to, "target member B (name or mesh file)")->required();
  cmd->add_option("--what", args->what, "colors, normals, uv or texture")
      ->required()
      ->check(CLI::IsMember({"colors", "normals", "uv", "texture"}));
  cmd->add_option("-o,--output", args->job.output, "output mesh (.obj; .ply also for colors)")->required();
  cmd->add_option("--attributes", args->job.attributes, "read A's attributes from this file (A's vertices and faces)");
  cmd->add_option("--texture", args->job.texture, "A's texture image (texture; default: from A's .mtl)");
  cmd->add_option("--size", args->job.size, "normals: normal map and remesh size, 2^k+1")->capture_default_str();
  cmd->add_flag("--no-align", args->no_align, "normals: do not rotate A's normals into B's orientation");
  cmd->add_option("--report", args->report, "write a JSON report here");
  add_threads_option(*cmd, args->job.threads);
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing but errors");
  cmd->callback([args] { set_exit_code(run_transfer(*args)); });
}

}  // namespace spherekit::cli
