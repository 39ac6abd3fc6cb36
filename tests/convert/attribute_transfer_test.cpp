// Attribute transfer through the common sphere (paper Fig. 6): colour round trips A -> B -> A
// within a proven interpolation bound, identity on one map, texture charts kept apart at
// seams, and the object-space normal map.
#include "spherekit/convert/attribute_transfer.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "collection_fixture.h"
#include "spherekit/geometry_image.h"

using namespace spherekit;
using namespace spherekit::convert;

namespace {

/// Circumradius of a chord triangle of a sphere map. A point q of a chord triangle lies in
/// the plane at distance sqrt(1 - rho^2) from the origin (rho = the circumradius: the plane
/// cuts the unit sphere in the circumcircle), so its central projection p = q/|q| is at most
/// 1 - |q| <= 1 - sqrt(1 - rho^2) <= rho^2 away from it.
double circumradius(const TriMesh& m, const RowMat3d& S, int f) {
  const Eigen::Vector3d a = S.row(m.F(f, 0)), b = S.row(m.F(f, 1)), c = S.row(m.F(f, 2));
  const double la = (b - c).norm(), lb = (c - a).norm(), lc = (a - b).norm();
  return la * lb * lc / (2 * (b - a).cross(c - a).norm());
}

/// The round trip A -> B -> A at vertex v of A uses B's face containing S_A(v) and, for each
/// of its corners w, A's face containing S_B(w) (located here with SphereLocator, the
/// geometry_image.h locator the transfer builds on).
struct Support {
  int b_face = -1;
  std::vector<int> a_faces;
};
Support round_trip_support(const RowMat3d& SA, const SphereLocator& in_a, const TriMesh& B, const RowMat3d& SB,
                           const SphereLocator& in_b, Eigen::Index v) {
  Support s;
  s.b_face = in_b.locate(SA.row(v).transpose()).face;
  for (int k = 0; k < 3; ++k) s.a_faces.push_back(in_a.locate(SB.row(B.F(s.b_face, k)).transpose()).face);
  return s;
}

}  // namespace

TEST_CASE("colours A -> B -> A return the original within the interpolation error", "[convert][transfer]") {
  const auto& c = spherekit::test::mapped_sample_collection();
  // Members 0 and 2 are closed: every vertex of one lies in a face of the other's map (a hole
  // would send a vertex to the nearest face instead, outside any interpolation bound).
  const TriMesh& A = c.members[0].mesh;
  const TriMesh& B = c.members[2].mesh;
  REQUIRE(c.members[0].boundary_loops == 0);
  REQUIRE(c.members[2].boundary_loops == 0);
  const RowMat3d& SA = c.maps[0];
  const RowMat3d& SB = c.maps[2];

  const SphereLocator in_a(A.F, SA), in_b(B.F, SB);

  SECTION("colours affine in the sphere point: the round trip error has a closed-form bound") {
    // c(v) = M S_A(v) + b. Interpolating an affine function over a chord triangle gives its
    // value at the chord point q instead of the sphere point p: error <= ||M|| |q - p| <=
    // ||M|| rho^2 (rho of the triangle used). The second step interpolates values that carry
    // that error (a convex combination keeps the largest) at a chord point of B's face:
    //   |error at v| <= ||M|| (max over the three A faces rho_A^2 + rho_B^2).
    Eigen::Matrix3d M;
    M << 0.3, -0.1, 0.05, 0.1, 0.25, -0.2, -0.05, 0.15, 0.3;
    const Eigen::RowVector3d b(0.5, 0.5, 0.5);
    const RowMatXd colors = (SA * M.transpose()).rowwise() + b;
    auto there = transfer_vertex_attributes(A, SA, colors, B, SB);
    REQUIRE(there.ok());
    CHECK(there->vertices_in_holes == 0);
    auto back = transfer_vertex_attributes(B, SB, there->values, A, SA);
    REQUIRE(back.ok());
    CHECK(back->vertices_in_holes == 0);
    const double norm_m = M.operatorNorm();
    int violations = 0;
    double worst_ratio = 0, max_err = 0;
    for (Eigen::Index v = 0; v < A.V.rows(); ++v) {
      const Support sup = round_trip_support(SA, in_a, B, SB, in_b, v);
      double rho_a = 0;
      for (int f : sup.a_faces) rho_a = std::max(rho_a, circumradius(A, SA, f));
      const double rho_b = circumradius(B, SB, sup.b_face);
      const double bound = norm_m * (rho_a * rho_a + rho_b * rho_b);
      const double err = (back->values.row(v) - colors.row(v)).norm();
      violations += err > bound * (1 + 1e-9) + 1e-15;
      worst_ratio = std::max(worst_ratio, err / bound);
      max_err = std::max(max_err, err);
    }
    INFO("largest error / bound " << worst_ratio << ", largest error " << max_err);
    CHECK(violations == 0);
    CHECK(max_err > 0);  // a real round trip, not a copy
  }

  SECTION("colours from positions: a convex combination of the colours it should use") {
    // The round trip at v is a convex combination of the colours at the corners of the A
    // faces of its support; its error is at most their largest difference from c(v).
    const Eigen::RowVector3d lo = A.V.colwise().minCoeff(), hi = A.V.colwise().maxCoeff();
    const RowMatXd colors = (A.V.rowwise() - lo).array().rowwise() / (hi - lo).array();
    auto there = transfer_vertex_attributes(A, SA, colors, B, SB);
    REQUIRE(there.ok());
    auto back = transfer_vertex_attributes(B, SB, there->values, A, SA);
    REQUIRE(back.ok());
    int violations = 0;
    double err2 = 0, local2 = 0;
    for (Eigen::Index v = 0; v < A.V.rows(); ++v) {
      const Support sup = round_trip_support(SA, in_a, B, SB, in_b, v);
      double local = 0;
      for (int f : sup.a_faces)
        for (int k = 0; k < 3; ++k) local = std::max(local, (colors.row(A.F(f, k)) - colors.row(v)).norm());
      const double e = (back->values.row(v) - colors.row(v)).norm();
      violations += e > local + 1e-12;
      err2 += e * e;
      local2 += local * local;
    }
    CHECK(violations == 0);
    // On average well inside it: the weights favour the corners nearest to S_A(v) (measured:
    // about a tenth on the samples).
    INFO("RMS error " << std::sqrt(err2 / A.V.rows()) << ", RMS bound " << std::sqrt(local2 / A.V.rows()));
    CHECK(err2 < 0.04 * local2);  // RMS error below a fifth of the RMS bound
  }
}

