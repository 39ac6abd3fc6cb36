// One JSON serialization per result: the keys reports, manifests and the main job record for
// the libraries' results (check, parameterization, evaluation, the path network).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "spherekit/check_mesh.h"
#include "spherekit/constrained_param.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/metrics.h"
#include "spherekit/pipeline/mesh_input.h"
#include "spherekit/sphere_param.h"

namespace spherekit::pipeline {

/// Reports keep the order in which keys are written, so they read like the summaries.
using Json = nlohmann::ordered_json;

/// x, or null when it is not finite (inf PSNR of an exact remesh).
Json number_or_null(double x);
/// Size of a file in bytes, 0 when it cannot be read.
std::uintmax_t file_bytes(const std::string& path);

/// The `check` report of a mesh (key names as in shared/meshes/manifest.json).
Json mesh_check_json(const std::string& file, const MeshCheck& check);
/// The file's faces before triangulation (formats::ReadInfo): counts by corner count and,
/// when some polygon was triangulated, `face_polygon` (per triangle of the mesh, the 0-based
/// face of the file it was cut from; absent means the identity). check --json and param's report.
Json source_faces_json(const formats::ReadInfo& info);
/// What `check --repair` did (repair_mesh) and where it wrote the mesh.
Json mesh_repair_json(const MeshRepair& repair, const std::string& output);
/// The options as recorded in reports.
Json sphere_param_options_json(const SphereParamOptions& options);
/// The constrained options as recorded in reports (the sphere options plus the network's).
Json constrained_options_json(const ConstrainedParamOptions& options);
/// The measures of a constrained map (efficiency, stretch, flips, winding, feature error,
/// holes) as recorded in reports (param) and manifests (each member's "result").
Json constrained_measures_json(const ConstrainedParamResult& result);
/// The path network's statistics as recorded in reports.
Json feature_network_json(const FeatureNetworkReport& network);
/// The measures of a parameterize_sphere() result as recorded in reports (param, run).
Json sphere_param_result_json(const SphereParamResult& result);
/// Sphere-map measures with the keys and conventions of shared/tools/evalsphere.py:
/// `flipped`/`degenerate` are evalsphere's float counts (majority orientation, |det| <= 1e-15),
/// `flipped_exact`/`degenerate_exact` the exact-predicate counts; winding and fold_excess
/// only for closed meshes, feature_err_deg only when targets were given.
Json sphere_map_metrics_json(const SphereMapMetrics& metrics, bool with_targets);

}  // namespace spherekit::pipeline
