// Tests of the sphere-map metrics (metrics.cpp): hand-made maps with exact or closed-form
// answers, and a two-way oracle against the independent evaluator shared/tools/evalsphere.py.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "spherekit/metrics.h"
#include "spherekit/predicates.h"
#include "test_meshes.h"
#include "test_paths.h"

namespace {

using namespace spherekit;
using Eigen::Vector3d;

constexpr double kPi = 3.14159265358979323846;

Vector3d row(const RowMat3d& M, Eigen::Index i) { return M.row(i).transpose(); }

/// Sphere map of a star-shaped mesh: radial projection of its vertices.
RowMat3d radial(const TriMesh& m) { return m.V.rowwise().normalized(); }

/// The first face containing vertex v, rotated so that v comes first.
Eigen::Vector3i face_at(const RowMat3i& F, int v) {
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (F(f, k) == v) return {F(f, k), F(f, (k + 1) % 3), F(f, (k + 2) % 3)};
  return {-1, -1, -1};
}

SphereMapMetrics evaluate(const TriMesh& mesh, const RowMat3d& S, const std::vector<FeatureTarget>& targets = {},
                          const std::vector<char>* mask = nullptr) {
  auto r = evaluate_sphere_map(mesh, S, targets, mask);
  INFO(r.status().message());
  REQUIRE(r.ok());
  return *r;
}

/// Moves vertex v across the opposite edge of one of its faces (a fold): that face flips.
RowMat3d fold_one_vertex(const TriMesh& mesh, RowMat3d S, int v) {
  const Eigen::Vector3i f = face_at(mesh.F, v);
  const Vector3d mid = (row(S, f[1]) + row(S, f[2])).normalized();
  S.row(v) = (mid + 0.5 * (mid - row(S, v))).normalized().transpose();
  return S;
}

// --- tiny helpers for the evalsphere oracle -------------------------------------------------

void write_obj(const std::string& path, const RowMat3d& V, const RowMat3i& F, const std::vector<char>* keep = nullptr) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  REQUIRE(f != nullptr);
  for (Eigen::Index i = 0; i < V.rows(); ++i) std::fprintf(f, "v %.17g %.17g %.17g\n", V(i, 0), V(i, 1), V(i, 2));
  for (Eigen::Index i = 0; i < F.rows(); ++i)
    if (!keep || (*keep)[static_cast<size_t>(i)]) std::fprintf(f, "f %d %d %d\n", F(i, 0) + 1, F(i, 1) + 1, F(i, 2) + 1);
  std::fclose(f);
}

/// The number after `"key": ` in evalsphere's one-line JSON output (Infinity/NaN included).
std::optional<double> json_number(const std::string& json, const std::string& key) {
  const std::string pattern = "\"" + key + "\": ";
  const size_t at = json.find(pattern);
  if (at == std::string::npos) return std::nullopt;
  const char* begin = json.c_str() + at + pattern.size();
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (end == begin) return std::nullopt;
  return v;
}

/// Path of evalsphere.py when it and /usr/bin/python3 with numpy are available.
std::optional<std::string> evalsphere_script() {
  const auto shared = test::shared_dir();
  if (!shared) return std::nullopt;
  const std::string script = *shared + "/tools/evalsphere.py";
  if (!std::filesystem::exists(script) || !std::filesystem::exists("/usr/bin/python3")) return std::nullopt;
  if (std::system("/usr/bin/python3 -c 'import numpy' >/dev/null 2>&1") != 0) return std::nullopt;
  return script;
}

std::string run_evalsphere(const std::string& script, const std::string& mesh, const std::string& sphere) {
  const std::string cmd = "/usr/bin/python3 '" + script + "' '" + mesh + "' '" + sphere + "' 2>&1";
  std::FILE* p = popen(cmd.c_str(), "r");
  REQUIRE(p != nullptr);
  std::string out;
  char buf[4096];
  while (size_t n = std::fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  const int status = pclose(p);
  INFO(out);
  REQUIRE(status == 0);
  return out;
}

/// |ours - theirs| <= tol * max(1, |theirs|), or both the same infinity.
void check_close(const std::string& json, const std::string& key, double ours, double tol = 1e-6) {
  const auto theirs = json_number(json, key);
  INFO("key " << key << " ours " << ours << " evalsphere " << (theirs ? *theirs : NAN) << "\n" << json);
  REQUIRE(theirs.has_value());
  if (std::isinf(*theirs)) {
    CHECK(ours == *theirs);
    return;
  }
  CHECK(std::fabs(ours - *theirs) <= tol * std::max(1.0, std::fabs(*theirs)));
}

}  // namespace