TEST_CASE("transfer onto the same map is the identity, and bad shapes are refused", "[convert][transfer]") {
  const auto& c = spherekit::test::mapped_sample_collection();
  const TriMesh& A = c.members[1].mesh;  // the one with a hole: its own vertices are never in it
  const RowMat3d& SA = c.maps[1];
  RowMatXd values(A.V.rows(), 2);
  for (Eigen::Index v = 0; v < A.V.rows(); ++v) values.row(v) << std::sin(3.0 * static_cast<double>(v)), static_cast<double>(v % 7);
  auto same = transfer_vertex_attributes(A, SA, values, A, SA);
  REQUIRE(same.ok());
  CHECK(same->vertices_in_holes == 0);
  CHECK((same->values - values).cwiseAbs().maxCoeff() < 1e-9);

  CHECK(transfer_vertex_attributes(A, SA, values.topRows(3), A, SA).status().code() == ErrorCode::InvalidInput);
  CHECK(transfer_vertex_attributes(A, SA.topRows(5), values, A, SA).status().code() == ErrorCode::InvalidInput);
  RowMatXd bad = values;
  bad(3, 1) = std::nan("");
  CHECK(transfer_vertex_attributes(A, SA, bad, A, SA).status().code() == ErrorCode::InvalidInput);
}

