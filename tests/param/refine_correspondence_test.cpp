// Correspondence refinement (refine_correspondence.h): a member that is a rigidly moved copy
// of the template, whose map agrees with the template's only at the feature (the rest
// twisted about it), must come back to agreeing everywhere: bijective, feature exact.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <vector>

#include <Eigen/Geometry>

#include "test_meshes.h"
#include "detail/feature_warp.h"
#include "spherekit/consistent_param.h"
#include "spherekit/correspondence.h"
#include "spherekit/metrics.h"
#include "spherekit/refine_correspondence.h"
#include "spherekit/sphere_param.h"

using namespace spherekit;

namespace {

double mesh_area(const TriMesh& m) {
  double a = 0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    a += 0.5 * (m.V.row(m.F(f, 1)) - m.V.row(m.F(f, 0))).cross(m.V.row(m.F(f, 2)) - m.V.row(m.F(f, 0))).norm();
  return a;
}

// A smooth bijection of the sphere fixing the axis a (and its antipode): every circle about
// a turns by amp * sin^2 of its angle from a.
RowMat3d twisted(const RowMat3d& S, const Eigen::Vector3d& a, double amp) {
  RowMat3d out(S.rows(), 3);
  for (Eigen::Index v = 0; v < S.rows(); ++v) {
    const Eigen::Vector3d s = S.row(v).transpose();
    const double c = std::clamp(s.dot(a), -1.0, 1.0);
    const double turn = amp * (1 - c * c);
    // The axis itself stays to the bit (a consistent pair: the feature on the same point).
    const Eigen::Vector3d t = s == a ? s : Eigen::Vector3d(Eigen::AngleAxisd(turn, a) * s);
    out.row(v) = t.transpose();
  }
  return out;
}

// Mean distance (/ sqrt(area)) between where the maps send each template vertex on the copy
// and the copy's own vertex (the truth: the copy has the template's vertex order).
double copy_error(const TriMesh& tmpl, const RowMat3d& St, const TriMesh& copy, const RowMat3d& Sc) {
  std::vector<SurfacePoint> pts;
  for (Eigen::Index v = 0; v < tmpl.V.rows(); ++v) pts.push_back(vertex_surface_point(tmpl, static_cast<int>(v)));
  auto moved = transfer_points(tmpl, St, pts, copy, Sc);
  REQUIRE(moved.ok());
  double sum = 0;
  for (Eigen::Index v = 0; v < tmpl.V.rows(); ++v)
    sum += (surface_position(copy, (*moved)[static_cast<size_t>(v)].point) - copy.V.row(v).transpose()).norm();
  return sum / static_cast<double>(tmpl.V.rows()) / std::sqrt(mesh_area(copy));
}

struct TwistCase {
  TriMesh tmpl, copy;
  RowMat3d St;
  int feature = 0;
};

TwistCase twist_case() {
  TwistCase c;
  c.tmpl = test::random_blob(3, 7);  // no symmetry: only the identity is an isometry
  SphereParamOptions o;
  o.effort = 1;
  o.threads = 1;
  auto r = parameterize_sphere(c.tmpl, o);
  REQUIRE(r.ok());
  c.St = r->map.S;
  // The copy: the same surface turned and moved (an isometry), vertex for vertex.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  c.copy = c.tmpl;
  for (Eigen::Index v = 0; v < c.copy.V.rows(); ++v)
    c.copy.V.row(v) = (R * c.tmpl.V.row(v).transpose() + Eigen::Vector3d(0.3, -1, 2)).transpose();
  // The feature: the vertex farthest along x.
  c.tmpl.V.col(0).maxCoeff(&c.feature);
  return c;
}

// The copy's map twisted by `angle` about the feature, refined against the template with one
// thread; *maps receives {template's map, refined map}.
Result<RefineCorrespondenceResult> refine_twisted_copy(const TwistCase& c, const RowMat3d& S1,
                                                       std::vector<RowMat3d>* maps) {
  std::vector<TriMesh> meshes{c.tmpl, c.copy};
  std::vector<std::vector<int>> features{{c.feature}, {c.feature}};
  *maps = {c.St, S1};
  RefineCorrespondenceOptions o;
  o.threads = 1;
  return refine_correspondence(meshes, features, *maps, o);
}

}  // namespace

