// Correspondence refinement (refine_correspondence.h): a member that is a rigidly moved copy
// of the template, whose map agrees with the template's only at the feature (the rest
// twisted about it), must come back to agreeing everywhere: bijective, feature exact.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "test_meshes.h"
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

}  // namespace

TEST_CASE("refinement brings a twisted map of an isometric copy back to the template's", "[refine]") {
  const TwistCase c = twist_case();
  const Eigen::Vector3d axis = c.St.row(c.feature).transpose();
  const RowMat3d S1 = twisted(c.St, axis, 0.5);
  REQUIRE(count_flipped_faces(c.copy.F, S1) == 0);
  const double before = copy_error(c.tmpl, c.St, c.copy, S1);
  REQUIRE(before > 0.02);  // the twist is a real disagreement

  std::vector<TriMesh> meshes{c.tmpl, c.copy};
  std::vector<std::vector<int>> features{{c.feature}, {c.feature}};
  std::vector<RowMat3d> maps{c.St, S1};
  RefineCorrespondenceOptions o;
  o.threads = 1;
  auto r = refine_correspondence(meshes, features, maps, o);
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
}
