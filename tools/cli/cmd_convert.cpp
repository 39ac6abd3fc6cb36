// `spherekit convert`: a mesh and its sphere map -> an octahedral geometry image (float EXR),
// optionally the remesh it defines (OBJ) and Draco glTF levels of detail, with the remesh PSNR
// against the original; or every member of a collection (--collection). The pipeline is
// spherekit::pipeline's (convert.h): this file parses flags, calls it and prints.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include "cli_common.h"
#include "commands.h"
#include "help_text.h"
#include "spherekit/pipeline/convert.h"

namespace spherekit::cli {
namespace {

struct ConvertFlags {
  std::string mesh, sphere, collection, output, remesh, report;
  pipeline::ConvertOptions options;
  bool quiet = false;
};

// The flags that are wrong whatever the input, before anything is read or written.
Status check_flags(const ConvertFlags& a) {
  SPHEREKIT_RETURN_IF_ERROR(pipeline::check_convert_options(a.options));
  if (a.collection.empty() && (a.mesh.empty() || a.sphere.empty()))
    return Status(ErrorCode::InvalidArgument, "give MESH and SPHERE, or --collection DIR");
  if (!a.collection.empty() && (!a.mesh.empty() || !a.sphere.empty()))
    return Status(ErrorCode::InvalidArgument, "--collection converts every member: give no MESH or SPHERE with it");
  if (!a.collection.empty() && !a.remesh.empty())
    return Status(ErrorCode::InvalidArgument, "--remesh is for one mesh; with --collection use --report");
  return Status();
}

int run_convert(const ConvertFlags& a) {
  if (Status s = check_flags(a); !s.ok()) return print_error(s);
  ProgressRenderer progress(a.quiet, a.collection.empty() ? file_stem(a.mesh) : std::string());
  if (!a.collection.empty()) {
    if (Status s = require_output_folders({a.report}); !s.ok()) return print_error(s);
    auto r = [&] {
      ComputeScope graceful_cancel;
      return pipeline::convert_collection({a.collection, a.output, a.options}, progress.callback(),
                                          [] { return !cancel_requested(); });
    }();
    progress.finish();
    if (!r.ok()) return print_error(r.status());
    if (!a.report.empty())
      if (Status s = write_json_atomic(a.report, r->report); !s.ok()) return print_error(s);
    if (!a.quiet) print_collection_summary(r.value());
    return 0;
  }
  // Every output folder before any work: a bad --report path must not fail the command
  // after the image was written.
  if (Status s = require_output_folders({a.output, a.remesh, a.report}); !s.ok()) return print_error(s);
  auto r = [&] {
    ComputeScope graceful_cancel;
    return pipeline::convert_mesh({a.mesh, a.sphere, a.output, a.remesh, a.options}, progress.callback());
  }();
  progress.finish();
  if (cancel_requested()) return print_error(cancelled_status());
  if (!r.ok()) return print_error(r.status());
  if (!a.report.empty())
    if (Status s = write_json_atomic(a.report, pipeline::to_json(r.value())); !s.ok()) return print_error(s);
  if (!a.quiet) print_mesh_summary(r.value());
  return 0;
}

}  // namespace

void register_convert(CLI::App& app) {
  auto args = std::make_shared<ConvertFlags>();
  CLI::App* cmd = add_command(
      app, "convert", "Resample a mesh through its sphere map into an octahedral geometry image (EXR) and glTF LODs",
      help::kConvert, help::kConvertExamples);
  cmd->add_option("MESH", args->mesh, "input mesh (.obj .ply .off .stl .gltf .glb)");
  cmd->add_option("SPHERE", args->sphere, "its sphere map (.obj, from `spherekit param`)");
  cmd->add_option("--collection", args->collection,
                  "instead of MESH SPHERE: convert every member of this collection folder (from `spherekit "
                  "consistent`) into the folder -o");
  cmd->add_option("-o,--output", args->output, "geometry image to write (.exr); with --collection: a folder")
      ->required();
  cmd->add_option("--size", args->options.size, "image size N = 2^k+1 (default 257)");
  cmd->add_option("--gi", args->options.size)->group("");  // the earlier spelling
  cmd->add_option("--remesh", args->remesh, "also write the remesh defined by the image (.obj .ply)");
  cmd->add_option("--report", args->report, "also write a JSON report here");
  cmd->add_option("--positions", args->options.positions,
                  "texel positions: fit (least-squares fit of the surface, the lower remesh error; default) or "
                  "sampled (each texel the surface point it samples)")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, pipeline::TexelPositions>{{"fit", pipeline::TexelPositions::Fit},
                                                          {"sampled", pipeline::TexelPositions::Sampled}}));
  cmd->add_option("--psnr-samples", args->options.psnr_samples,
                  "points sampled per direction for the PSNR (0: skip it; default 400000)");
  cmd->add_option("--lods", args->options.lods, "also write this many glTF levels of detail (default 0: none)");
  cmd->add_option("--lod-mode", args->options.lod_mode,
                  "glTF levels: original (quadric simplification of the mesh itself, texture coordinates into the "
                  "geometry image, seams at the octahedral fold; with --collection the reference member's mesh laid on "
                  "every member, or the remesh's levels where it folds over on one), adaptive (quadric simplification "
                  "of the remesh) or uniform (coarser geometry images); a collection's members share each level's "
                  "connectivity")
      ->transform(CLI::CheckedTransformer(std::map<std::string, convert::LodMode>{
          {"uniform", convert::LodMode::Uniform}, {"adaptive", convert::LodMode::Adaptive}, {"original", convert::LodMode::Original}}));
  cmd->add_flag("!--no-lod-normals", args->options.lod_normals,
                "glTF levels without NORMAL (a viewer derives them from the triangles, as for gltfpack -cc "
                "output)");
  cmd->add_flag("!--no-lod-texcoords", args->options.lod_texcoords,
                "glTF levels without TEXCOORD_0 (geometry only, as gltfpack and gltf-transform files of a mesh "
                "without texture coordinates; the copies of a vertex at the octahedral fold become one)");
  cmd->add_option("--lod-coarse-position-bits", args->options.lod_coarse_position_bits,
                  "adaptive glTF levels 1..: position bits from each level's own error, at least this many "
                  "(default 0: all levels use level 0's bits)");
  cmd->add_option("--lod-position-bits", args->options.lod_position_bits,
                  "glTF levels: position bits per level by rate and distortion (default: the smallest file at "
                  "the level's own error, README) or from the error budget (level 0's bits, at least "
                  "--min-position-bits, for every level)")
      ->transform(CLI::CheckedTransformer(std::map<std::string, convert::PositionBitsRule>{
          {"rate-distortion", convert::PositionBitsRule::RateDistortion},
          {"budget", convert::PositionBitsRule::ErrorBudget}}));
  cmd->add_option("--min-position-bits", args->options.budget.min_position_bits,
                  "glTF: fewest Draco position bits (default 14; more if the error budget needs them)");
  cmd->add_option("--normal-bits", args->options.budget.normal_bits, "glTF: Draco normal bits (default 10)");
  cmd->add_option("--min-texcoord-bits", args->options.budget.min_texcoord_bits,
                  "glTF: Draco bits of arbitrary texture coordinates (default 12; texel-centre "
                  "lattices take the fewest that hold them)");
  cmd->add_option("--cage", args->options.cage,
                  "also fit a Catmull-Clark cage with N x N quads per cube face (OUT_cage.obj) and sample "
                  "its displacement map (OUT_disp.exr); default 0: none");
  cmd->add_option("--cage-tile", args->options.cage_tile, "displacement samples per cage-quad edge (default 17)");
  cmd->add_option("--displacement", args->options.displacement,
                  "scalar (along the limit normal, 1 float per sample; default) or vector (3 floats)")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, convert::DisplacementKind>{{"scalar", convert::DisplacementKind::Scalar},
                                                           {"vector", convert::DisplacementKind::Vector}}));
  add_threads_option(*cmd, args->options.threads);
  cmd->add_flag("-q,--quiet", args->quiet, "print no summary (errors still)");
  cmd->callback([args] { set_exit_code(run_convert(*args)); });
}

}  // namespace spherekit::cli
