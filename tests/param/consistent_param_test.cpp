// Consistent parameterization of a collection (paper §3) on the built-in samples, whose
// exact ground truth lets the induced correspondence be measured.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include <Eigen/SVD>

#include "detail/collapsed_map.h"
#include "map_checks.h"
#include "sample_collection.h"
#include "spherekit/consistent_param.h"
#include "spherekit/correspondence.h"
#include "spherekit/metrics.h"
#include "spherekit/sphere_param.h"
#include "test_meshes.h"

using namespace spherekit;
using samples::SampleMesh;

namespace {

// Small members so that the six steps run in seconds; the shapes keep their limbs, ears
// and tail (the features are the same 13 landmarks).
const std::vector<SampleMesh>& small_collection() {
  static const std::vector<SampleMesh> c = [] {
    samples::SampleCollectionOptions o;
    o.members = 3;
    o.target_vertices = 1200;
    auto r = samples::make_sample_collection(o);
    REQUIRE(r.ok());
    return std::move(r).value();
  }();
  return c;
}

void split(const std::vector<SampleMesh>& c, std::vector<TriMesh>* meshes, std::vector<std::vector<int>>* features) {
  for (const SampleMesh& m : c) {
    meshes->push_back(m.mesh);
    std::vector<int> f;
    for (const Landmark& l : m.landmarks) f.push_back(l.vertex);
    features->push_back(f);
  }
}

ConsistentParamOptions fast_options() {
  ConsistentParamOptions o;
  o.remesh_size = 33;
  o.constrained.sphere.effort = 1;
  o.threads = 2;
  return o;
}

double surface_area(const TriMesh& m) {
  double a = 0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    a += 0.5 * (m.V.row(m.F(f, 1)) - m.V.row(m.F(f, 0))).cross(m.V.row(m.F(f, 2)) - m.V.row(m.F(f, 0))).norm();
  return a;
}

// Mean distance (/ sqrt(area)) between where the maps send every vertex of `from` and where
// the ground truth says it belongs on `to` (vertices whose true image is in a hole skipped).
double mean_transfer_error(const SampleMesh& from, const RowMat3d& S_from, const SampleMesh& to, const RowMat3d& S_to) {
  std::vector<SurfacePoint> pts;
  for (Eigen::Index v = 0; v < from.mesh.V.rows(); ++v) pts.push_back(vertex_surface_point(from.mesh, static_cast<int>(v)));
  auto moved = transfer_points(from.mesh, S_from, pts, to.mesh, S_to);
  REQUIRE(moved.ok());
  double sum = 0;
  int n = 0;
  for (Eigen::Index v = 0; v < from.mesh.V.rows(); ++v) {
    Eigen::Vector3d truth;
    if (!samples::ground_truth_point(from, static_cast<int>(v), to, &truth)) continue;
    sum += (surface_position(to.mesh, (*moved)[static_cast<size_t>(v)].point) - truth).norm();
    ++n;
  }
  REQUIRE(n > from.mesh.V.rows() / 2);
  return sum / n / std::sqrt(surface_area(to.mesh));
}

double angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

}  // namespace