TEST_CASE("metrics: identity map of a unit icosphere is isometric", "[metrics]") {
  // The mesh is its own sphere map: every chord triangle IS the surface triangle, so each
  // face Jacobian is a rotation (a = c = 1, b = 0) up to rounding.
  const TriMesh m = test::icosphere(4);
  const SphereMapMetrics r = evaluate(m, m.V);
  CHECK(r.vertices == m.V.rows());
  CHECK(r.faces == m.F.rows());
  CHECK(r.radius_dev < 1e-15);
  CHECK(r.flipped == 0);
  CHECK(r.degenerate == 0);
  CHECK(r.flipped_majority == 0);
  CHECK(r.degenerate_tol == 0);
  CHECK(r.closed);
  CHECK(std::fabs(r.winding - 1) < 1e-12);
  CHECK(std::fabs(r.fold_excess) < 1e-12);
  CHECK(std::fabs(r.efficiency - 1) < 1e-12);
  CHECK(std::fabs(r.l2_stretch - 1) < 1e-12);
  CHECK(std::fabs(r.linf - 1) < 1e-12);
  CHECK(std::fabs(r.conformal_mean - 1) < 1e-12);
  CHECK(std::fabs(r.conformal_p95 - 1) < 1e-12);
  CHECK(r.area_log_mean < 1e-12);
  CHECK_FALSE(r.feature_err_deg.has_value());
  CHECK(count_flipped_faces(m.F, m.V) == 0);
}

TEST_CASE("metrics: uniform scaling of surface or sphere changes nothing", "[metrics]") {
  const TriMesh base = test::random_blob(2, 5);
  const RowMat3d S = radial(base);
  const SphereMapMetrics r0 = evaluate(base, S);
  REQUIRE(r0.flipped == 0);
  TriMesh big = base;
  big.V *= 3.0;  // the surface is normalised to the domain's area
  const SphereMapMetrics r1 = evaluate(big, S);
  const SphereMapMetrics r2 = evaluate(base, 0.25 * S);  // the sphere points are normalised
  for (const SphereMapMetrics* r : {&r1, &r2}) {
    CHECK(r->efficiency == Approx(r0.efficiency).epsilon(1e-12));
    CHECK(r->linf == Approx(r0.linf).epsilon(1e-12));
    CHECK(r->conformal_mean == Approx(r0.conformal_mean).epsilon(1e-12));
    CHECK(r->conformal_p95 == Approx(r0.conformal_p95).epsilon(1e-12));
    CHECK(r->area_log_mean == Approx(r0.area_log_mean).epsilon(1e-10));
    CHECK(r->winding == Approx(r0.winding).epsilon(1e-12));
  }
  CHECK(r2.radius_dev == Approx(0.75));
  CHECK(r0.efficiency < 1.0);
}

