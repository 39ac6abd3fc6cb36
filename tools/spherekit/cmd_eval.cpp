// `spherekit eval`: measures any sphere map of a mesh with the definitions of the
// independent evaluator shared/tools/evalsphere.py (evaluate_sphere_map).
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cli_common.h"
#include "commands.h"
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

// evalsphere.py's --targets format: `name vertex_index x y z` per line. Parsed here because
// it exists only for evaluation; `#` comments and blank lines are skipped like the
// landmark files'.
Result<std::vector<FeatureTarget>> read_targets(const std::string& path, int num_vertices) {
  std::ifstream in(path);
  if (!in) return Status(ErrorCode::IoError, path + ": cannot open targets file");
  std::vector<FeatureTarget> targets;
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    if (const size_t hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream fields(line);
    std::string name;
    if (!(fields >> name)) continue;
    long long vertex = 0;
    double x = 0, y = 0, z = 0;
    std::string extra;
    if (!(fields >> vertex >> x >> y >> z) || (fields >> extra))
      return Status(ErrorCode::ParseError,
                    strprintf("%s:%d: expected 'name vertex_index x y z'", path.c_str(), line_no));
    if (vertex < 0 || vertex >= num_vertices)
      return Status(ErrorCode::InvalidInput, strprintf("%s:%d: vertex index %lld out of range [0, %d)", path.c_str(),
                                                       line_no, vertex, num_vertices));
    const Eigen::Vector3d p(x, y, z);
    if (!p.allFinite() || p.norm() == 0)
      return Status(ErrorCode::InvalidInput,
                    strprintf("%s:%d: target point must be finite and non-zero", path.c_str(), line_no));
    targets.push_back(FeatureTarget{static_cast<int>(vertex), p.normalized()});
  }
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
                              strprintf("%s: sphere map has %lld vertices, mesh %s has %lld", a.sphere.c_str(),
                                        static_cast<long long>(sphere->V.rows()), a.mesh.c_str(),
                                        static_cast<long long>(nv))));

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
  cmd->add_option("--targets", args->targets, "lines 'name vertex_index x y z': where feature vertices must land");
  cmd->add_flag("--json", args->json, "print one JSON line instead of text");
  cmd->callback([args] { set_exit_code(run_eval(*args)); });
}

}  // namespace spherekit::cli