TEST_CASE("texture coordinates keep each target face inside one chart", "[convert][transfer]") {
  const auto& c = spherekit::test::mapped_sample_collection();
  const TriMesh& A = c.members[0].mesh;
  const RowMat3d& SA = c.maps[0];
  // A two-chart atlas: faces whose centroid has z > centre go to the left half of the texture
  // (u < 0.5), the others to the right half; vertices on the cut get one coordinate per chart.
  const double zmid = 0.5 * (A.V.col(2).minCoeff() + A.V.col(2).maxCoeff());
  const Eigen::RowVector3d lo = A.V.colwise().minCoeff(), hi = A.V.colwise().maxCoeff();
  RowMat2d UV(2 * A.V.rows(), 2);
  for (Eigen::Index v = 0; v < A.V.rows(); ++v) {
    const double x = (A.V(v, 0) - lo(0)) / (hi(0) - lo(0)), y = (A.V(v, 1) - lo(1)) / (hi(1) - lo(1));
    UV.row(v) << 0.05 + 0.4 * x, 0.05 + 0.9 * y;
    UV.row(A.V.rows() + v) << 0.55 + 0.4 * x, 0.05 + 0.9 * y;
  }
  RowMat3i FT(A.F.rows(), 3);
  std::vector<int> chart_of(static_cast<std::size_t>(A.F.rows()));
  for (Eigen::Index f = 0; f < A.F.rows(); ++f) {
    const double z = (A.V(A.F(f, 0), 2) + A.V(A.F(f, 1), 2) + A.V(A.F(f, 2), 2)) / 3;
    chart_of[static_cast<std::size_t>(f)] = z > zmid ? 0 : 1;
    for (int k = 0; k < 3; ++k) FT(f, k) = A.F(f, k) + (z > zmid ? 0 : static_cast<int>(A.V.rows()));
  }

  SECTION("onto itself: every corner gets its own face's coordinate") {
    auto r = transfer_texture_coordinates(A, SA, UV, FT, A, SA);
    REQUIRE(r.ok());
    CHECK(r->charts == 2);
    CHECK(r->seam_faces > 0);  // the faces along the cut needed their chart's coordinate
    double worst = 0;
    for (Eigen::Index f = 0; f < A.F.rows(); ++f)
      for (int k = 0; k < 3; ++k) worst = std::max(worst, (r->UV.row(r->FT(f, k)) - UV.row(FT(f, k))).norm());
    CHECK(worst < 1e-9);
  }
  SECTION("onto another member: no face spans both halves of the atlas") {
    const TriMesh& B = c.members[2].mesh;
    auto r = transfer_texture_coordinates(A, SA, UV, FT, B, c.maps[2]);
    REQUIRE(r.ok());
    REQUIRE(r->FT.rows() == B.F.rows());
    int straddling = 0, left = 0, right = 0;
    for (Eigen::Index f = 0; f < B.F.rows(); ++f) {
      double umin = 1e9, umax = -1e9;
      for (int k = 0; k < 3; ++k) {
        umin = std::min(umin, r->UV(r->FT(f, k), 0));
        umax = std::max(umax, r->UV(r->FT(f, k), 0));
      }
      // A face extrapolated across the cut may reach a little past its half, never across.
      straddling += umin < 0.5 - 0.1 && umax > 0.5 + 0.1;
      left += umax < 0.5;
      right += umin > 0.5;
    }
    CHECK(straddling == 0);
    CHECK(left > B.F.rows() / 10);
    CHECK(right > B.F.rows() / 10);
  }
}

TEST_CASE("normals: transferred unit normals and the object-space normal map", "[convert][transfer]") {
  const auto& c = spherekit::test::mapped_sample_collection();
  const TriMesh& A = c.members[0].mesh;
  const TriMesh& B = c.members[2].mesh;
  const RowMat3d NA = vertex_normals(A);
  CHECK((NA.rowwise().norm().array() - 1).abs().maxCoeff() < 1e-12);
  // A quarter turn about z: the transferred normals are the rotated ones.
  Eigen::Matrix3d R;
  R << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  auto plain = transfer_vertex_normals(A, c.maps[0], NA, B, c.maps[2]);
  auto turned = transfer_vertex_normals(A, c.maps[0], NA, B, c.maps[2], R);
  REQUIRE(plain.ok());
  REQUIRE(turned.ok());
  CHECK((plain->values.rowwise().norm().array() - 1).abs().maxCoeff() < 1e-12);
  CHECK((turned->values - plain->values * R.transpose()).cwiseAbs().maxCoeff() < 1e-12);
  // Corresponding points of two similar shapes in one pose have similar normals.
  const RowMat3d NB = vertex_normals(B);
  double agree = 0;
  for (Eigen::Index v = 0; v < B.V.rows(); ++v) agree += plain->values.row(v).dot(NB.row(v)) > 0.5;
  CHECK(agree > 0.8 * static_cast<double>(B.V.rows()));

  auto image = sample_geometry_image(A, c.maps[0], 33);
  REQUIRE(image.ok());
  auto map = bake_normal_map(image.value(), R);
  REQUIRE(map.ok());
  REQUIRE(map->width == 33);
  REQUIRE(map->channels == 3);
  double worst = 0;
  for (int i = 0; i < 33; ++i)
    for (int j = 0; j < 33; ++j) {
      const Eigen::Vector3d n = (R * image->normal(i, j).cast<double>()).normalized();
      worst = std::max(worst, (decode_normal_pixel(map->at(j, i)) - n).norm());
    }
  // 8 bits: each component within 0.5/127.5 before renormalizing, so the vector within
  // sqrt(3) * 0.5/127.5 = 0.0068, and renormalizing at most doubles that.
  CHECK(worst < 0.014);
  // Folded border pairs (geometry_image.h) hold the same normal, hence the same pixel.
  for (int s = 0; s < 33; ++s) {
    CHECK(std::equal(map->at(s, 0), map->at(s, 0) + 3, map->at(32 - s, 0)));
    CHECK(std::equal(map->at(0, s), map->at(0, s) + 3, map->at(0, 32 - s)));
  }
  GeometryImage broken = image.value();
  broken.normals.pop_back();
  CHECK(bake_normal_map(broken).status().code() == ErrorCode::InvalidArgument);
}