TEST_CASE("consistent maps: bijective, features coincide exactly, correspondence beats independent maps",
          "[param][consistent]") {
  const auto& c = small_collection();
  std::vector<TriMesh> meshes;
  std::vector<std::vector<int>> features;
  split(c, &meshes, &features);
  auto r = parameterize_consistent(meshes, features, fast_options());
  REQUIRE(r.ok());
  REQUIRE(r->maps.size() == c.size());
  REQUIRE(r->final_locations.size() == features[0].size());
  CHECK(r->remesh_vertices == 31 * 31 + 2 * 33 - 1);  // (N-2)^2 + 2N - 1 welded grid vertices, N = 33
  CHECK(r->joint_flips == 0);
  CHECK(r->joint_efficiency > 0.3);

  for (size_t i = 0; i < c.size(); ++i) {
    INFO(c[i].name);
    test::require_valid_map(c[i].mesh, r->maps[i].map.S);
    for (size_t k = 0; k < features[i].size(); ++k)
      REQUIRE(angle(r->maps[i].map.S.row(features[i][k]).transpose(), r->final_locations[k]) < 1e-9);
  }
  // The final locations are distinct and differ from F' (step 5 moved them), but only a
  // little (same layout).
  double moved = 0;
  for (size_t k = 0; k < r->final_locations.size(); ++k) {
    moved = std::max(moved, angle(r->final_locations[k], r->initial_locations[k]));
    for (size_t l = 0; l < k; ++l) CHECK(angle(r->final_locations[k], r->final_locations[l]) > 1e-3);
  }
  CHECK(moved > 0);
  CHECK(moved < 1.0);

  // Baseline: independent unconstrained maps, each rotated to best match the first one's
  // feature images. On these similar shapes that baseline is already fair (the maps of
  // similar shapes drift alike); a consistent parameterization must still be better for
  // every pair, and below 5% of sqrt(area) on average: the Princeton benchmark's usual
  // threshold for a correct match (members differ in pose and proportion, and corresponding
  // points between landmarks are only as good as the stretch-minimizing interpolation).
  std::vector<RowMat3d> independent;
  for (const auto& m : meshes) {
    auto u = parameterize_sphere(m, fast_options().constrained.sphere);
    REQUIRE(u.ok());
    independent.push_back(u->map.S);
  }
  for (size_t i = 1; i < c.size(); ++i) {
    Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
    for (size_t k = 0; k < features[0].size(); ++k)
      M += independent[0].row(features[0][k]).transpose() * independent[i].row(features[i][k]);
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
    if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) D(2, 2) = -1;
    const Eigen::Matrix3d R = svd.matrixU() * D * svd.matrixV().transpose();
    independent[i] = (independent[i] * R.transpose()).rowwise().normalized();
  }
  for (size_t i = 0; i < c.size(); ++i)
    for (size_t j = 0; j < c.size(); ++j) {
      if (i == j) continue;
      INFO(c[i].name << " -> " << c[j].name);
      const double consistent = mean_transfer_error(c[i], r->maps[i].map.S, c[j], r->maps[j].map.S);
      const double baseline = mean_transfer_error(c[i], independent[i], c[j], independent[j]);
      CHECK(consistent < 0.05);
      CHECK(consistent < baseline);
    }
}

TEST_CASE("consistent maps without refinement keep the reference's own map", "[param][consistent]") {
  const auto& c = small_collection();
  std::vector<TriMesh> meshes;
  std::vector<std::vector<int>> features;
  split(c, &meshes, &features);
  ConsistentParamOptions o = fast_options();
  o.refine_locations = false;
  o.reference = 1;
  auto r = parameterize_consistent(meshes, features, o);
  REQUIRE(r.ok());
  auto u = parameterize_sphere(meshes[1], o.constrained.sphere);
  REQUIRE(u.ok());
  CHECK(r->maps[1].map.S == u->map.S);
  CHECK(r->maps[1].network.paths == 0);
  CHECK(r->remesh_vertices == 0);
  for (size_t k = 0; k < features[1].size(); ++k) {
    CHECK(r->initial_locations[k] == u->map.S.row(features[1][k]).transpose());
    CHECK(r->final_locations[k] == r->initial_locations[k]);
  }
  for (size_t i = 0; i < c.size(); ++i) {
    test::require_valid_map(c[i].mesh, r->maps[i].map.S);
    for (size_t k = 0; k < features[i].size(); ++k)
      CHECK(angle(r->maps[i].map.S.row(features[i][k]).transpose(), r->initial_locations[k]) < 1e-9);
  }
}