TEST_CASE("refinement brings a twisted map of an isometric copy back to the template's", "[refine]") {
  const TwistCase c = twist_case();
  const Eigen::Vector3d axis = c.St.row(c.feature).transpose();
  const RowMat3d S1 = twisted(c.St, axis, 0.5);
  REQUIRE(count_flipped_faces(c.copy.F, S1) == 0);
  const double before = copy_error(c.tmpl, c.St, c.copy, S1);
  REQUIRE(before > 0.02);  // the twist is a real disagreement
  std::vector<RowMat3d> maps;
  auto r = refine_twisted_copy(c, S1, &maps);
  REQUIRE(r.ok());
  const RefinedMember& m = r->members[1];
  INFO(m.note);
  REQUIRE(m.refined);
  CHECK_FALSE(r->members[0].refined);
  CHECK(r->members[0].note == "template");
  // The template's map is untouched; the member's is a bijection with the feature exact.
  CHECK(maps[0] == c.St);
  CHECK(count_flipped_faces(c.copy.F, maps[1]) == 0);
  CHECK(maps[1].row(c.feature) == c.St.row(c.feature));
  auto metrics = evaluate_sphere_map(c.copy, maps[1]);
  REQUIRE(metrics.ok());
  CHECK(metrics->winding == Approx(1.0).margin(1e-9));
  CHECK(metrics->efficiency == Approx(m.efficiency_after).epsilon(1e-12));
  CHECK(m.efficiency_after >= 0.8 * m.efficiency_before);
  CHECK(m.energy_after < m.energy_before);
  // Untwisting an isometric copy crushes no template face (the count is what the energy
  // leaves out).
  CHECK(m.crushed_faces == 0);
  // The maps agree again: most of the twist is gone.
  const double after = copy_error(c.tmpl, c.St, c.copy, maps[1]);
  INFO("error before " << before << ", after " << after);
  CHECK(after < 0.35 * before);
}

TEST_CASE("refinement gives the same bits for any thread count", "[refine]") {
  const TwistCase c = twist_case();
  const Eigen::Vector3d axis = c.St.row(c.feature).transpose();
  std::vector<TriMesh> meshes{c.tmpl, c.copy, c.copy};
  std::vector<std::vector<int>> features{{c.feature}, {c.feature}, {c.feature}};
  std::vector<RowMat3d> one{c.St, twisted(c.St, axis, 0.4), twisted(c.St, axis, -0.3)};
  std::vector<RowMat3d> two = one;
  RefineCorrespondenceOptions o;
  o.rounds = 1;
  o.threads = 1;
  REQUIRE(refine_correspondence(meshes, features, one, o).ok());
  o.threads = 2;
  REQUIRE(refine_correspondence(meshes, features, two, o).ok());
  for (size_t i = 0; i < one.size(); ++i) CHECK(one[i] == two[i]);
}

