// `spherekit param`: one mesh -> its stretch-minimizing bijective sphere map
// (parameterize_sphere, Praun & Hoppe 2003), written only when it is a bijection.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>

#include "cli_common.h"
#include "commands.h"
#include "spherekit/constrained_param.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/feature_io.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/sphere_param.h"
#include "spherekit/version.h"

namespace spherekit::cli {
namespace {

struct ParamArgs {
  std::string mesh;
  std::string output;
  std::string report;
  bool quiet = false;
  SphereParamOptions options;
  // Constrained mode (--features with --targets).
  std::string features;
  std::string targets;
  std::string dump_network;
  ConstrainedFlags flags;
};

void print_summary(const ParamArgs& a, const LoadedMesh& m, const SphereParamResult& r, double wall, double cpu,
                   double peak_mb) {
  std::printf("%s -> %s\n", a.mesh.c_str(), a.output.c_str());
  std::printf("  %d vertices, %d faces, %d hole%s filled; base %d vertices, %d optimization passes\n",
              m.check.vertices, m.check.faces, r.holes_filled, r.holes_filled == 1 ? "" : "s", r.base_vertices,
              r.optimization_passes);
  std::printf("  efficiency %.4f, L2 stretch %.4f, Linf stretch %.4g, flipped faces %d, winding %.6f\n", r.efficiency,
              r.l2_stretch, r.linf_stretch, r.flipped_faces, r.winding);
  std::printf("  time: simplify %.2f s, refine %.2f s, total %.2f s (wall %.2f s, CPU %.2f s), peak memory %.0f MB\n",
              r.times.simplify, r.times.refine, r.times.total, wall, cpu, peak_mb);
}

// The path network as an OBJ: each mesh path as a polyline (`l`) in group `paths`, and each
// arc sampled on the unit sphere in group `arcs`, for viewing next to the mesh / sphere map.
std::string network_obj(const FeatureNetworkReport& n) {
  std::string out = "# spherekit path network: mesh paths (group paths), sphere arcs (group arcs)\n";
  int next = 1;
  out += "g paths\n";
  for (const auto& line : n.polylines) {
    for (const auto& p : line) out += strprintf("v %.9g %.9g %.9g\n", p.x(), p.y(), p.z());
    out += "l";
    for (size_t i = 0; i < line.size(); ++i) out += strprintf(" %d", next + static_cast<int>(i));
    out += "\n";
    next += static_cast<int>(line.size());
  }
  out += "g arcs\n";
  constexpr int kSamples = 16;
  for (const auto& arc : n.arcs) {
    const Eigen::Vector3d& a = n.arc_targets[static_cast<size_t>(arc[0])];
    const Eigen::Vector3d& b = n.arc_targets[static_cast<size_t>(arc[1])];
    for (int i = 0; i <= kSamples; ++i) {
      Eigen::Vector3d p = (a + (b - a) * (static_cast<double>(i) / kSamples)).normalized();
      out += strprintf("v %.9g %.9g %.9g\n", p.x(), p.y(), p.z());
    }
    out += "l";
    for (int i = 0; i <= kSamples; ++i) out += strprintf(" %d", next + i);
    out += "\n";
    next += kSamples + 1;
  }
  return out;
}

Json provenance_json(const Provenance& p) {
  return Json{{"library_version", p.library_version},
              {"method", p.method},
              {"options_digest", p.options_digest},
              {"seed", p.seed}};
}

int run_constrained(const ParamArgs& a, const LoadedMesh& m, const Stopwatch& wall) {
  auto lms = formats::read_landmarks(a.features, m.check.vertices);
  if (!lms.ok()) return print_error(with_file(lms.status(), a.features));
  auto pts = formats::read_sphere_points(a.targets, /*require_unit=*/true);
  if (!pts.ok()) return print_error(with_file(pts.status(), a.targets));
  std::vector<int> fv;
  std::vector<Eigen::Vector3d> targets;
  std::vector<std::string> names;
  for (const Landmark& l : lms.value()) {
    const SpherePoint* hit = nullptr;
    for (const SpherePoint& p : pts.value())
      if (p.name == l.name) hit = &p;
    if (!hit)
      return print_error(Status(ErrorCode::InvalidInput,
                                strprintf("%s: no target for feature '%s' of %s", a.targets.c_str(), l.name.c_str(),
                                          a.features.c_str())));
    fv.push_back(l.vertex);
    targets.push_back(hit->p);
    names.push_back(l.name);
  }
  for (const SpherePoint& p : pts.value())
    if (std::find(names.begin(), names.end(), p.name) == names.end())
      return print_error(Status(ErrorCode::InvalidInput, strprintf("%s: target '%s' names no feature of %s", a.targets.c_str(),
                                                                   p.name.c_str(), a.features.c_str())));
  const ConstrainedParamOptions o = a.flags.resolve(a.options);

  ProgressRenderer progress(a.quiet);
  Result<ConstrainedParamResult> result = [&] {
    ComputeScope graceful_cancel;
    return parameterize_sphere_constrained(m.mesh, fv, targets, o, progress.callback());
  }();
  progress.finish();
  if (!result.ok()) return print_error(with_file(result.status(), a.mesh));
  if (cancel_requested()) return print_error(cancelled_status());
  const ConstrainedParamResult& r = result.value();
  if (r.flipped_faces != 0)
    return print_error(Status(ErrorCode::SolverFailed,
                              strprintf("%s: the map has %d flipped faces (not bijective); nothing written",
                                        a.mesh.c_str(), r.flipped_faces)));
  if (!(r.max_feature_angle < 1e-9))
    return print_error(Status(ErrorCode::Internal, strprintf("%s: a feature is %.3g rad off its target; nothing written",
                                                             a.mesh.c_str(), r.max_feature_angle)));
  if (!a.dump_network.empty())
    if (Status s = formats::write_file_atomic(a.dump_network, network_obj(r.network)); !s.ok()) return print_error(s);
  if (Status s = formats::write_sphere_map(a.output, m.mesh, r.map); !s.ok()) return print_error(s);
  const double wall_seconds = wall.seconds();
  const double cpu = cpu_seconds();
  const double peak_mb = peak_rss_mb();
  if (!a.report.empty()) {
    Json j;
    j["input"] = a.mesh;
    j["output"] = a.output;
    j["features"] = a.features;
    j["targets"] = a.targets;
    j["V"] = m.check.vertices;
    j["F"] = m.check.faces;
    j["method"] = "constrained";
    j["efficiency"] = r.efficiency;
    j["l2_stretch"] = r.l2_stretch;
    j["linf_stretch"] = r.linf_stretch;
    j["flipped_faces"] = r.flipped_faces;
    j["winding"] = r.winding;
    j["max_feature_angle"] = r.max_feature_angle;
    j["holes_filled"] = r.holes_filled;
    j["network"] = feature_network_json(r.network);
    j["network"]["features"] = static_cast<int>(fv.size());
    j["times"] = Json{{"read", m.read_seconds}, {"check", r.times.check},     {"network", r.times.network},
                      {"simplify", r.times.simplify}, {"refine", r.times.refine}, {"total", r.times.total},
                      {"wall", wall_seconds}};
    j["cpu_seconds"] = cpu;
    j["peak_rss_mb"] = peak_mb;
    j["options"] = constrained_options_json(o);
    j["version"] = kVersion;
    j["provenance"] = provenance_json(r.map.provenance);
    if (Status s = write_json_atomic(a.report, j); !s.ok()) return print_error(s);
  }
  if (!a.quiet) {
    std::printf("%s -> %s (%zu features on their targets)\n", a.mesh.c_str(), a.output.c_str(), fv.size());
    std::printf("  network: %d paths, total length %.4g, max length/geodesic %.3f, %d swirls fixed, %d flips, %d Steiner vertices%s\n",
                r.network.paths, r.network.total_length, r.network.max_ratio, r.network.swirls_fixed, r.network.edge_flips,
                r.network.steiner_vertices,
                r.network.auxiliary_features ? strprintf(", %d auxiliary features", r.network.auxiliary_features).c_str() : "");
    std::printf("  efficiency %.4f, L2 stretch %.4f, flipped faces %d, winding %.6f, max feature error %.2g rad\n",
                r.efficiency, r.l2_stretch, r.flipped_faces, r.winding, r.max_feature_angle);
    std::printf("  time: network %.2f s, simplify %.2f s, refine %.2f s, total %.2f s (wall %.2f s, CPU %.2f s), peak memory %.0f MB\n",
                r.times.network, r.times.simplify, r.times.refine, r.times.total, wall_seconds, cpu, peak_mb);
  }
  return 0;
}

int run_param(const ParamArgs& a) {
  Stopwatch wall;
  // Every output folder must exist before any work: no partial set of outputs on failure.
  if (Status s = require_output_folders({a.output, a.report, a.dump_network}); !s.ok()) return print_error(s);
  auto loaded = load_mesh_checked(a.mesh, /*allow_boundary=*/true, /*repair=*/false);
  if (!loaded.ok()) return print_error(loaded.status());
  const LoadedMesh& m = loaded.value();
  if (!a.features.empty() || !a.targets.empty()) {
    if (a.features.empty() || a.targets.empty())
      return print_error(Status(ErrorCode::InvalidArgument, "--features and --targets go together"));
    return run_constrained(a, m, wall);
  }
  if (!a.dump_network.empty())
    return print_error(Status(ErrorCode::InvalidArgument, "--dump-network needs --features and --targets"));

  ProgressRenderer progress(a.quiet);
  Result<SphereParamResult> result = [&] {
    ComputeScope graceful_cancel;
    return parameterize_sphere(m.mesh, a.options, progress.callback());
  }();
  progress.finish();
  if (!result.ok()) return print_error(with_file(result.status(), a.mesh));
  if (cancel_requested()) return print_error(cancelled_status());
  const SphereParamResult& r = result.value();

  // A map that is not a bijection is a failure, never an output: later stages (resampling,
  // correspondence) silently produce garbage from a folded map.
  if (r.flipped_faces != 0)
    return print_error(Status(ErrorCode::SolverFailed,
                              strprintf("%s: the map has %d flipped faces (not bijective); nothing written",
                                        a.mesh.c_str(), r.flipped_faces)));

  Stopwatch write_time;
  if (Status s = formats::write_sphere_map(a.output, m.mesh, r.map); !s.ok()) return print_error(s);
  const double write_seconds = write_time.seconds();

  const double wall_seconds = wall.seconds();
  const double cpu = cpu_seconds();
  const double peak_mb = peak_rss_mb();
  if (!a.report.empty()) {
    Json j;
    j["input"] = a.mesh;
    j["output"] = a.output;
    j["V"] = m.check.vertices;
    j["F"] = m.check.faces;
    const Json measures = sphere_param_result_json(r);  // named: items() does not extend its lifetime
    for (const auto& [key, value] : measures.items()) j[key] = value;
    j["times"]["read"] = m.read_seconds;
    j["times"]["write"] = write_seconds;
    j["times"]["wall"] = wall_seconds;
    j["cpu_seconds"] = cpu;
    j["peak_rss_mb"] = peak_mb;
    j["options"] = sphere_param_options_json(a.options);
    j["version"] = kVersion;
    j["provenance"] = provenance_json(r.map.provenance);
    if (Status s = write_json_atomic(a.report, j); !s.ok()) return print_error(s);
  }
  if (!a.quiet) print_summary(a, m, r, wall_seconds, cpu, peak_mb);
  return 0;
}

}  // namespace

void register_param(CLI::App& app) {
  auto args = std::make_shared<ParamArgs>();
  CLI::App* cmd = add_command(
      app, "param", "Map a genus-0 mesh bijectively onto the unit sphere (stretch-minimizing)",
      "Map a genus-0 triangle mesh bijectively onto the unit sphere, minimizing the L2 stretch of\n"
      "the map sphere -> surface (Praun & Hoppe 2003: progressive mesh down to a tetrahedron, then\n"
      "coarse-to-fine vertex splits with stretch optimization). Holes are closed with low-weight\n"
      "faces that do not appear in the output. The sphere map is an OBJ with the mesh's vertex\n"
      "order and faces whose vertices are the unit-sphere points. It is written only if the map is\n"
      "a bijection (0 flipped faces by exact predicate; otherwise exit 5). Progress goes to stderr,\n"
      "a summary to stdout; --report writes the measures, per-stage times and peak memory as JSON.\n"
      "\n"
      "With --features F.lm.txt (`name vertex` lines) and --targets T.txt (`name x y z` unit\n"
      "vectors, same names) the map is constrained (Asirvatham, Praun, Hoppe 2005 §4): every\n"
      "feature vertex lands exactly on its target. A path network links the features on the\n"
      "mesh and on the sphere; --dump-network writes it (mesh paths and sphere arcs) as OBJ\n"
      "polylines, and the report gives its total length, worst length/geodesic ratio and the\n"
      "swirls it fixed.",
      "  spherekit param spot.obj -o spot.sphere.obj\n"
      "  spherekit param bunny.obj -o bunny.sphere.obj --report bunny.json --effort 3\n"
      "  spherekit param igea.ply -o igea.sphere.obj --threads 2 --quiet\n"
      "  spherekit param cat2.obj --features cat2.lm.txt --targets cat0.targets.txt -o cat2.sphere.obj");
  cmd->add_option("MESH", args->mesh, "input mesh (.obj .ply .off .stl .gltf .glb)")->required();
  cmd->add_option("-o,--output", args->output, "sphere map to write (.obj)")->required();
  cmd->add_option("--report", args->report, "also write a JSON report here");
  cmd->add_flag("-q,--quiet", args->quiet, "print neither progress nor the summary (errors still)");
  add_sphere_param_options(*cmd, args->options);
  cmd->add_option("--features", args->features, "feature vertices (`name vertex` lines): constrained map");
  cmd->add_option("--targets", args->targets, "their sphere points (`name x y z` unit vectors)");
  cmd->add_option("--dump-network", args->dump_network, "write the path network here (.obj polylines)");
  add_constrained_flags(*cmd, args->flags);
  cmd->callback([args] { set_exit_code(run_param(*args)); });
}

}  // namespace spherekit::cli