TEST_CASE("the correspondence refinement brings the members closer to the reference's correspondence",
          "[param][consistent][refine]") {
  const auto& c = small_collection();
  std::vector<TriMesh> meshes;
  std::vector<std::vector<int>> features;
  split(c, &meshes, &features);
  ConsistentParamOptions o = fast_options();
  o.refine_locations = false;  // steps 1-2: the refinement works on any consistent maps
  o.refine_correspondence = false;
  auto plain = parameterize_consistent(meshes, features, o);
  o.refine_correspondence = true;
  auto refined = parameterize_consistent(meshes, features, o);
  REQUIRE(plain.ok());
  REQUIRE(refined.ok());
  REQUIRE(refined->refinement.members.size() == c.size());
  CHECK(plain->refinement.members.empty());
  CHECK(refined->maps[0].map.S == plain->maps[0].map.S);  // the reference is the template
  int taken = 0;
  for (size_t i = 1; i < c.size(); ++i) {
    const RefinedMember& m = refined->refinement.members[i];
    INFO(c[i].name << ": " << m.note);
    test::require_valid_map(c[i].mesh, refined->maps[i].map.S);
    for (size_t k = 0; k < features[i].size(); ++k)
      CHECK(refined->maps[i].map.S.row(features[i][k]) == plain->maps[i].map.S.row(features[i][k]));
    CHECK(refined->maps[i].efficiency == Approx(m.efficiency_after).epsilon(1e-12));
    CHECK(m.efficiency_after >= 0.8 * std::min(m.efficiency_before, plain->maps[0].efficiency));
    if (!m.refined) continue;
    ++taken;
    const double before = mean_transfer_error(c[0], plain->maps[0].map.S, c[i], plain->maps[i].map.S);
    const double after = mean_transfer_error(c[0], refined->maps[0].map.S, c[i], refined->maps[i].map.S);
    INFO("error " << before << " -> " << after);
    CHECK(after < before);
  }
  CHECK(taken >= 1);
}

TEST_CASE("a refined map of a mesh with holes is measured with its holes closed: winding +1",
          "[param][consistent]") {
  // The refinement's maps are measured again by replace_refined_map. On the open mesh the
  // winding is undefined and was reported as 0 for every refined member with holes (the
  // ICT heads), beside +1 for the same map before the refinement.
  const TriMesh open = test::sphere_with_holes(2, 3);
  RowMat3d S = open.V.rowwise().normalized();  // the icosphere's own bijective map
  REQUIRE(count_flipped_faces(open.F, S) == 0);
  auto on_open = evaluate_sphere_map(open, S);
  REQUIRE(on_open.ok());
  CHECK(on_open->winding == 0.0);  // the metric's convention for open meshes
  ConstrainedParamResult map;
  const std::vector<int> fv{0, 5};
  const std::vector<Eigen::Vector3d> at{S.row(0).transpose(), S.row(5).transpose()};
  REQUIRE(replace_refined_map(open, fv, at, S, &map).ok());
  CHECK(map.winding == Approx(1.0).margin(1e-9));
  CHECK(map.flipped_faces == 0);
  CHECK(map.max_feature_angle == 0.0);
  // Stretch over the input's own faces: the same as measured on the open mesh.
  CHECK(map.efficiency == Approx(on_open->efficiency).epsilon(1e-9));
  CHECK(map.map.S == S);
}

TEST_CASE("a step-6 map that keeps too little of its step-2 efficiency is found", "[param][consistent]") {
  auto maps = [](std::vector<double> eff) {
    std::vector<ConstrainedParamResult> m(eff.size());
    for (size_t i = 0; i < eff.size(); ++i) m[i].efficiency = eff[i];
    return m;
  };
  // The ICT heads of the fallback's comment: 0.799/0.432/0.770/0.806 to F, 0.819/0.796/
  // 0.795/0.837 to F'; the second collapsed (0.54x), the others kept 0.96-0.98x.
  const auto step2 = maps({0.819, 0.796, 0.795, 0.837});
  CHECK(detail::first_collapsed_map(maps({0.799, 0.432, 0.770, 0.806}), step2, 0.7) == 1);
  CHECK(detail::first_collapsed_map(maps({0.799, 0.760, 0.770, 0.806}), step2, 0.7) == -1);
  // The first of several, and the boundary itself is not a collapse.
  CHECK(detail::first_collapsed_map(maps({0.799, 0.760, 0.3, 0.2}), step2, 0.7) == 2);
  CHECK(detail::first_collapsed_map(maps({0.5, 0.5, 0.5, 0.5}), maps({0.5, 0.5, 0.5, 0.5}), 1.0) == -1);
}

