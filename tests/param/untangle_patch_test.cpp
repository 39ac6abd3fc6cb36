// Patch untangling of spherical maps (detail/untangle_patch.h): folds that no single vertex
// move repairs come out with every face positive by the exact predicate, features and
// vertices outside the patch stay where they were.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "detail/untangle_patch.h"
#include "spherekit/predicates.h"
#include "test_meshes.h"

using namespace spherekit;

namespace {

using test::icosphere;

struct SoupForUntangle {
  std::vector<std::array<int, 3>> F;
  std::vector<std::vector<int>> vf;
  std::vector<Eigen::Vector3d> X;
  explicit SoupForUntangle(const TriMesh& m) {
    vf.resize(static_cast<size_t>(m.V.rows()));
    for (int f = 0; f < m.F.rows(); ++f) {
      F.push_back({m.F(f, 0), m.F(f, 1), m.F(f, 2)});
      for (int c = 0; c < 3; ++c) vf[static_cast<size_t>(m.F(f, c))].push_back(f);
    }
    for (int v = 0; v < m.V.rows(); ++v) X.push_back(m.V.row(v).transpose());
  }
  std::vector<int> flipped(const RowMat3d& S) const {
    std::vector<int> out;
    for (size_t f = 0; f < F.size(); ++f)
      if (orient3d_origin(S.row(F[f][0]).data(), S.row(F[f][1]).data(), S.row(F[f][2]).data()) <= 0)
        out.push_back(static_cast<int>(f));
    return out;
  }
};

// The vertices within `radius` radians of direction d on the unit sphere map S.
std::vector<int> cap_vertices(const RowMat3d& S, const Eigen::Vector3d& d, double radius) {
  std::vector<int> out;
  for (int v = 0; v < S.rows(); ++v)
    if (std::acos(std::clamp(S.row(v).dot(d), -1.0, 1.0)) < radius) out.push_back(v);
  return out;
}

// Mirrors the points of a cap across the plane through its axis d and the direction t: every
// face inside comes back inverted and every inside vertex's ring turns clockwise, so its
// kernel is empty and one-vertex-at-a-time repair cannot start.
void fold_cap(RowMat3d* S, const Eigen::Vector3d& d, double radius) {
  Eigen::Vector3d t = d.cross(Eigen::Vector3d(0.6, 0.8, 0.0)).normalized();
  for (int v : cap_vertices(*S, d, radius)) {
    Eigen::Vector3d p = S->row(v).transpose();
    S->row(v) = (p - 2 * p.dot(t) * t).normalized().transpose();
  }
}

}  // namespace

TEST_CASE("untangle_patch undoes a fold that inverts dozens of faces", "[untangle]") {
  TriMesh m = icosphere(4);
  SoupForUntangle soup(m);
  RowMat3d S = m.V.rowwise().normalized();
  const RowMat3d before = S;
  const Eigen::Vector3d d = Eigen::Vector3d(0.3, -0.2, 0.9).normalized();
  fold_cap(&S, d, 0.35);
  std::vector<int> bad = soup.flipped(S);
  REQUIRE(bad.size() >= 20);

  std::vector<char> fixed(static_cast<size_t>(m.V.rows()), 0);
  // A feature inside the fold stays where it is.
  const int feature = cap_vertices(S, d, 0.1).front();
  fixed[static_cast<size_t>(feature)] = 1;
  const Eigen::RowVector3d feature_at = S.row(feature);

  detail::PatchMesh pm{&soup.F, &soup.vf};
  detail::UntanglePatchStats st;
  bool ok = false;
  for (int rings : {2, 4, 8})
    if ((ok = detail::untangle_patch(pm, soup.X, fixed, bad, rings, &S, &st))) break;
  REQUIRE(ok);
  CHECK(soup.flipped(S).empty());
  CHECK(S.row(feature) == feature_at);
  // Only vertices near the fold moved, and they stay on the unit sphere.
  for (int v = 0; v < S.rows(); ++v) {
    CHECK(std::abs(S.row(v).norm() - 1) < 1e-12);
    if (std::acos(std::clamp(before.row(v).dot(d), -1.0, 1.0)) > 1.2) CHECK(S.row(v) == before.row(v));
  }
  CHECK(st.free_vertices > 0);
}

