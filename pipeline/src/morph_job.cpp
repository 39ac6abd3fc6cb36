// morph_members() (apps.h): a morph sequence between two members of a collection on their
// consistent remeshes, aligned by their features.
#include <cmath>
#include <cstdio>

#include "spherekit/convert/consistent_remesh.h"
#include "spherekit/convert/gltf_morph.h"
#include "spherekit/convert/morph.h"
#include "spherekit/formats/collection.h"
#include "spherekit/formats/mesh_attributes.h"
#include "spherekit/geometry_image.h"
#include "spherekit/pipeline/apps.h"
#include "stopwatch.h"

namespace spherekit::pipeline {
namespace {

using formats::OutputFiles;

std::string frame_name(std::size_t k, const char* extension) {
  char text[32];
  std::snprintf(text, sizeof text, "frame_%03zu%s", k, extension);
  return text;
}

/// OBJ text of a mesh (17 significant digits: the frames read back bit for bit).
std::string frame_obj_text(const TriMesh& mesh) {
  auto bytes = formats::format_mesh_with_attributes("frame.obj", mesh, {});
  return bytes.ok() ? std::move(bytes).value() : std::string();
}

}  // namespace

Result<MorphResult> morph_members(const MorphJob& a, const ProgressFn& progress,
                                  const formats::KeepGoingFn& keep_going) {
  if (!is_geometry_image_size(a.size))
    return Status(ErrorCode::InvalidArgument, "--size " + std::to_string(a.size) + " is not 2^k+1 (33, 65, 129, ...)");
  if (Status s = formats::require_staged_folder_target(a.output, kMorphReport); !s.ok()) return s;
  Stopwatch clock;
  auto col = formats::read_collection(a.collection);
  if (!col.ok()) return col.status();
  auto A = formats::load_collection_member(col.value(), a.a);
  if (!A.ok()) return A.status();
  auto B = formats::load_collection_member(col.value(), a.b);
  if (!B.ok()) return B.status();

  SPHEREKIT_ASSIGN_OR_RETURN(std::vector<convert::ConsistentRemesh> remeshes,
                             convert::consistent_remeshes({A->mesh, B->mesh}, {A->map.S, B->map.S}, a.size, GeometryImageOptions{.threads = a.threads}, progress));
  convert::MorphOptions o;
  o.frames = a.frames;
  o.align = a.align;
  o.with_scale = !a.rigid;
  const bool features = A->features.rows() >= 3 && A->features.rows() == B->features.rows();
  auto seq = convert::morph_sequence(remeshes[0].mesh, remeshes[1].mesh, features ? A->features : RowMat3d(),
                                     features ? B->features : RowMat3d(), o);
  if (!seq.ok()) return seq.status();

  convert::GltfMorphOptions g;
  g.name = A->name + "_to_" + B->name;
  g.animation_seconds = a.seconds;
  g.provenance.sphere_map = a.collection;
  for (std::size_t k = 0; k < seq->frames.size(); ++k) g.names.push_back(frame_name(k, ""));
  auto glb = convert::build_gltf_morph_targets(seq->frames, g);
  if (!glb.ok()) return glb.status();

  OutputFiles files;
  files.add("morph.glb", glb->glb);
  Json frames = Json::array();
  for (std::size_t k = 0; k < seq->frames.size(); ++k) {
    const std::string name = frame_name(k, ".obj");
    files.add(name, frame_obj_text(seq->frames[k]));
    frames.push_back({{"file", name}, {"t", seq->times[k]}});
  }
  const convert::Similarity& H = seq->alignment;
  Json rep;
  rep["command"] = "morph";
  rep["collection"] = a.collection;
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
  SPHEREKIT_RETURN_IF_ERROR(formats::write_output_folder(a.output, kMorphReport, files, keep_going));
  MorphResult result;
  result.a = A->name;
  result.b = B->name;
  result.vertices = remeshes[0].mesh.V.rows();
  result.aligned = seq->aligned;
  result.scale = H.scale;
  result.rotation_deg = Eigen::AngleAxisd(H.R).angle() * 180.0 / M_PI;
  result.report = std::move(rep);
  return result;
}

}  // namespace spherekit::pipeline
