// map_mesh() (param.h): the unconstrained or constrained map of one mesh, and its report.
#include <algorithm>

#include "spherekit/file_status.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/feature_io.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/formats/text_formats.h"
#include "spherekit/pipeline/param.h"
#include "spherekit/pipeline/paths.h"
#include "spherekit/pipeline/process_stats.h"
#include "spherekit/version.h"
#include "spherekit/format_text.h"
#include "stopwatch.h"

namespace spherekit::pipeline {
namespace {


Json provenance_json(const Provenance& p) {
  return Json{{"library_version", p.library_version},
              {"method", p.method},
              {"options_digest", p.options_digest},
              {"seed", p.seed}};
}

// The features of `a.features` with their targets from `a.targets`, matched by name: every
// feature needs a target and every target a feature.
Status read_constraints(const ParamJob& a, int vertices, std::vector<int>& fv, std::vector<Eigen::Vector3d>& targets) {
  auto lms = formats::read_landmarks(a.features, vertices);
  if (!lms.ok()) return with_file(lms.status(), a.features);
  auto pts = formats::read_sphere_points(a.targets, /*require_unit=*/true);
  if (!pts.ok()) return with_file(pts.status(), a.targets);
  std::vector<std::string> names;
  for (const Landmark& l : lms.value()) {
    const SpherePoint* hit = nullptr;
    for (const SpherePoint& p : pts.value())
      if (p.name == l.name) hit = &p;
    if (!hit)
      return Status(ErrorCode::InvalidInput, format_text("%s: no target for feature '%s' of %s", a.targets.c_str(),
                                                         l.name.c_str(), a.features.c_str()));
    fv.push_back(l.vertex);
    targets.push_back(hit->p);
    names.push_back(l.name);
  }
  for (const SpherePoint& p : pts.value())
    if (std::find(names.begin(), names.end(), p.name) == names.end())
      return Status(ErrorCode::InvalidInput, format_text("%s: target '%s' names no feature of %s", a.targets.c_str(),
                                                         p.name.c_str(), a.features.c_str()));
  return Status();
}

}  // namespace

Result<ParamResult> map_mesh(const ParamJob& a, const ProgressFn& progress) {
  Stopwatch wall;
  // Every output folder must exist before any work: no partial set of outputs on failure.
  SPHEREKIT_RETURN_IF_ERROR(require_output_folders({a.output, a.dump_network}));
  SPHEREKIT_RETURN_IF_ERROR(formats::check_sphere_map_path(a.output));
  ParamResult out;
  out.job = a;
  SPHEREKIT_ASSIGN_OR_RETURN(out.input, load_mesh_checked(a.mesh, /*allow_boundary=*/true, /*repair=*/false));
  const LoadedMesh& m = out.input;
  const bool constrained = !a.features.empty() || !a.targets.empty();
  if (constrained && (a.features.empty() || a.targets.empty()))
    return Status(ErrorCode::InvalidArgument, "--features and --targets go together");
  if (!constrained && !a.dump_network.empty())
    return Status(ErrorCode::InvalidArgument, "--dump-network needs --features and --targets");
  // A map that is not a bijection is a failure, never an output: later stages (resampling,
  // correspondence) silently produce garbage from a folded map.
  auto refuse_flips = [&](int flipped) {
    return Status(ErrorCode::SolverFailed, format_text("%s: the map has %d flipped faces (not bijective); nothing written",
                                                       a.mesh.c_str(), flipped));
  };
  const SphereMap* map = nullptr;
  if (constrained) {
    std::vector<int> fv;
    std::vector<Eigen::Vector3d> targets;
    SPHEREKIT_RETURN_IF_ERROR(read_constraints(a, m.check.vertices, fv, targets));
    out.features = static_cast<int>(fv.size());
    ConstrainedParamOptions o = a.constrained;
    o.sphere = a.options;
    auto r = parameterize_sphere_constrained(m.mesh, fv, targets, o, progress);
    if (!r.ok()) return with_file(r.status(), a.mesh);
    if (r->flipped_faces != 0) return refuse_flips(r->flipped_faces);
    if (!(r->max_feature_angle < 1e-9))
      return Status(ErrorCode::Internal, format_text("%s: a feature is %.3g rad off its target; nothing written",
                                                     a.mesh.c_str(), r->max_feature_angle));
    if (!a.dump_network.empty())
      SPHEREKIT_RETURN_IF_ERROR(formats::write_file_atomic(
          a.dump_network, formats::path_network_obj_text(r->network.polylines, r->network.arcs, r->network.arc_targets)));
    out.constrained = std::move(r).value();
    map = &out.constrained->map;
  } else {
    auto r = parameterize_sphere(m.mesh, a.options, progress);
    if (!r.ok()) return with_file(r.status(), a.mesh);
    if (r->flipped_faces != 0) return refuse_flips(r->flipped_faces);
    out.unconstrained = std::move(r).value();
    map = &out.unconstrained->map;
  }
  Stopwatch write_time;
  SPHEREKIT_RETURN_IF_ERROR(formats::write_sphere_map(a.output, m.mesh, *map));
  out.write_seconds = write_time.seconds();
  out.wall_seconds = wall.seconds();
  return out;
}

Json to_json(const ParamResult& p) {
  const ParamJob& a = p.job;
  const LoadedMesh& m = p.input;
  Json j;
  j["input"] = a.mesh;
  j["output"] = a.output;
  if (p.constrained) {
    const ConstrainedParamResult& r = *p.constrained;
    ConstrainedParamOptions o = a.constrained;
    o.sphere = a.options;
    j["features"] = a.features;
    j["targets"] = a.targets;
    j["V"] = m.check.vertices;
    j["F"] = m.check.faces;
    j["source_faces"] = source_faces_json(m.info);
    j["method"] = "constrained";
    const Json measures = constrained_measures_json(r);  // named: items() does not extend its lifetime
    for (const auto& [key, value] : measures.items()) j[key] = value;
    j["network"] = feature_network_json(r.network);
    j["network"]["features"] = p.features;
    j["times"] = Json{{"read", m.read_seconds}, {"check", r.times.check},     {"network", r.times.network},
                      {"simplify", r.times.simplify}, {"refine", r.times.refine}, {"total", r.times.total},
                      {"wall", p.wall_seconds}};
    j["cpu_seconds"] = cpu_seconds();
    j["peak_rss_mb"] = peak_rss_mb();
    j["options"] = constrained_options_json(o);
    j["version"] = kVersion;
    j["provenance"] = provenance_json(r.map.provenance);
    return j;
  }
  const SphereParamResult& r = *p.unconstrained;
  j["V"] = m.check.vertices;
  j["F"] = m.check.faces;
  j["source_faces"] = source_faces_json(m.info);
  const Json measures = sphere_param_result_json(r);  // named: items() does not extend its lifetime
  for (const auto& [key, value] : measures.items()) j[key] = value;
  j["times"]["read"] = m.read_seconds;
  j["times"]["write"] = p.write_seconds;
  j["times"]["wall"] = p.wall_seconds;
  j["cpu_seconds"] = cpu_seconds();
  j["peak_rss_mb"] = peak_rss_mb();
  j["options"] = sphere_param_options_json(a.options);
  j["version"] = kVersion;
  j["provenance"] = provenance_json(r.map.provenance);
  return j;
}

}  // namespace spherekit::pipeline
