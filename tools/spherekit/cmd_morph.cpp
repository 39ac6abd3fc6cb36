// `spherekit morph`: a morph sequence between two members of a collection, from their
// consistent remeshes (identical connectivity), blended in a feature-aligned frame; written as
// a glTF whose morph targets are the frames (with an animation playing them) and as one OBJ
// per frame. The algorithm is convert/morph.h.
#include <CLI/CLI.hpp>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "cli_common.h"
#include "commands.h"
#include "member_io.h"
#include "spherekit/convert/consistent_remesh.h"
#include "spherekit/convert/gltf_morph.h"
#include "spherekit/convert/morph.h"
#include "spherekit/formats/mesh_attributes.h"
#include "spherekit/geometry_image.h"

namespace spherekit::cli {
namespace {

constexpr const char* kMorphReport = "morph.json";

struct MorphArgs {
  std::string dir, a, b, output;
  int frames = 9;
  int size = 65;
  bool no_align = false, rigid = false;
  double seconds = 3;
  bool quiet = false;
};

/// OBJ text of a mesh (17 significant digits: the frames read back bit for bit).
std::string frame_obj_text(const TriMesh& mesh) {
  auto bytes = formats::format_mesh_with_attributes("frame.obj", mesh, {});
  return bytes.ok() ? std::move(bytes).value() : std::string();
}

int run_morph(const MorphArgs& a) {
  if (!is_geometry_image_size(a.size))
    return print_error(Status(ErrorCode::InvalidArgument, "--size " + std::to_string(a.size) + " is not 2^k+1 (33, 65, 129, ...)"));
  if (Status s = require_output_folder(a.output, kMorphReport); !s.ok()) return print_error(s);
  Stopwatch clock;
  auto col = read_collection(a.dir);
  if (!col.ok()) return print_error(col.status());
  auto A = load_member(col.value(), a.a);
  if (!A.ok()) return print_error(A.status());
  auto B = load_member(col.value(), a.b);
  if (!B.ok()) return print_error(B.status());

  ProgressRenderer progress(a.quiet, "morph");
  std::vector<convert::ConsistentRemesh> remeshes;
  {
    ComputeScope graceful_cancel;
    auto r = convert::consistent_remeshes({A->mesh, B->mesh}, {A->map.S, B->map.S}, a.size, {}, progress.callback());
    if (!r.ok()) return print_error(cancel_requested() ? cancelled_status() : r.status());
    remeshes = std::move(r).value();
  }
  progress.finish();
  convert::MorphOptions o;
  o.frames = a.frames;
  o.align = !a.no_align;
  o.with_scale = !a.rigid;
  const bool features = A->features.rows() >= 3 && A->features.rows() == B->features.rows();
  auto seq = convert::morph_sequence(remeshes[0].mesh, remeshes[1].mesh, features ? A->features : RowMat3d(),
                                     features ? B->features : RowMat3d(), o);
  if (!seq.ok()) return print_error(seq.status());

  convert::GltfMorphOptions g;
  g.name = A->name + "_to_" + B->name;
  g.animation_seconds = a.seconds;
  g.provenance.sphere_map = a.dir;
  for (std::size_t k = 0; k < seq->frames.size(); ++k) g.names.push_back(strprintf("frame_%03zu", k));
  auto glb = convert::build_gltf_morph_targets(seq->frames, g);
  if (!glb.ok()) return print_error(glb.status());

  OutputFiles files;
  files.add("morph.glb", glb->glb);
  Json frames = Json::array();
  for (std::size_t k = 0; k < seq->frames.size(); ++k) {
    const std::string name = strprintf("frame_%03zu.obj", k);
    files.add(name, frame_obj_text(seq->frames[k]));
    frames.push_back({{"file", name}, {"t", seq->times[k]}});
  }
  const convert::Similarity& H = seq->alignment;
  Json rep;
  rep["command"] = "morph";
  rep["collection"] = a.dir;
  rep["a"] = A->name;
  rep["b"] = B->name;
  rep["size"] = a.size;
  rep["vertices"] = remeshes[0].mesh.V.rows();
  rep["faces"] = remeshes[0].mesh.F.rows();
  rep["aligned"] = seq->aligned;
  rep["alignment"] = {{"scale", H.scale},
                      {"rotation_deg", Eigen::AngleAxisd(H.R).angle() * 180.0 / M_PI},
                      {"offset", {H.offset.x(), H.offset.y(), H.offset.z()}},
                      {"feature_rms", seq->alignment_rms}};
  rep["glb"] = "morph.glb";
  rep["glb_bytes"] = glb->glb.size();
  rep["animation_seconds"] = a.seconds;
  rep["frames"] = frames;
  rep["seconds"] = clock.seconds();
  files.add(kMorphReport, rep.dump(2) + "\n");
  if (Status s = write_output_folder(a.output, kMorphReport, files); !s.ok()) return print_error(s);
  if (!a.quiet)
    std::printf("morph %s -> %s: %d frames of %lld vertices (%s) in %s\n", A->name.c_str(), B->name.c_str(), a.frames,
                static_cast<long long>(remeshes[0].mesh.V.rows()),
                seq->aligned ? strprintf("aligned: scale %.3f, rotation %.1f deg", H.scale,
                                         Eigen::AngleAxisd(H.R).angle() * 180.0 / M_PI).c_str()
                             : "not aligned",
                a.output.c_str());
  return 0;
}

}  // namespace

int run_morph_job(const std::string& dir, const std::string& a, const std::string& b, const std::string& output,
                  bool quiet) {
  MorphArgs args;
  args.dir = dir;
  args.a = a;
  args.b = b;
  args.output = output;
  args.quiet = quiet;
  return run_morph(args);
}

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
  cmd->add_option("DIR", args->dir, "collection folder")->required();
  cmd->add_option("A", args->a, "first member (name or mesh file)")->required();
  cmd->add_option("B", args->b, "last member (name or mesh file)")->required();
  cmd->add_option("-o,--output", args->output, "output folder")->required();
  cmd->add_option("--frames", args->frames, "frames including both ends (>= 2)")
      ->check(CLI::Range(2, 1000))->capture_default_str();
  cmd->add_option("--size", args->size, "geometry-image size of the remeshes, 2^k+1")->capture_default_str();
  cmd->add_flag("--no-align", args->no_align, "blend linearly, without the feature alignment");
  cmd->add_flag("--rigid", args->rigid, "align without scaling");
  cmd->add_option("--seconds", args->seconds, "length of the glTF animation")
      ->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing but errors");
  cmd->callback([args] { set_exit_code(run_morph(*args)); });
}

}  // namespace spherekit::cli