TEST_CASE("refinement works with holes in the template, and refuses bad arguments", "[refine]") {
  TwistCase c = twist_case();
  // Two holes (one face each, far from the feature) in both the template and the copy: the
  // copy's points in the template's holes get no target; the rest is fitted as before.
  std::vector<int> keep;
  for (int f = 0; f < static_cast<int>(c.tmpl.F.rows()); ++f) {
    bool far = true;
    for (int k = 0; k < 3; ++k) far = far && c.tmpl.F(f, k) != c.feature;
    if (!(far && (f == 40 || f == 400))) keep.push_back(f);
  }
  REQUIRE(keep.size() + 2 == static_cast<size_t>(c.tmpl.F.rows()));
  RowMat3i F(static_cast<Eigen::Index>(keep.size()), 3);
  for (size_t i = 0; i < keep.size(); ++i) F.row(static_cast<Eigen::Index>(i)) = c.tmpl.F.row(keep[i]);
  c.tmpl.F = F;
  c.copy.F = F;
  SphereParamOptions so;
  so.effort = 1;
  so.threads = 1;
  auto r = parameterize_sphere(c.tmpl, so);
  REQUIRE(r.ok());
  const RowMat3d St = r->map.S;
  const RowMat3d S1 = twisted(St, St.row(c.feature).transpose(), 0.5);
  REQUIRE(count_flipped_faces(F, S1) == 0);
  std::vector<TriMesh> meshes{c.tmpl, c.copy};
  std::vector<std::vector<int>> features{{c.feature}, {c.feature}};
  std::vector<RowMat3d> maps{St, S1};
  auto out = refine_correspondence(meshes, features, maps);
  REQUIRE(out.ok());
  INFO(out->members[1].note);
  REQUIRE(out->members[1].refined);
  CHECK(out->members[1].note.empty());  // every round polished: the holes' fans found a place
  CHECK(count_flipped_faces(F, maps[1]) == 0);
  CHECK(maps[1].row(c.feature) == St.row(c.feature));
  const double before = copy_error(c.tmpl, St, c.copy, S1), after = copy_error(c.tmpl, St, c.copy, maps[1]);
  INFO("error before " << before << ", after " << after);
  CHECK(after < 0.35 * before);

  RefineCorrespondenceOptions bad;
  bad.template_mesh = 2;
  const TriMesh holed = c.tmpl;
  auto e = refine_correspondence(meshes, features, maps, bad);
  REQUIRE_FALSE(e.ok());
  CHECK(e.status().code() == ErrorCode::InvalidArgument);
  std::vector<std::vector<int>> out_of_range{{0}, {static_cast<int>(holed.V.rows())}};
  bad.template_mesh = 0;
  bad.damping = 0;
  CHECK(refine_correspondence(meshes, features, maps, bad).status().code() == ErrorCode::InvalidArgument);
  CHECK(refine_correspondence(meshes, out_of_range, maps).status().code() == ErrorCode::InvalidArgument);
  bad.damping = 0.01;
  bad.stretch_passes = -1;
  CHECK(refine_correspondence(meshes, features, maps, bad).status().code() == ErrorCode::InvalidArgument);
  bad.stretch_passes = 3;
  bad.sample_growth = 0;
  CHECK(refine_correspondence(meshes, features, maps, bad).status().code() == ErrorCode::InvalidArgument);
  bad.sample_growth = 2;
  bad.vertices_per_sample = 0;
  CHECK(refine_correspondence(meshes, features, maps, bad).status().code() == ErrorCode::InvalidArgument);
}

// Later rounds flow onto more samples: 256, then twice as many up to max_samples, or as many
// as the member has (every vertex but the feature), or one per vertices_per_sample vertices
// (never fewer than 256); with sample_growth 1 every round takes 256, as collections refined
// before it did. The finer flows agree at least as well.
TEST_CASE("each refinement round flows onto sample_growth times the samples of the last", "[refine]") {
  const TwistCase c = twist_case();
  const RowMat3d S1 = twisted(c.St, c.St.row(c.feature).transpose(), 0.5);
  std::vector<TriMesh> meshes{c.tmpl, c.copy};
  std::vector<std::vector<int>> features{{c.feature}, {c.feature}};
  auto refine = [&](int growth, RefinedMember* rep, int most = 512, int per_sample = 1) {
    std::vector<RowMat3d> maps{c.St, S1};
    RefineCorrespondenceOptions o;
    o.threads = 1;
    o.sample_growth = growth;
    o.max_samples = most;
    o.vertices_per_sample = per_sample;
    auto r = refine_correspondence(meshes, features, maps, o);
    REQUIRE(r.ok());
    *rep = r->members[1];
    REQUIRE(rep->refined);
    return maps[1];
  };
  RefinedMember same, grown, all, sparse;
  const RowMat3d Ss = refine(1, &same), Sg = refine(2, &grown);
  refine(2, &all, 4096);
  refine(2, &sparse, 512, 8);  // the default density: this small member keeps 256
  const int nv = static_cast<int>(c.copy.V.rows());
  REQUIRE(nv - 1 > 512);
  REQUIRE(nv - 1 < 1024);
  CHECK(same.rounds == 3);
  CHECK(grown.rounds == 3);
  CHECK(all.rounds == 3);
  CHECK(same.samples == 256);
  CHECK(grown.samples == 512);
  CHECK(all.samples == nv - 1);
  REQUIRE(nv / 8 < 256);
  CHECK(sparse.samples == 256);
  CHECK(count_flipped_faces(c.copy.F, Sg) == 0);
  CHECK(Sg.row(c.feature) == c.St.row(c.feature));
  const double e_same = copy_error(c.tmpl, c.St, c.copy, Ss), e_grown = copy_error(c.tmpl, c.St, c.copy, Sg);
  INFO("error with 256 samples per round " << e_same << ", growing " << e_grown);
  CHECK(e_grown <= e_same);
}