TEST_CASE("metrics: anisotropic scaling x*2 of the icosphere, closed form per face", "[metrics]") {
  // Surface = D * chord triangle with D = diag(2, 1, 1). With s, t an orthonormal frame of the
  // chord triangle, Ss = D s and St = D t, so
  //   a = |D s|^2 = 1 + 3 s_x^2,  c = 1 + 3 t_x^2,  b = 3 s_x t_x,
  //   a + c = trace(D^T D) - |D n|^2 = 5 - 3 n_x^2            (n the unit chord normal),
  //   area_surface = area_domain * |cof(D) n| = area_domain * sqrt(4 - 3 n_x^2).
  const TriMesh sphere = test::icosphere(3);
  TriMesh m = sphere;
  m.V.col(0) *= 2.0;

  const Eigen::Index f0 = 17;
  const Vector3d q0 = row(sphere.V, sphere.F(f0, 0)), q1 = row(sphere.V, sphere.F(f0, 1)),
                 q2 = row(sphere.V, sphere.F(f0, 2));
  const Vector3d p0 = row(m.V, m.F(f0, 0)), p1 = row(m.V, m.F(f0, 1)), p2 = row(m.V, m.F(f0, 2));
  const FaceStretch fs = face_stretch(p0, p1, p2, q0, q1, q2);
  const Vector3d s = (q1 - q0).normalized();
  const Vector3d t = ((q2 - q0) - (q2 - q0).dot(s) * s).normalized();
  const Vector3d n = (q1 - q0).cross(q2 - q0).normalized();
  CHECK(fs.a == Approx(1 + 3 * s.x() * s.x()).epsilon(1e-12));
  CHECK(fs.c == Approx(1 + 3 * t.x() * t.x()).epsilon(1e-12));
  CHECK(fs.b == Approx(3 * s.x() * t.x()).margin(1e-12));
  CHECK(fs.area_domain == Approx(0.5 * (q1 - q0).cross(q2 - q0).norm()).epsilon(1e-12));
  CHECK(fs.area_surface == Approx(fs.area_domain * std::sqrt(4 - 3 * n.x() * n.x())).epsilon(1e-12));

  // Whole mesh from the closed form: L2n^2 = (sum A' (a+c)/2 / sum A') (sum A / sum A').
  double sum_dom = 0, sum_surf = 0, sum_l2 = 0, max_g2 = 0;
  for (Eigen::Index f = 0; f < sphere.F.rows(); ++f) {
    const Vector3d a = row(sphere.V, sphere.F(f, 0)), b = row(sphere.V, sphere.F(f, 1)), c = row(sphere.V, sphere.F(f, 2));
    const Vector3d nf = (b - a).cross(c - a);
    const double area = 0.5 * nf.norm(), nx = nf.x() / nf.norm();
    const double surf = area * std::sqrt(4 - 3 * nx * nx);
    sum_dom += area;
    sum_surf += surf;
    sum_l2 += surf * 0.5 * (5 - 3 * nx * nx);
    // Singular values of D on the plane: the largest is sqrt(1 + 3 (1 - n_x^2)).
    max_g2 = std::max(max_g2, 4 - 3 * nx * nx);
  }
  const double scale = sum_dom / sum_surf;
  const double L2sq = sum_l2 / sum_surf * scale;
  const SphereMapMetrics r = evaluate(m, sphere.V);
  CHECK(r.efficiency < 0.95);
  CHECK(r.efficiency == Approx(1 / L2sq).epsilon(1e-12));
  CHECK(r.l2_stretch == Approx(std::sqrt(L2sq)).epsilon(1e-12));
  CHECK(r.linf == Approx(std::sqrt(max_g2 * scale)).epsilon(1e-12));
  CHECK(r.conformal_p95 <= 2.0 + 1e-12);  // Gamma/gamma <= 2 for D
  CHECK(r.conformal_mean > 1.0);
  CHECK(r.flipped == 0);
  CHECK(std::fabs(r.winding - 1) < 1e-12);
}

TEST_CASE("metrics: a folded vertex flips faces but keeps winding 1", "[metrics]") {
  const TriMesh m = test::icosphere(2);
  const RowMat3d S = fold_one_vertex(m, m.V, 7);
  const SphereMapMetrics r = evaluate(m, S);
  CHECK(r.flipped > 0);
  CHECK(r.flipped == r.flipped_majority);
  CHECK(r.degenerate == 0);
  CHECK(r.closed);
  CHECK(std::fabs(r.winding - 1) < 1e-12);  // a fold has degree 1: signed area still 4 pi
  CHECK(r.fold_excess > 1e-3);              // but |area| double-covers the folded region
  CHECK(count_flipped_faces(m.F, S) == r.flipped + r.degenerate);
  // Brute-force recount with the predicate directly.
  int flipped = 0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    flipped += orient3d_origin(row(S, m.F(f, 0)), row(S, m.F(f, 1)), row(S, m.F(f, 2))) < 0;
  CHECK(flipped == r.flipped);
}

TEST_CASE("metrics: mirrored map has winding -1; exact counts are relative to +1", "[metrics]") {
  const TriMesh m = test::icosphere(2);
  RowMat3d S = m.V;
  S.col(0) *= -1.0;
  const SphereMapMetrics r = evaluate(m, S);
  CHECK(std::fabs(r.winding + 1) < 1e-12);
  CHECK(std::fabs(r.fold_excess) < 1e-12);
  CHECK(r.flipped == m.F.rows());   // every face is clockwise seen from outside
  CHECK(r.flipped_majority == 0);   // evalsphere compares with the majority orientation
  CHECK(count_flipped_faces(m.F, S) == m.F.rows());
}