TEST_CASE("untangle_patch leaves the map unchanged when it cannot succeed", "[untangle]") {
  TriMesh m = icosphere(3);
  SoupForUntangle soup(m);
  RowMat3d S = m.V.rowwise().normalized();
  const Eigen::Vector3d d = Eigen::Vector3d::UnitZ();
  fold_cap(&S, d, 0.5);
  std::vector<int> bad = soup.flipped(S);
  REQUIRE(!bad.empty());
  const RowMat3d folded = S;
  detail::PatchMesh pm{&soup.F, &soup.vf};

  SECTION("every vertex of the patch is fixed") {
    std::vector<char> fixed(static_cast<size_t>(m.V.rows()), 1);
    CHECK_FALSE(detail::untangle_patch(pm, soup.X, fixed, bad, 2, &S));
  }
  SECTION("the patch is larger than a hemisphere cap") {
    std::vector<char> fixed(static_cast<size_t>(m.V.rows()), 0);
    CHECK_FALSE(detail::untangle_patch(pm, soup.X, fixed, bad, 40, &S));
  }
  SECTION("the fixed vertices force an inverted face") {
    // Fix every vertex of the fold: an inverted face with three fixed corners stays.
    std::vector<char> fixed(static_cast<size_t>(m.V.rows()), 0);
    for (int f : bad)
      for (int v : soup.F[static_cast<size_t>(f)]) fixed[static_cast<size_t>(v)] = 1;
    CHECK_FALSE(detail::untangle_patch(pm, soup.X, fixed, bad, 3, &S));
  }
  CHECK(S == folded);
}

TEST_CASE("untangle_patch is deterministic", "[untangle]") {
  TriMesh m = icosphere(3);
  SoupForUntangle soup(m);
  RowMat3d S = m.V.rowwise().normalized();
  fold_cap(&S, Eigen::Vector3d::UnitX(), 0.4);
  std::vector<int> bad = soup.flipped(S);
  REQUIRE(!bad.empty());
  std::vector<char> fixed(static_cast<size_t>(m.V.rows()), 0);
  detail::PatchMesh pm{&soup.F, &soup.vf};
  RowMat3d A = S, B = S;
  REQUIRE(detail::untangle_patch(pm, soup.X, fixed, bad, 4, &A));
  REQUIRE(detail::untangle_patch(pm, soup.X, fixed, bad, 4, &B));
  CHECK(A == B);
}

TEST_CASE("grow_rings: the vertices within k face rings, sorted and unique, against breadth-first search", "[untangle]") {
  const TriMesh m = icosphere(3);
  SoupForUntangle soup(m);
  const detail::PatchMesh mesh{&soup.F, &soup.vf};
  // Face-ring distance from the seeds by breadth-first search over the faces' corners.
  auto reference = [&](const std::vector<int>& seeds, int rings) {
    std::vector<int> depth(soup.vf.size(), -1), queue;
    for (int s : seeds)
      if (depth[static_cast<size_t>(s)] < 0) depth[static_cast<size_t>(s)] = 0, queue.push_back(s);
    for (size_t q = 0; q < queue.size(); ++q) {
      const int v = queue[q];
      if (depth[static_cast<size_t>(v)] == rings) continue;
      for (int f : soup.vf[static_cast<size_t>(v)])
        for (int w : soup.F[static_cast<size_t>(f)])
          if (depth[static_cast<size_t>(w)] < 0) depth[static_cast<size_t>(w)] = depth[static_cast<size_t>(v)] + 1, queue.push_back(w);
    }
    std::vector<int> out;
    for (size_t v = 0; v < depth.size(); ++v)
      if (depth[v] >= 0) out.push_back(static_cast<int>(v));
    return out;
  };
  const std::vector<std::vector<int>> seeds = {{5}, {300, 7, 300, 12}, {0, 641, 320}};
  for (const auto& s : seeds)
    for (int rings : {0, 1, 2, 5, 40}) {
      const std::vector<int> got = detail::grow_rings(mesh, s, rings);
      CHECK(got == reference(s, rings));
      CHECK(std::is_sorted(got.begin(), got.end()));
    }
  CHECK(detail::grow_rings(mesh, {5}, 40).size() == soup.vf.size());  // the whole sphere
}