TEST_CASE("the stretch polish after each flow raises the efficiency and keeps the agreement", "[refine]") {
  const TwistCase c = twist_case();
  const RowMat3d S1 = twisted(c.St, c.St.row(c.feature).transpose(), 0.5);
  const double before = copy_error(c.tmpl, c.St, c.copy, S1);
  std::vector<TriMesh> meshes{c.tmpl, c.copy};
  std::vector<std::vector<int>> features{{c.feature}, {c.feature}};
  auto refine = [&](int passes, RefinedMember* rep) {
    std::vector<RowMat3d> maps{c.St, S1};
    RefineCorrespondenceOptions o;
    o.threads = 1;
    o.stretch_passes = passes;
    o.snap_sweeps = 0;  // the passes alone (the snap alone nearly reaches this fit: see below)
    auto r = refine_correspondence(meshes, features, maps, o);
    REQUIRE(r.ok());
    *rep = r->members[1];
    REQUIRE(rep->refined);
    return maps[1];
  };
  RefinedMember plain, polished;
  const RowMat3d Sf = refine(0, &plain), Sp = refine(3, &polished);
  INFO(polished.note);
  CHECK(polished.note.empty());
  CHECK(count_flipped_faces(c.copy.F, Sp) == 0);
  CHECK(Sp.row(c.feature) == c.St.row(c.feature));
  auto m = evaluate_sphere_map(c.copy, Sp);
  REQUIRE(m.ok());
  CHECK(m->winding == Approx(1.0).margin(1e-9));
  // The flow leaves stretch between its samples that the polish takes out ...
  INFO("efficiency unpolished " << plain.efficiency_after << ", polished " << polished.efficiency_after
                                << ", the template's own " << evaluate_sphere_map(c.tmpl, c.St)->efficiency);
  CHECK(polished.efficiency_after > plain.efficiency_after);
  // ... while the agreement the fit made stays.
  const double e_plain = copy_error(c.tmpl, c.St, c.copy, Sf), e_polished = copy_error(c.tmpl, c.St, c.copy, Sp);
  INFO("error before " << before << ", unpolished " << e_plain << ", polished " << e_polished);
  CHECK(e_polished < 0.35 * before);
  CHECK(e_polished < 1.25 * e_plain);
}

// The snap toward the fitted partners (detail::snap_toward_targets): every vertex that may
// move reaches a target the others leave room for; a target across the vertex's ring is
// approached only as far as its faces stay positive and at least half their size.
TEST_CASE("the snap moves vertices onto their targets without a flip or a sliver", "[refine]") {
  const TriMesh m = test::icosphere(3);
  const RowMat3d S0 = m.V;
  REQUIRE(count_flipped_faces(m.F, S0) == 0);
  // Targets: the map turned by a small angle (a valid map); vertex 0 may not move.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.05, Eigen::Vector3d(1, 2, 2).normalized()).toRotationMatrix();
  RowMat3d T = (S0 * R.transpose()).eval();
  for (Eigen::Index v = 0; v < T.rows(); ++v) T.row(v).normalize();
  std::vector<char> movable(static_cast<size_t>(S0.rows()), 1);
  movable[0] = 0;
  RowMat3d S = S0;
  const int moves = detail::snap_toward_targets(m.F, T, movable, 3, &S);
  CHECK(moves >= S0.rows() - 1);
  CHECK(S.row(0) == S0.row(0));
  CHECK(count_flipped_faces(m.F, S) == 0);
  int reached = 0;
  for (Eigen::Index v = 1; v < S.rows(); ++v) reached += (S.row(v) - T.row(v)).norm() < 1e-15;
  CHECK(reached == S.rows() - 1);
  // One vertex sent across its ring, beyond its farthest neighbour: it moves part of the way
  // or not at all, never through a face.
  const int v = 5;
  int far = -1;
  double best = -1;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int c = 0; c < 3; ++c)
      if (m.F(f, c) == v)
        for (int k = 1; k < 3; ++k) {
          const int u = m.F(f, (c + k) % 3);
          const double d = (S0.row(u) - S0.row(v)).norm();
          if (d > best) best = d, far = u;
        }
  RowMat3d T2 = S0;
  T2.row(v) = (S0.row(v) + 2.0 * (S0.row(far) - S0.row(v))).normalized();
  std::vector<char> only(static_cast<size_t>(S0.rows()), 0);
  only[static_cast<size_t>(v)] = 1;
  for (int sweeps : {1, 3}) {
    RowMat3d S2 = S0;
    CHECK(detail::snap_toward_targets(m.F, T2, only, sweeps, &S2) <= sweeps);
    CHECK(count_flipped_faces(m.F, S2) == 0);
    CHECK(S2.row(v) != S0.row(v));
    CHECK((S2.row(v) - S0.row(v)).norm() < (T2.row(v) - S0.row(v)).norm());
    // Each move keeps every face at least half the size it had.
    for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
      auto vol = [&](const RowMat3d& X) {
        return Eigen::Vector3d(X.row(m.F(f, 0))).dot(Eigen::Vector3d(X.row(m.F(f, 1))).cross(Eigen::Vector3d(X.row(m.F(f, 2)))));
      };
      CHECK(vol(S2) >= std::pow(0.5, sweeps) * vol(S0));
    }
    for (Eigen::Index u = 0; u < S0.rows(); ++u)
      if (u != v) CHECK(S2.row(u) == S0.row(u));
  }
}