TEST_CASE("a step-6 network that winds round where its step-2 network did not is found", "[param][consistent]") {
  auto maps = [](std::vector<double> ratio) {
    std::vector<ConstrainedParamResult> m(ratio.size());
    for (size_t i = 0; i < ratio.size(); ++i) m[i].network.max_ratio = ratio[i];
    return m;
  };
  // The ICT heads of collapsed_map.h: longest paths 1.17/1.21/2.76/2.47 to F, the reference's
  // step-2 map unconstrained (no network), the others 1.17/1.18/1.22 to F'.
  const auto step2 = maps({0.0, 1.17, 1.18, 1.22});
  CHECK(detail::first_wound_map(maps({1.17, 1.21, 2.76, 2.47}), step2, 2.0, 1.5) == 2);
  // Normal networks (at most 1.25x), and a mesh that wound as much to F' (no gain in falling back).
  CHECK(detail::first_wound_map(maps({1.05, 1.10, 1.13, 1.25}), step2, 2.0, 1.5) == -1);
  CHECK(detail::first_wound_map(maps({1.05, 1.10, 1.13, 2.5}), maps({0.0, 1.1, 1.1, 2.2}), 2.0, 1.5) == -1);
  // The reference (no step-2 network) by the limit alone; the limit itself is not winding.
  CHECK(detail::first_wound_map(maps({2.1, 1.0, 1.0, 1.0}), step2, 2.0, 1.5) == 0);
  CHECK(detail::first_wound_map(maps({2.0, 1.0, 1.0, 1.0}), step2, 2.0, 1.5) == -1);
}

TEST_CASE("consistent maps are the same bits for any thread count", "[param][consistent]") {
  const auto& c = small_collection();
  std::vector<TriMesh> meshes;
  std::vector<std::vector<int>> features;
  split(c, &meshes, &features);
  meshes.resize(2);
  features.resize(2);
  ConsistentParamOptions o = fast_options();
  o.threads = 1;
  auto a = parameterize_consistent(meshes, features, o);
  o.threads = 2;
  auto b = parameterize_consistent(meshes, features, o);
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  for (size_t i = 0; i < meshes.size(); ++i) CHECK(a->maps[i].map.S == b->maps[i].map.S);
  CHECK(a->final_locations == b->final_locations);
}

