// spherekit::pipeline in Python: the folder-level jobs the command line runs (`consistent`,
// `add`, `convert`, `convert --collection`), on file paths, writing the same files. Each returns
// its report as a dict (the JSON `--report` writes, without the process's times).
#include <pybind11/pybind11.h>

#include "py_common.h"
#include "spherekit/pipeline/collection.h"
#include "spherekit/pipeline/convert.h"

namespace spherekit::py {
namespace {

using Callback = std::optional<pyb::function>;

// nlohmann JSON -> Python objects, through the json module (reports are small).
pyb::object to_python(const pipeline::Json& j) { return pyb::module_::import("json").attr("loads")(j.dump()); }

convert::LodMode lod_mode(const std::string& name) {
  if (name == "uniform") return convert::LodMode::Uniform;
  if (name == "adaptive") return convert::LodMode::Adaptive;
  if (name == "original") return convert::LodMode::Original;
  throw_status(Status(ErrorCode::InvalidArgument, "lod_mode must be 'original', 'adaptive' or 'uniform', not '" + name + "'"));
}

convert::DisplacementKind displacement_kind(const std::string& name) {
  if (name == "scalar") return convert::DisplacementKind::Scalar;
  if (name == "vector") return convert::DisplacementKind::Vector;
  throw_status(Status(ErrorCode::InvalidArgument, "displacement must be 'scalar' or 'vector', not '" + name + "'"));
}

pipeline::ConvertOptions convert_options(int size, int lods, const std::string& mode, int cage, int cage_tile,
                                         const std::string& displacement, int psnr_samples, int threads) {
  pipeline::ConvertOptions o;
  o.size = size;
  o.lods = lods;
  o.lod_mode = lod_mode(mode);
  o.cage = cage;
  o.cage_tile = cage_tile;
  o.displacement = displacement_kind(displacement);
  o.psnr_samples = psnr_samples;
  o.threads = threads;
  return o;
}

// The convert options as keyword arguments, one spelling for both convert functions.
#define SPHEREKIT_PY_CONVERT_ARGS                                                                       \
  pyb::kw_only(), pyb::arg("size") = 257, pyb::arg("lods") = 0, pyb::arg("lod_mode") = "original",      \
      pyb::arg("cage") = 0, pyb::arg("cage_tile") = 17, pyb::arg("displacement") = "scalar",           \
      pyb::arg("psnr_samples") = pipeline::ConvertOptions{}.psnr_samples, pyb::arg("threads") = 0,     \
      pyb::arg("progress") = pyb::none()

}  // namespace

void bind_pipeline(pyb::module_& m) {
  m.def(
      "make_collection",
      [](const std::vector<std::string>& meshes, const std::string& output, const std::vector<std::string>& features,
         const std::string& reference, int remesh_size, int effort, std::uint64_t seed, int threads, Callback progress) {
        pipeline::MakeCollectionJob job;
        job.meshes = meshes;
        job.features = features;
        job.output = output;
        job.reference = reference;
        job.options.constrained.sphere = collection_options(effort, seed, threads);
        job.options.threads = threads;
        job.options.remesh_size = remesh_size;
        const pipeline::MakeCollectionResult r = run_stage(std::move(progress), "", [&](const ProgressFn& fn) {
          return pipeline::make_collection(job, fn);
        });
        pyb::dict out = to_python(formats::collection_manifest_json(r.manifest)).cast<pyb::dict>();
        out["output"] = output;
        out["refinement_warning"] = r.refinement_warning;
        out["landmark_warnings"] = to_python(pipeline::Json(r.landmark_warnings));
        return out;
      },
      pyb::arg("meshes"), pyb::arg("output"), pyb::kw_only(), pyb::arg("features") = std::vector<std::string>{},
      pyb::arg("reference") = "", pyb::arg("remesh_size") = ConsistentParamOptions{}.remesh_size,
      pyb::arg("effort") = SphereParamOptions{}.effort,
      pyb::arg("seed") = SphereParamOptions{}.seed, pyb::arg("threads") = 0, pyb::arg("progress") = pyb::none(),
      "A consistent collection folder from mesh files (as `spherekit consistent MESH... -o OUTPUT`): each\n"
      "mesh's landmarks from `features` (one file per mesh) or NAME.lm.txt beside it. The folder appears\n"
      "only when complete. Returns its manifest (collection.json) as a dict, with `landmark_warnings`:\n"
      "given landmarks most likely on another feature (as the CLI's warnings).");

  m.def(
      "add_to_collection",
      [](const std::string& dir, const std::string& mesh, const std::string& features, const std::string& name,
         bool replace, const std::string& map, std::optional<std::uint64_t> seed, int threads, Callback progress) {
        pipeline::AddToCollectionJob job;
        job.dir = dir;
        job.mesh = mesh;
        job.features = features;
        job.name = name;
        job.replace = replace;
        job.map = map;
        job.options.sphere.threads = threads;
        if (seed) {
          job.options.sphere.seed = *seed;
          job.seed_given = true;
        }
        const pipeline::AddToCollectionResult r = run_stage(std::move(progress), "", [&](const ProgressFn& fn) {
          return pipeline::add_to_collection(job, fn);
        });
        pyb::dict out;
        out["name"] = r.name;
        out["map"] = r.map_path;
        out["vertices"] = r.vertices;
        out["features"] = r.features;
        out["registered"] = r.registered;
        out["result"] = to_python(pipeline::map_entry_json(r.map));
        out["manifest"] = to_python(formats::collection_manifest_json(r.manifest));
        out["landmark_warnings"] = to_python(pipeline::Json(r.landmark_warnings));
        return out;
      },
      pyb::arg("dir"), pyb::arg("mesh"), pyb::kw_only(), pyb::arg("features") = "", pyb::arg("name") = "",
      pyb::arg("replace") = false, pyb::arg("map") = "", pyb::arg("seed") = pyb::none(), pyb::arg("threads") = 0,
      pyb::arg("progress") = pyb::none(),
      "Adds a mesh to a collection folder (as `spherekit add DIR MESH`): maps it with its features on the\n"
      "collection's locations, or registers `map` (a sphere map computed elsewhere) after verifying it.\n"
      "Safe to run concurrently on one folder. Returns the member's entry and the manifest as written.");

  m.def(
      "convert",
      [](const std::string& mesh, const std::string& sphere, const std::string& output, const std::string& remesh,
         int size, int lods, const std::string& mode, int cage, int cage_tile, const std::string& displacement,
         int psnr_samples, int threads, Callback progress) {
        pipeline::ConvertMeshJob job{mesh, sphere, output, remesh,
                                     convert_options(size, lods, mode, cage, cage_tile, displacement, psnr_samples, threads)};
        check(pipeline::check_convert_options(job.options));
        const pipeline::ConvertMeshResult r =
            run_stage(std::move(progress), "", [&](const ProgressFn& fn) { return pipeline::convert_mesh(job, fn); });
        return to_python(pipeline::to_json(r));
      },
      pyb::arg("mesh"), pyb::arg("sphere"), pyb::arg("output"), pyb::arg("remesh") = "", SPHEREKIT_PY_CONVERT_ARGS,
      "A mesh and its sphere map -> geometry image OUTPUT.exr with previews, optionally the remesh, glTF\n"
      "levels of detail and a Catmull-Clark cage + displacement (as `spherekit convert`; the same files).\n"
      "Returns the report `convert --report` writes, as a dict.");

  m.def(
      "convert_collection",
      [](const std::string& collection, const std::string& output, int size, int lods, const std::string& mode, int cage,
         int cage_tile, const std::string& displacement, int psnr_samples, int threads, Callback progress) {
        pipeline::ConvertCollectionJob job{
            collection, output, convert_options(size, lods, mode, cage, cage_tile, displacement, psnr_samples, threads)};
        check(pipeline::check_convert_options(job.options));
        const pipeline::ConvertCollectionResult r = run_stage(
            std::move(progress), "", [&](const ProgressFn& fn) { return pipeline::convert_collection(job, fn); });
        return to_python(r.report);
      },
      pyb::arg("collection"), pyb::arg("output"), SPHEREKIT_PY_CONVERT_ARGS,
      "Every member of a collection folder into the folder OUTPUT, all-or-nothing (as `spherekit convert\n"
      "--collection DIR -o OUTPUT`). Returns convert_report.json as a dict.");
}

}  // namespace spherekit::py