// The refinement with and without the snap before the stretch passes: the same twisted copy
// ends nearer the template with it, as bijective and about as efficient.
TEST_CASE("the snap before the stretch passes keeps more of the fit", "[refine]") {
  const TwistCase c = twist_case();
  const RowMat3d S1 = twisted(c.St, c.St.row(c.feature).transpose(), 0.5);
  std::vector<TriMesh> meshes{c.tmpl, c.copy};
  std::vector<std::vector<int>> features{{c.feature}, {c.feature}};
  auto refine = [&](int sweeps, RefinedMember* rep) {
    std::vector<RowMat3d> maps{c.St, S1};
    RefineCorrespondenceOptions o;
    o.threads = 1;
    o.snap_sweeps = sweeps;
    auto r = refine_correspondence(meshes, features, maps, o);
    REQUIRE(r.ok());
    *rep = r->members[1];
    INFO(rep->note);
    REQUIRE(rep->refined);
    return maps[1];
  };
  RefinedMember without, with;
  const RowMat3d Sw = refine(0, &without), Ss = refine(3, &with);
  CHECK(without.snap_moves == 0);
  CHECK(with.snap_moves > 0);
  CHECK(count_flipped_faces(c.copy.F, Ss) == 0);
  CHECK(Ss.row(c.feature) == c.St.row(c.feature));
  const double e_without = copy_error(c.tmpl, c.St, c.copy, Sw), e_with = copy_error(c.tmpl, c.St, c.copy, Ss);
  INFO("error without the snap " << e_without << ", with " << e_with << "; efficiency " << without.efficiency_after
                                 << " -> " << with.efficiency_after);
  CHECK(e_with < e_without);
  CHECK(with.efficiency_after >= 0.95 * without.efficiency_after);
  RefineCorrespondenceOptions bad;
  bad.snap_sweeps = -1;
  std::vector<RowMat3d> maps{c.St, S1};
  auto r = refine_correspondence(meshes, features, maps, bad);
  REQUIRE_FALSE(r.ok());
  CHECK(r.status().code() == ErrorCode::InvalidArgument);
}

// A round must keep 0.8x the lower of the member's own unconstrained efficiency, where given,
// and the template's: a long member (its maps less efficient than a round blob's) whose own is
// given as the blob's cannot keep 0.8x of it, and is left as it was; unknown, its starting map
// sets the bar and the round is taken.
TEST_CASE("a refined map keeps 0.8x of the member's own unconstrained efficiency where it is given", "[refine]") {
  const TriMesh blob = test::random_blob(3, 7), longm = test::elongated(3, 4.0);
  SphereParamOptions so;
  so.effort = 1;
  so.threads = 1;
  auto sb = parameterize_sphere(blob, so), sl = parameterize_sphere(longm, so);
  REQUIRE(sb.ok());
  REQUIRE(sl.ok());
  int fb = 0, fl = 0;
  blob.V.col(0).maxCoeff(&fb);
  longm.V.col(0).maxCoeff(&fl);
  // The long member's map turned so that its feature sits on the blob's (a consistent pair).
  const Eigen::Vector3d from = sl->map.S.row(fl).transpose(), to = sb->map.S.row(fb).transpose();
  const Eigen::Matrix3d R = Eigen::Quaterniond::FromTwoVectors(from, to).toRotationMatrix();
  RowMat3d S1 = (sl->map.S * R.transpose()).eval();
  S1.row(fl) = to.transpose();
  REQUIRE(count_flipped_faces(longm.F, S1) == 0);
  const double blob_eff = evaluate_sphere_map(blob, sb->map.S)->efficiency;
  const double long_eff = evaluate_sphere_map(longm, S1)->efficiency;
  INFO("efficiency: blob " << blob_eff << ", long member " << long_eff);
  REQUIRE(long_eff < 0.8 * blob_eff);
  std::vector<TriMesh> meshes{blob, longm};
  std::vector<std::vector<int>> features{{fb}, {fl}};
  for (bool given : {false, true}) {
    std::vector<RowMat3d> maps{sb->map.S, S1};
    RefineCorrespondenceOptions o;
    o.threads = 1;
    o.rounds = 1;
    if (given) o.own_efficiency = {0.0, blob_eff};
    auto r = refine_correspondence(meshes, features, maps, o);
    REQUIRE(r.ok());
    const RefinedMember& m = r->members[1];
    INFO("given " << given << ": " << m.note);
    if (given) {
      CHECK_FALSE(m.refined);
      CHECK(m.note.find("not taken") != std::string::npos);
      CHECK(maps[1] == S1);
    } else {
      CHECK(m.refined);
      CHECK(m.efficiency_after >= 0.8 * long_eff);
    }
  }
}