TEST_CASE("consistent parameterization refuses bad arguments with a clear error", "[param][consistent]") {
  const auto& c = small_collection();
  std::vector<TriMesh> meshes;
  std::vector<std::vector<int>> features;
  split(c, &meshes, &features);
  ConsistentParamOptions o = fast_options();
  {
    auto f = features;
    f[2].pop_back();
    auto r = parameterize_consistent(meshes, f, o);
    REQUIRE_FALSE(r.ok());
    CHECK(r.status().code() == ErrorCode::InvalidArgument);
    CHECK(r.status().message().find("mesh 2") != std::string::npos);
  }
  {
    auto f = features;
    f[1][0] = static_cast<int>(meshes[1].V.rows());
    MeshFailure failure;
    auto r = parameterize_consistent(meshes, f, o, {}, &failure);
    REQUIRE_FALSE(r.ok());
    CHECK(r.status().code() == ErrorCode::InvalidInput);
    CHECK(r.status().message().find("mesh 1") != std::string::npos);
    // The same as a value: which mesh, and why without the label.
    CHECK(failure.mesh == 1);
    CHECK(failure.reason.code() == ErrorCode::InvalidInput);
    CHECK(r.status().message() == "mesh 1: " + failure.reason.message());
  }
  {
    // Two features on one vertex of mesh 1: the constrained stage's error, naming the mesh.
    auto f = features;
    f[1][1] = f[1][0];
    MeshFailure failure;
    auto r = parameterize_consistent(meshes, f, o, {}, &failure);
    REQUIRE_FALSE(r.ok());
    CHECK(r.status().code() == ErrorCode::InvalidInput);
    CHECK(r.status().message().find("mesh 1") != std::string::npos);
    CHECK(failure.mesh == 1);  // found in a parallel job: still the mesh, as a value
    CHECK(r.status().message() == "mesh 1: " + failure.reason.message());
  }
  ConsistentParamOptions bad = o;
  bad.reference = 3;
  CHECK(parameterize_consistent(meshes, features, bad).status().code() == ErrorCode::InvalidArgument);
  bad = o;
  bad.remesh_size = 100;
  CHECK(parameterize_consistent(meshes, features, bad).status().code() == ErrorCode::InvalidArgument);
  CHECK(parameterize_consistent({}, {}, o).status().code() == ErrorCode::InvalidArgument);
  // Cancellation through the progress callback.
  int calls = 0;
  auto r = parameterize_consistent(meshes, features, o, [&](const ProgressEvent&) { return ++calls < 50; });
  REQUIRE_FALSE(r.ok());
  CHECK(r.status().code() == ErrorCode::Cancelled);
}

// ---------------------------------------------------------------------------------------
// Correspondence building blocks

TEST_CASE("closest points agree with brute force", "[param][correspondence]") {
  const TriMesh& m = small_collection()[0].mesh;
  const ClosestPointLocator locator(m);
  std::uint64_t state = 7;
  auto uniform = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) * 0x1.0p-53;
  };
  const Eigen::Vector3d lo = m.V.colwise().minCoeff(), hi = m.V.colwise().maxCoeff();
  for (int t = 0; t < 300; ++t) {
    Eigen::Vector3d q;
    for (int a = 0; a < 3; ++a) q[a] = lo[a] + (hi[a] - lo[a]) * (1.6 * uniform() - 0.3);  // also outside the box
    const SurfacePoint p = locator.closest(q);
    REQUIRE(p.face >= 0);
    CHECK(p.bary.minCoeff() >= 0);
    CHECK(std::abs(p.bary.sum() - 1) < 1e-12);
    double best = std::numeric_limits<double>::infinity();
    for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
      // Dense sampling is not exact; the locator's point must be at least as near as every
      // corner and every face centroid (a strict, failable comparison).
      for (int k = 0; k < 3; ++k) best = std::min(best, (m.V.row(m.F(f, k)).transpose() - q).norm());
      const Eigen::Vector3d centroid = (m.V.row(m.F(f, 0)) + m.V.row(m.F(f, 1)) + m.V.row(m.F(f, 2))).transpose() / 3;
      best = std::min(best, (centroid - q).norm());
    }
    CHECK((surface_position(m, p) - q).norm() <= best + 1e-12);
  }
  // A point on the surface is its own closest point.
  for (int f = 0; f < m.F.rows(); f += 97) {
    SurfacePoint s{f, Eigen::Vector3d(0.2, 0.3, 0.5)};
    const Eigen::Vector3d x = surface_position(m, s);
    CHECK((surface_position(m, locator.closest(x)) - x).norm() < 1e-12);
  }
}

