// The JSON of every result the jobs and commands report (json.h): one serialization each.
#include "spherekit/pipeline/json.h"

#include <cmath>
#include <filesystem>
#include <system_error>

namespace spherekit::pipeline {

Json number_or_null(double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); }

std::uintmax_t file_bytes(const std::string& path) {
  std::error_code ec;
  const std::uintmax_t n = std::filesystem::file_size(path, ec);
  return ec ? 0 : n;
}

Json source_faces_json(const formats::ReadInfo& info) {
  Json j{{"faces", info.faces.faces},
         {"triangles", info.faces.triangles},
         {"quads", info.faces.quads},
         {"ngons", info.faces.ngons}};
  if (info.polygons_triangulated > 0) j["face_polygon"] = info.face_polygon;
  return j;
}

Json mesh_repair_json(const MeshRepair& r, const std::string& output) {
  return Json{{"split_vertices", r.split_vertices},
              {"removed_unreferenced_vertices", r.removed_unreferenced_vertices},
              {"renumbered", r.renumbered},
              {"output", output}};
}

Json mesh_check_json(const std::string& file, const MeshCheck& c) {
  Json j;
  j["file"] = file;
  j["V"] = c.vertices;
  j["F"] = c.faces;
  j["edges"] = c.edges;
  j["unreferenced_vertices"] = c.unreferenced_vertices;
  j["degenerate_faces"] = c.degenerate_faces;
  j["duplicate_faces"] = c.duplicate_faces;
  j["zero_area_faces"] = c.zero_area_faces;
  j["boundary_edges"] = c.boundary_edges;
  j["nonmanifold_edges"] = c.nonmanifold_edges;
  j["orientation_conflicts"] = c.orientation_conflicts;
  j["boundary_loops"] = c.boundary_loops;
  j["components"] = c.components;
  j["nonmanifold_vertices"] = c.nonmanifold_vertices;
  j["orientable"] = c.orientable;
  j["euler"] = c.euler;
  j["genus"] = c.genus;
  j["bbox_diag"] = c.bbox_diag;
  // Not in the manifest (its meshes are all finite and indexed correctly), but part of the
  // check: keep them after the manifest's keys.
  j["nonfinite_vertices"] = c.nonfinite_vertices;
  j["invalid_indices"] = c.invalid_indices;
  j["genus0_ok"] = c.genus0_ok();
  return j;
}

Json sphere_param_options_json(const SphereParamOptions& o) {
  Json j;
  j["effort"] = o.effort;
  j["seed"] = o.seed;
  j["threads"] = o.threads;
  j["regularizer_weight"] = o.regularizer_weight;
  j["hole_weight"] = o.hole_weight;
  j["hole_shape_weight"] = o.hole_shape_weight;
  j["precise_layout"] = o.precise_layout;
  j["block_vertices"] = o.block_vertices;
  return j;
}

Json constrained_options_json(const ConstrainedParamOptions& o) {
  Json j = sphere_param_options_json(o.sphere);
  j["steiner_penalty"] = o.steiner_penalty;
  j["min_angle_deg"] = o.min_angle_deg;
  j["extremity_fraction"] = o.extremity_fraction;
  j["unswirl"] = o.unswirl;
  j["edge_flips"] = o.edge_flips;
  j["sidedness"] = o.sidedness;
  j["arc_ranking"] = o.arc_ranking;
  j["as_unconstrained"] = o.as_unconstrained;
  return j;
}

Json constrained_measures_json(const ConstrainedParamResult& r) {
  Json j;
  j["efficiency"] = r.efficiency;
  j["l2_stretch"] = r.l2_stretch;
  j["linf_stretch"] = r.linf_stretch;
  j["flipped_faces"] = r.flipped_faces;
  j["winding"] = r.winding;
  j["max_feature_angle"] = r.max_feature_angle;
  j["holes_filled"] = r.holes_filled;
  return j;
}

Json feature_network_json(const FeatureNetworkReport& n) {
  Json j{{"auxiliary_features", n.auxiliary_features},
              {"paths", n.paths},
              {"total_path_length", n.total_length},
              {"max_length_ratio", n.max_ratio},
              {"swirls_fixed", n.swirls_fixed},
              {"edge_flips", n.edge_flips},
              {"deferred", n.deferred},
              {"steiner_vertices", n.steiner_vertices},
              {"flips_untangled", n.flips_after_steiner_removal},
              {"attempts", n.attempts}};
  // Dense feature sets only (constrained_param.h), so sparse sets' reports keep their bytes.
  if (n.warped_features > 0) {
    j["warped_features"] = n.warped_features;
    j["warp_steps"] = n.warp_steps;
  }
  return j;
}

Json sphere_param_result_json(const SphereParamResult& r) {
  Json j;
  j["holes_filled"] = r.holes_filled;
  j["efficiency"] = r.efficiency;
  j["l2_stretch"] = r.l2_stretch;
  j["linf_stretch"] = r.linf_stretch;
  j["flipped_faces"] = r.flipped_faces;
  j["winding"] = r.winding;
  j["base_vertices"] = r.base_vertices;
  j["optimization_passes"] = r.optimization_passes;
  j["times"] = Json{{"check", r.times.check},
                    {"simplify", r.times.simplify},
                    {"refine", r.times.refine},
                    {"total", r.times.total}};
  return j;
}

Json sphere_map_metrics_json(const SphereMapMetrics& m, bool with_targets) {
  Json j;
  j["vertices"] = m.vertices;
  j["faces"] = m.faces;
  j["radius_dev"] = m.radius_dev;
  j["flipped"] = m.flipped_majority;
  j["degenerate"] = m.degenerate_tol;
  j["closed"] = m.closed;
  if (m.closed) {
    j["winding"] = m.winding;
    j["fold_excess"] = m.fold_excess;
  }
  j["efficiency"] = m.efficiency;
  j["linf"] = m.linf;
  j["conformal_mean"] = m.conformal_mean;
  j["conformal_p95"] = m.conformal_p95;
  j["area_log_mean"] = m.area_log_mean;
  if (with_targets) j["feature_err_deg"] = m.feature_err_deg ? Json(*m.feature_err_deg) : Json(nullptr);
  j["flipped_exact"] = m.flipped;
  j["degenerate_exact"] = m.degenerate;
  j["l2_stretch"] = m.l2_stretch;
  return j;
}

}  // namespace spherekit::pipeline