namespace {

// The same surface with other connectivity: a set of non-adjacent edge flips of nearly flat
// edges (the surface moves by far less than an edge), vertices renumbered, the whole moved
// rigidly. The intrinsic metric is the template's up to the flipped chords; vertex v of the
// template is vertex perm[v] of the copy (the ground truth).
TriMesh flipped_copy(const TriMesh& m, std::uint64_t seed, std::vector<int>* perm, int* flips) {
  RowMat3i F = m.F;
  std::map<std::pair<int, int>, std::vector<int>> edge_faces;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      edge_faces[{std::min(a, b), std::max(a, b)}].push_back(static_cast<int>(f));
    }
  std::set<std::pair<int, int>> edges;
  for (const auto& [e, fs] : edge_faces) edges.insert(e);
  std::vector<char> touched(static_cast<size_t>(m.V.rows()), 0);
  std::mt19937_64 rng(seed);
  *flips = 0;
  for (const auto& [e, fs] : edge_faces) {
    if (fs.size() != 2 || rng() % 2) continue;
    const int f0 = fs[0], f1 = fs[1];
    auto opposite = [&](int f) {
      for (int k = 0; k < 3; ++k)
        if (F(f, k) != e.first && F(f, k) != e.second) return F(f, k);
      return -1;
    };
    const int c = opposite(f0), d = opposite(f1);
    const int a = e.first, b = e.second;
    if (touched[static_cast<size_t>(a)] || touched[static_cast<size_t>(b)] || touched[static_cast<size_t>(c)] ||
        touched[static_cast<size_t>(d)] || edges.count({std::min(c, d), std::max(c, d)}))
      continue;
    const Eigen::Vector3d n0 = (m.V.row(F(f0, 1)) - m.V.row(F(f0, 0))).cross(m.V.row(F(f0, 2)) - m.V.row(F(f0, 0))).normalized();
    const Eigen::Vector3d n1 = (m.V.row(F(f1, 1)) - m.V.row(F(f1, 0))).cross(m.V.row(F(f1, 2)) - m.V.row(F(f1, 0))).normalized();
    if (n0.dot(n1) < 0.995) continue;  // nearly flat: the flip barely moves the surface
    // f0 = (a, b, c) in some rotation with a -> b its edge direction, or (b, a, c).
    int p = a, q = b;
    for (int k = 0; k < 3; ++k)
      if (F(f0, k) == b && F(f0, (k + 1) % 3) == a) p = b, q = a;
    F.row(f0) << p, d, c;  // c -> p -> d and d -> q -> c keep the orientation
    F.row(f1) << q, c, d;
    for (int v : {a, b, c, d}) touched[static_cast<size_t>(v)] = 1;
    ++*flips;
  }
  perm->resize(static_cast<size_t>(m.V.rows()));
  std::iota(perm->begin(), perm->end(), 0);
  std::shuffle(perm->begin(), perm->end(), rng);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(1.1, Eigen::Vector3d(-2, 1, 0.5).normalized()).toRotationMatrix();
  TriMesh out;
  out.V.resize(m.V.rows(), 3);
  for (Eigen::Index v = 0; v < m.V.rows(); ++v)
    out.V.row((*perm)[static_cast<size_t>(v)]) = (R * m.V.row(v).transpose() + Eigen::Vector3d(1, 2, -0.5)).transpose();
  out.F.resize(F.rows(), 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) out.F(f, k) = (*perm)[static_cast<size_t>(F(f, k))];
  return out;
}

}  // namespace