TEST_CASE("transfer through the same map is the identity, and the error of a perfect map is 0",
          "[param][correspondence]") {
  const SampleMesh& s = small_collection()[0];
  auto u = parameterize_sphere(s.mesh, fast_options().constrained.sphere);
  REQUIRE(u.ok());
  std::vector<SurfacePoint> pts;
  std::vector<int> truth;
  for (int v = 0; v < s.mesh.V.rows(); v += 7) {
    pts.push_back(vertex_surface_point(s.mesh, v));
    truth.push_back(v);
  }
  for (int f = 0; f < s.mesh.F.rows(); f += 13) pts.push_back(SurfacePoint{f, Eigen::Vector3d(0.6, 0.3, 0.1)});
  auto moved = transfer_points(s.mesh, u->map.S, pts, s.mesh, u->map.S);
  REQUIRE(moved.ok());
  for (size_t i = 0; i < pts.size(); ++i) {
    CHECK_FALSE((*moved)[i].in_hole);
    CHECK((surface_position(s.mesh, (*moved)[i].point) - surface_position(s.mesh, pts[i])).norm() < 1e-9);
  }
  std::vector<SurfacePoint> predicted;
  for (size_t i = 0; i < truth.size(); ++i) predicted.push_back((*moved)[i].point);
  auto e = correspondence_error(s.mesh, predicted, truth);
  REQUIRE(e.ok());
  CHECK(e->pairs == static_cast<int>(truth.size()));
  CHECK(e->max < 1e-9);
  CHECK(e->under_0025 == 1.0);
  // Every prediction sent to the first vertex instead: errors are the geodesic distances.
  std::vector<SurfacePoint> wrong(truth.size(), vertex_surface_point(s.mesh, 0));
  auto w = correspondence_error(s.mesh, wrong, truth);
  REQUIRE(w.ok());
  CHECK(w->mean > 0.1);
  CHECK(w->max <= 2.0);  // a geodesic is at most about half the perimeter, well below 2 sqrt(area) here
  CHECK_FALSE(correspondence_error(s.mesh, predicted, {}).ok());
  CHECK_FALSE(transfer_points(s.mesh, u->map.S.topRows(10), pts, s.mesh, u->map.S).ok());
}

// The measure is the edge graph's shortest path plus the straight step into the predicted
// point's face, each edge counted once at its length. (shared/tools/evalcorr.py builds its
// graph from every face's three edges with scipy's coo_matrix, whose conversion sums the two
// faces' copies of an edge: twice each length, so its means are up to twice these.)
TEST_CASE("the correspondence error is the edge-graph geodesic over sqrt(area), each edge once",
          "[param][correspondence]") {
  const TriMesh oct = test::octahedron();  // edges sqrt(2), area 8 * sqrt(3)/4 * 2 = 4 sqrt(3)
  const double unit = 1.0 / std::sqrt(4.0 * std::sqrt(3.0));
  // Predicted at +x (vertex 0); truths: itself, a neighbour (+y), the opposite vertex (-x).
  const std::vector<SurfacePoint> at_px(3, vertex_surface_point(oct, 0));
  auto e = correspondence_error(oct, at_px, {0, 2, 1});
  REQUIRE(e.ok());
  CHECK(std::abs(e->max - 2.0 * std::sqrt(2.0) * unit) < 1e-12);  // two edges to the opposite vertex
  CHECK(std::abs(e->mean - (0.0 + std::sqrt(2.0) + 2.0 * std::sqrt(2.0)) * unit / 3.0) < 1e-12);
  CHECK(std::abs(e->median - std::sqrt(2.0) * unit) < 1e-12);
  // A predicted point inside face {0, 2, 4} at its centroid, true partner -x: the shortest of
  // (corner's path + straight step to the centroid); from +y or +z: one edge + the step.
  const SurfacePoint centre{0, Eigen::Vector3d(1.0, 1.0, 1.0) / 3.0};
  auto c = correspondence_error(oct, {centre}, {1});
  REQUIRE(c.ok());
  const double step = (Eigen::Vector3d(0, 1, 0) - Eigen::Vector3d(1, 1, 1) / 3.0).norm();
  CHECK(std::abs(c->mean - (std::sqrt(2.0) + step) * unit) < 1e-12);
}