TEST_CASE("metrics: collapsed vertices are exactly degenerate", "[metrics]") {
  const TriMesh m = test::octahedron();
  RowMat3d S = m.V;
  // Put vertex 4 (+z) exactly on the great circle z = 0 between +x and +y: faces (0,2,4) and
  // neighbours become exactly degenerate or flipped, decided exactly.
  S.row(4) << 1, 1, 0;
  const SphereMapMetrics r = evaluate(m, S);
  CHECK(r.degenerate >= 1);
  CHECK(r.degenerate == r.degenerate_tol);  // the float test agrees on these exact zeros
  CHECK(count_flipped_faces(m.F, S) == r.flipped + r.degenerate);
  // Coincident points: a vertex of an icosphere put on one of its neighbours. Exactly the two
  // faces sharing their edge become degenerate (no two icosphere neighbours are antipodal).
  const TriMesh ico = test::icosphere(1);
  const Eigen::Vector3i f = face_at(ico.F, 0);
  RowMat3d S2 = ico.V;
  S2.row(0) = S2.row(f[1]);
  const SphereMapMetrics r2 = evaluate(ico, S2);
  CHECK(r2.degenerate == 2);
  CHECK(r2.degenerate_tol == 2);
  CHECK(count_flipped_faces(ico.F, S2) == r2.flipped + 2);
}

TEST_CASE("metrics: open meshes report closed = false and no winding", "[metrics]") {
  const TriMesh m = test::sphere_with_holes(2, 2);
  const SphereMapMetrics r = evaluate(m, m.V);
  CHECK_FALSE(r.closed);
  CHECK(r.winding == 0);
  CHECK(r.fold_excess == 0);
  CHECK(std::fabs(r.efficiency - 1) < 1e-12);
}

TEST_CASE("metrics: face mask restricts stretch statistics, not orientation", "[metrics]") {
  // Masked evaluation of the closed mesh == unmasked evaluation of the sub-mesh of masked faces
  // for the stretch statistics; orientation and winding still see every face.
  const TriMesh m = test::random_blob(2, 9);
  const RowMat3d S = fold_one_vertex(m, radial(m), 3);
  std::vector<char> mask(static_cast<size_t>(m.F.rows()), 1);
  for (size_t f = 0; f < mask.size(); f += 7) mask[f] = 0;
  TriMesh sub;
  sub.V = m.V;
  sub.F.resize(std::count(mask.begin(), mask.end(), 1), 3);
  for (Eigen::Index f = 0, k = 0; f < m.F.rows(); ++f)
    if (mask[static_cast<size_t>(f)]) sub.F.row(k++) = m.F.row(f);
  const SphereMapMetrics all = evaluate(m, S);
  const SphereMapMetrics masked = evaluate(m, S, {}, &mask);
  const SphereMapMetrics part = evaluate(sub, S);
  CHECK(masked.efficiency == Approx(part.efficiency).epsilon(1e-12));
  CHECK(masked.l2_stretch == Approx(part.l2_stretch).epsilon(1e-12));
  CHECK(masked.linf == Approx(part.linf).epsilon(1e-12));
  CHECK(masked.conformal_mean == Approx(part.conformal_mean).epsilon(1e-12));
  CHECK(masked.conformal_p95 == Approx(part.conformal_p95).epsilon(1e-12));
  CHECK(masked.area_log_mean == Approx(part.area_log_mean).epsilon(1e-12));
  CHECK(masked.efficiency != Approx(all.efficiency).epsilon(1e-9));
  CHECK(masked.flipped == all.flipped);
  CHECK(masked.flipped_majority == all.flipped_majority);
  CHECK(masked.closed);
  CHECK(masked.winding == all.winding);
  CHECK(masked.fold_excess == all.fold_excess);
  CHECK_FALSE(part.closed);
}

TEST_CASE("metrics: feature error for known targets", "[metrics]") {
  const TriMesh m = test::icosphere(2);
  std::vector<FeatureTarget> targets(2);
  targets[0].vertex = 0;
  targets[0].target = 5.0 * row(m.V, 0);  // exactly on the vertex (targets are normalised)
  targets[1].vertex = 5;
  const Vector3d v5 = row(m.V, 5);
  const Vector3d axis = v5.unitOrthogonal();
  targets[1].target = Eigen::AngleAxisd(10.0 * kPi / 180.0, axis) * v5;
  SphereMapMetrics r = evaluate(m, m.V, targets);
  REQUIRE(r.feature_err_deg.has_value());
  CHECK(*r.feature_err_deg == Approx(10.0).epsilon(1e-12));
  targets.pop_back();
  r = evaluate(m, m.V, targets);
  REQUIRE(r.feature_err_deg.has_value());
  CHECK(*r.feature_err_deg < 1e-12);  // atan2 formula: no sqrt(eps) noise at 0
}