TEST_CASE("two isometric copies with different connectivity correspond after refinement", "[refine][consistent]") {
  const TriMesh a = test::random_blob(4, 11);
  std::vector<int> perm;
  int flips = 0;
  const TriMesh b = flipped_copy(a, 5, &perm, &flips);
  REQUIRE(flips > a.F.rows() / 20);  // really other connectivity
  // Four features: the extremes along x and y of the template, the same vertices on the copy.
  std::vector<int> fa;
  for (int axis = 0; axis < 2; ++axis) {
    int lo = 0, hi = 0;
    a.V.col(axis).minCoeff(&lo);
    a.V.col(axis).maxCoeff(&hi);
    fa.push_back(lo);
    fa.push_back(hi);
  }
  std::vector<int> fb;
  for (int v : fa) fb.push_back(perm[static_cast<size_t>(v)]);
  auto error = [&](const ConsistentParamResult& r) {
    std::vector<SurfacePoint> pts;
    for (Eigen::Index v = 0; v < a.V.rows(); ++v) pts.push_back(vertex_surface_point(a, static_cast<int>(v)));
    auto moved = transfer_points(a, r.maps[0].map.S, pts, b, r.maps[1].map.S);
    REQUIRE(moved.ok());
    double sum = 0;
    for (Eigen::Index v = 0; v < a.V.rows(); ++v)
      sum += (surface_position(b, (*moved)[static_cast<size_t>(v)].point) - b.V.row(perm[static_cast<size_t>(v)]).transpose()).norm();
    return sum / static_cast<double>(a.V.rows()) / std::sqrt(mesh_area(b));
  };
  ConsistentParamOptions o;
  o.threads = 2;
  o.refine_correspondence = false;
  auto plain = parameterize_consistent({a, b}, {fa, fb}, o);
  REQUIRE(plain.ok());
  o.refine_correspondence = true;
  auto refined = parameterize_consistent({a, b}, {fa, fb}, o);
  REQUIRE(refined.ok());
  INFO(refined->refinement.members[1].note);
  REQUIRE(refined->refinement.members[1].refined);
  const double before = error(*plain), after = error(*refined);
  INFO("mean error / sqrt(area): without refinement " << before << ", with " << after);
  CHECK(after < 0.01);
  CHECK(before > 3 * after);
  CHECK(refined->maps[1].flipped_faces == 0);
  for (size_t k = 0; k < fb.size(); ++k)
    CHECK(refined->maps[1].map.S.row(fb[k]) == refined->maps[0].map.S.row(fa[k]));
}

TEST_CASE("a flow that stalls is relaxed and goes on: the refined map stays bijective and agrees better",
          "[refine]") {
  // A twist of 1.5 rad about the feature: the flow onto the fitted targets squeezes slivers
  // it cannot carry however small the step, and one stretch pass with the features and
  // samples held spreads them out (refine_correspondence.cpp). Whatever the remedy, the
  // result must be a bijection with the feature exact, and closer to the template's.
  const TwistCase c = twist_case();
  const Eigen::Vector3d axis = c.St.row(c.feature).transpose();
  const RowMat3d S1 = twisted(c.St, axis, 1.5);
  REQUIRE(count_flipped_faces(c.copy.F, S1) == 0);
  const double before = copy_error(c.tmpl, c.St, c.copy, S1);
  std::vector<RowMat3d> maps;
  auto r = refine_twisted_copy(c, S1, &maps);
  REQUIRE(r.ok());
  const RefinedMember& m = r->members[1];
  INFO(m.note);
  REQUIRE(m.refined);
  // Measured here: one relaxation (libm's per-CPU variants could let another machine's flow
  // pass without one; then only the outcome is checked).
  if (m.flow_relaxations == 0) WARN("the flow did not stall on this machine");
  CHECK(count_flipped_faces(c.copy.F, maps[1]) == 0);
  CHECK(maps[1].row(c.feature) == c.St.row(c.feature));
  CHECK(m.efficiency_after >= 0.8 * m.efficiency_before);
  const double after = copy_error(c.tmpl, c.St, c.copy, maps[1]);
  INFO("error before " << before << ", after " << after);
  CHECK(after < 0.7 * before);
}
