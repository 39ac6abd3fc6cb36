// `spherekit eval`: measures any sphere map of a mesh with the definitions of the
// independent evaluator shared/tools/evalsphere.py (evaluate_sphere_map).
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli_common.h"
#include "commands.h"
#include "spherekit/formats/feature_io.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/metrics.h"

namespace spherekit::cli {
namespace {

struct EvalArgs {
  std::string mesh;
  std::string sphere;
  std::string targets;
  bool json = false;
};

// evalsphere.py's --targets format, `name vertex_index x y z` per line, read by
// formats::read_landmark_targets: indices in range, unit vectors, unique names and vertices.
Result<std::vector<FeatureTarget>> read_targets(const std::string& path, int num_vertices) {
  auto read = formats::read_landmark_targets(path, num_vertices);
  if (!read.ok()) return with_file(read.status(), path);
  std::vector<FeatureTarget> targets;
  targets.reserve(read->size());
  for (const formats::LandmarkTarget& t : read.value()) targets.push_back(FeatureTarget{t.vertex, t.p});
  return targets;
}

void print_human(const EvalArgs& a, const SphereMapMetrics& m) {
  std::printf("%s on %s: %d vertices, %d faces\n", a.sphere.c_str(), a.mesh.c_str(), m.vertices, m.faces);
  std::printf("  flipped %d (exact predicate %d), degenerate %d (exact %d), radius deviation %.3g\n",
              m.flipped_majority, m.flipped, m.degenerate_tol, m.degenerate, m.radius_dev);
  if (m.closed)
    std::printf("  closed: winding %.6f, fold excess %.3g\n", m.winding, m.fold_excess);
  else
    std::printf("  open mesh: winding and fold excess not defined\n");
  std::printf("  efficiency %.4f (L2 stretch %.4f), Linf stretch %.4g\n", m.efficiency, m.l2_stretch, m.linf);
  std::printf("  conformal distortion mean %.4f, p95 %.4f; area distortion mean |log| %.4f\n", m.conformal_mean,
              m.conformal_p95, m.area_log_mean);
  if (!a.targets.empty()) {
    if (m.feature_err_deg)
      std::printf("  feature error max %.4f deg\n", *m.feature_err_deg);
    else
      std::printf("  feature error: no targets in %s\n", a.targets.c_str());
  }
}

int run_eval(const EvalArgs& a) {
  auto mesh = formats::read_mesh(a.mesh);
  if (!mesh.ok()) return print_error(with_file(mesh.status(), a.mesh));
  // Out-of-range coordinates make every stretch measure NaN or 0: refuse them like param does.
  if (Status s = with_file(require_supported_coordinates(mesh.value()), a.mesh); !s.ok()) return print_error(s);

  // The sphere file is read as a plain mesh, not with read_sphere_map, because that
  // normalizes the points and radius_dev must report how far from unit they really are
  // (as evalsphere.py does). Its faces are ignored: the mesh's faces define the map, so a
  // mesh with holes is measured over its real faces only.
  formats::ReadOptions lenient;
  lenient.polygons = formats::PolygonPolicy::Triangulate;
  auto sphere = formats::read_mesh(a.sphere, lenient);
  if (!sphere.ok()) return print_error(with_file(sphere.status(), a.sphere));
  const auto nv = mesh->V.rows();
  if (sphere->V.rows() != nv)
    return print_error(Status(ErrorCode::InvalidInput,
                              format_text("%s: sphere map has %lld vertices, mesh %s has %lld", a.sphere.c_str(),
                                        static_cast<long long>(sphere->V.rows()), a.mesh.c_str(),
                                        static_cast<long long>(nv))));

  // The evaluator normalises the points itself, in plain double arithmetic: beyond these
  // radii |s|^2 overflows or underflows and every measure becomes NaN or 0 ("zero point").
  // read_sphere_map (convert) normalises such points exactly; eval must see them as written.
  for (Eigen::Index i = 0; i < sphere->V.rows(); ++i) {
    const double radius = sphere->V.row(i).cwiseAbs().maxCoeff();
    if (radius > kMaxCoordinate || (radius > 0 && radius < kMinExtent))
      return print_error(Status(ErrorCode::InvalidInput,
                                format_text("%s: point %lld is %.3g from the origin, outside the %.0e..%.0e eval "
                                          "can measure; normalise the points",
                                          a.sphere.c_str(), static_cast<long long>(i), sphere->V.row(i).stableNorm(),
                                          kMinExtent, kMaxCoordinate)));
  }

  std::vector<FeatureTarget> targets;
  if (!a.targets.empty()) {
    auto t = read_targets(a.targets, static_cast<int>(nv));
    if (!t.ok()) return print_error(t.status());
    targets = std::move(t).value();
  }

  auto metrics = evaluate_sphere_map(mesh.value(), sphere->V, targets);
  if (!metrics.ok()) return print_error(with_file(metrics.status(), a.sphere));

  if (a.json)
    std::printf("%s\n", sphere_map_metrics_json(metrics.value(), !a.targets.empty()).dump().c_str());
  else
    print_human(a, metrics.value());
  return 0;
}

}  // namespace

void register_eval(CLI::App& app) {
  auto args = std::make_shared<EvalArgs>();
  CLI::App* cmd = add_command(
      app, "eval", "Measure a sphere map like shared/tools/evalsphere.py",
      "Measure a sphere map SPHERE of MESH (any producer: same vertex order, faces taken from MESH)\n"
      "with the quantities and definitions of shared/tools/evalsphere.py: flipped and degenerate\n"
      "faces, winding number and fold excess (closed meshes), stretch efficiency 1/L2n^2 (faces\n"
      "weighted by surface area, Jacobians on chord triangles), Linf stretch, conformal and area\n"
      "distortion, and with --targets the largest angle between feature vertices and their target\n"
      "points. --json prints evalsphere.py's JSON keys plus flipped_exact/degenerate_exact (exact\n"
      "orientation predicate). Exit 0 whenever the map could be measured, whatever its quality.",
      "  spherekit eval spot.obj spot.sphere.obj\n"
      "  spherekit eval bunny.obj bunny.sphere.obj --json\n"
      "  spherekit eval cat0.obj cat0.sphere.obj --targets cat0.targets.txt --json");
  cmd->add_option("MESH", args->mesh, "the surface mesh")->required();
  cmd->add_option("SPHERE", args->sphere, "the sphere map (.obj; vertex positions = sphere points)")->required();
  cmd->add_option("--targets", args->targets,
                  "lines 'name vertex_index x y z' (x y z a unit vector): where feature vertices must land");
  cmd->add_flag("--json", args->json, "print one JSON line instead of text");
  cmd->callback([args] { set_exit_code(run_eval(*args)); });
}

}  // namespace spherekit::cli