TEST_CASE("metrics: invalid inputs give InvalidInput", "[metrics]") {
  const TriMesh m = test::icosphere(1);
  auto code = [](const Result<SphereMapMetrics>& r) { return r.ok() ? ErrorCode::Ok : r.status().code(); };
  CHECK(code(evaluate_sphere_map(m, m.V.topRows(m.V.rows() - 1))) == ErrorCode::InvalidInput);
  RowMat3d S = m.V;
  S(3, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK(code(evaluate_sphere_map(m, S)) == ErrorCode::InvalidInput);
  S = m.V;
  S(2, 0) = std::numeric_limits<double>::infinity();
  CHECK(code(evaluate_sphere_map(m, S)) == ErrorCode::InvalidInput);
  S = m.V;
  S.row(4).setZero();
  CHECK(code(evaluate_sphere_map(m, S)) == ErrorCode::InvalidInput);
  TriMesh bad = m;
  bad.F(0, 1) = static_cast<int>(m.V.rows());
  CHECK(code(evaluate_sphere_map(bad, m.V)) == ErrorCode::InvalidInput);
  bad = m;
  bad.V(0, 0) = std::numeric_limits<double>::quiet_NaN();
  CHECK(code(evaluate_sphere_map(bad, m.V)) == ErrorCode::InvalidInput);
  bad = m;
  bad.F.resize(0, 3);
  CHECK(code(evaluate_sphere_map(bad, m.V)) == ErrorCode::InvalidInput);
  std::vector<char> short_mask(static_cast<size_t>(m.F.rows() - 1), 1);
  CHECK(code(evaluate_sphere_map(m, m.V, {}, &short_mask)) == ErrorCode::InvalidInput);
  std::vector<char> empty_mask(static_cast<size_t>(m.F.rows()), 0);
  CHECK(code(evaluate_sphere_map(m, m.V, {}, &empty_mask)) == ErrorCode::InvalidInput);
  std::vector<FeatureTarget> targets(1);
  targets[0].vertex = static_cast<int>(m.V.rows());
  CHECK(code(evaluate_sphere_map(m, m.V, targets)) == ErrorCode::InvalidInput);
  targets[0].vertex = 0;
  targets[0].target.setZero();
  CHECK(code(evaluate_sphere_map(m, m.V, targets)) == ErrorCode::InvalidInput);
  auto r = evaluate_sphere_map(m, m.V.topRows(3));
  CHECK_FALSE(r.ok());
  CHECK(r.status().message().find("vertices") != std::string::npos);
}

TEST_CASE("metrics: two-way oracle against evalsphere.py", "[metrics]") {
  const auto script = evalsphere_script();
  if (!script) {
    SPHEREKIT_SKIP("../shared/tools/evalsphere.py or /usr/bin/python3 with numpy is absent");
  }
  const std::string dir = test::temp_dir("metrics_evalsphere");
  const TriMesh m = test::random_blob(3, 7);
  // A valid but non-trivial map: radial projection, jittered along the sphere by up to a
  // tenth of the smallest edge, then each point scaled (normalised again by both sides).
  RowMat3d S = radial(m);
  double min_edge = 1e9;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) min_edge = std::min(min_edge, (S.row(m.F(f, k)) - S.row(m.F(f, (k + 1) % 3))).norm());
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(-1, 1), R(0.5, 2.0);
  for (Eigen::Index v = 0; v < S.rows(); ++v) {
    const Vector3d jitter(U(rng), U(rng), U(rng));
    S.row(v) = (row(S, v) + 0.1 * min_edge * jitter).normalized().transpose() * R(rng);
  }
  REQUIRE(count_flipped_faces(m.F, S) == 0);
  const RowMat3d S_folded = fold_one_vertex(m, S, 11);

  const std::string mesh_path = dir + "/mesh.obj";
  write_obj(mesh_path, m.V, m.F);
  struct Case {
    const char* name;
    const RowMat3d* S;
  };
  for (const Case& c : {Case{"valid", &S}, Case{"folded", &S_folded}}) {
    SECTION(c.name) {
      const std::string sphere_path = dir + "/" + c.name + ".sphere.obj";
      write_obj(sphere_path, *c.S, m.F);
      const std::string json = run_evalsphere(*script, mesh_path, sphere_path);
      const SphereMapMetrics r = evaluate(m, *c.S);
      check_close(json, "radius_dev", r.radius_dev);
      check_close(json, "efficiency", r.efficiency);
      check_close(json, "linf", r.linf);
      check_close(json, "conformal_mean", r.conformal_mean);
      check_close(json, "conformal_p95", r.conformal_p95);
      check_close(json, "area_log_mean", r.area_log_mean);
      check_close(json, "winding", r.winding);
      check_close(json, "fold_excess", r.fold_excess);
      CHECK(json.find("\"closed\": true") != std::string::npos);
      CHECK(json_number(json, "flipped") == std::optional<double>(r.flipped_majority));
      CHECK(json_number(json, "degenerate") == std::optional<double>(r.degenerate_tol));
      CHECK(r.flipped == r.flipped_majority);  // no near-degenerate faces here
      if (c.S == &S_folded) CHECK(r.flipped > 0);
    }
  }
  SECTION("collapsed cap: zero-area domains, infinite percentile") {
    // Every vertex with z > 0.5 is sent to the north pole: hundreds of sphere triangles with
    // coincident corners (exactly degenerate, A_dom = 0, Gamma/gamma = inf) cover > 5% of the
    // surface, so the 95th percentile is inf in both. efficiency, linf and area_log_mean are
    // left out here: faces with two coincident corners have A_dom made of rounding noise.
    RowMat3d C = radial(m);
    for (Eigen::Index v = 0; v < C.rows(); ++v)
      if (C(v, 2) > 0.5) C.row(v) << 0, 0, 1;
    const std::string sphere_path = dir + "/cap.sphere.obj";
    write_obj(sphere_path, C, m.F);
    const std::string json = run_evalsphere(*script, mesh_path, sphere_path);
    const SphereMapMetrics r = evaluate(m, C);
    CHECK(r.degenerate > 100);
    CHECK(json_number(json, "degenerate") == std::optional<double>(r.degenerate_tol));
    CHECK(json_number(json, "flipped") == std::optional<double>(r.flipped_majority));
    CHECK(r.degenerate == r.degenerate_tol);
    CHECK(std::isinf(r.conformal_p95));
    check_close(json, "conformal_p95", r.conformal_p95);
    check_close(json, "conformal_mean", r.conformal_mean);
    check_close(json, "winding", r.winding);
    check_close(json, "fold_excess", r.fold_excess);
  }
  SECTION("masked faces = evalsphere on the open mesh") {
    std::vector<char> mask(static_cast<size_t>(m.F.rows()), 1);
    for (size_t f = 0; f < mask.size(); f += 5) mask[f] = 0;
    const std::string open_path = dir + "/open.obj", sphere_path = dir + "/masked.sphere.obj";
    write_obj(open_path, m.V, m.F, &mask);
    write_obj(sphere_path, S, m.F);
    const std::string json = run_evalsphere(*script, open_path, sphere_path);
    const SphereMapMetrics r = evaluate(m, S, {}, &mask);
    check_close(json, "efficiency", r.efficiency);
    check_close(json, "linf", r.linf);
    check_close(json, "conformal_mean", r.conformal_mean);
    check_close(json, "conformal_p95", r.conformal_p95);
    check_close(json, "area_log_mean", r.area_log_mean);
    CHECK(json.find("\"closed\": false") != std::string::npos);
  }
}

TEST_CASE("metrics: timing on an icosphere of level 7 (327,680 faces)", "[.][metrics_benchmark]") {
  const TriMesh sphere = test::icosphere(7);
  TriMesh m = test::elongated(7, 3.0);
  const auto t0 = std::chrono::steady_clock::now();
  const SphereMapMetrics r = evaluate(m, sphere.V);
  const auto t1 = std::chrono::steady_clock::now();
  const int flipped = count_flipped_faces(m.F, sphere.V);
  const auto t2 = std::chrono::steady_clock::now();
  const double ms_eval = std::chrono::duration<double, std::milli>(t1 - t0).count();
  const double ms_flip = std::chrono::duration<double, std::milli>(t2 - t1).count();
  CHECK(r.flipped == 0);
  CHECK(flipped == 0);
  WARN("evaluate_sphere_map on " << r.faces << " faces: " << ms_eval << " ms; count_flipped_faces: " << ms_flip
                                 << " ms; efficiency " << r.efficiency);
}
