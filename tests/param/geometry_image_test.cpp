// Tests of geometry_image.cpp and the sphere locator: octahedral map and its folds, locator
// against a brute-force search (both ways), resampling, the remesh's topology, and PSNR.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "spherekit/geometry_image.h"
#include "spherekit/remove_faces.h"
#include "test_meshes.h"

namespace {

using namespace spherekit;
using Eigen::Vector3d;

RowMat3d radial(const TriMesh& m) { return m.V.rowwise().normalized(); }
Vector3d srow(const RowMat3d& S, int v) { return S.row(v).transpose(); }

Vector3d random_direction(std::mt19937_64& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  return Vector3d(N(rng), N(rng), N(rng)).normalized();
}

// Brute force: the smallest gnomonic barycentric of p in every face; returns the best face.
int brute_force_face(const RowMat3i& F, const RowMat3d& S, const Vector3d& p, double& best_score) {
  best_score = -1e300;
  int best = -1;
  for (int f = 0; f < F.rows(); ++f) {
    Vector3d b;
    if (!gnomonic_barycentrics(srow(S, F(f, 0)), srow(S, F(f, 1)), srow(S, F(f, 2)), p, b)) continue;
    if (b.minCoeff() > best_score) {
      best_score = b.minCoeff();
      best = f;
    }
  }
  return best;
}

bool bit_equal(const Vector3d& a, const Vector3d& b) { return std::memcmp(a.data(), b.data(), sizeof(double) * 3) == 0; }

struct EdgeCount {
  std::map<std::pair<int, int>, int> directed;
  std::map<std::pair<int, int>, int> undirected;
};

EdgeCount count_edges(const TriMesh& m) {
  EdgeCount c;
  for (int f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = m.F(f, k), b = m.F(f, (k + 1) % 3);
      ++c.directed[{a, b}];
      ++c.undirected[{std::min(a, b), std::max(a, b)}];
    }
  return c;
}

double remesh_signed_volume(const TriMesh& m) {
  double v = 0;
  for (int f = 0; f < m.F.rows(); ++f)
    v += Vector3d(m.V.row(m.F(f, 0))).dot(Vector3d(m.V.row(m.F(f, 1))).cross(Vector3d(m.V.row(m.F(f, 2)))));
  return v / 6;
}

}  // namespace

TEST_CASE("octahedral map: inverse round trip away from the folds", "[gim]") {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int k = 0; k < 20000; ++k) {
    const double u = U(rng), v = U(rng);
    if (std::abs(std::abs(u) - 1) < 1e-9 || std::abs(std::abs(v) - 1) < 1e-9) continue;
    const Vector3d p = octahedral_to_sphere(u, v);
    REQUIRE(std::abs(p.norm() - 1) < 1e-15);
    const Eigen::Vector2d uv = sphere_to_octahedral(p);
    REQUIRE(std::abs(uv.x() - u) < 1e-12);
    REQUIRE(std::abs(uv.y() - v) < 1e-12);
    // Hemispheres: inner diamond = z >= 0.
    REQUIRE((std::abs(u) + std::abs(v) <= 1) == (p.z() >= -1e-15));
  }
  // And the other way round, for random directions.
  for (int k = 0; k < 20000; ++k) {
    const Vector3d p = random_direction(rng);
    const Eigen::Vector2d uv = sphere_to_octahedral(p);
    REQUIRE((octahedral_to_sphere(uv.x(), uv.y()) - p).norm() < 1e-14);
  }
}

TEST_CASE("octahedral map: the 6 octahedron vertices are texels", "[gim]") {
  for (int n : {3, 9, 257}) {
    const int m = n - 1, h = m / 2;
    const auto at = [n](int i, int j) {
      const Eigen::Vector2d uv = texel_to_octahedral(i, j, n);
      return octahedral_to_sphere(uv.x(), uv.y());
    };
    CHECK(bit_equal(at(h, h), Vector3d(0, 0, 1)));
    CHECK(bit_equal(at(h, m), Vector3d(1, 0, 0)));
    CHECK(bit_equal(at(h, 0), Vector3d(-1, 0, 0)));
    CHECK(bit_equal(at(m, h), Vector3d(0, 1, 0)));
    CHECK(bit_equal(at(0, h), Vector3d(0, -1, 0)));
    for (auto [i, j] : {std::pair{0, 0}, {0, m}, {m, 0}, {m, m}}) CHECK(bit_equal(at(i, j), Vector3d(0, 0, -1)));
    // Octants land in the documented quadrants: inner diamond (u, v > 0) is +x+y+z, the
    // corner triangle u, v > 0 is +x+y-z.
    if (n >= 9) {
      const Vector3d q = at(h + 1, h + 1);
      CHECK((q.x() > 0 && q.y() > 0 && q.z() > 0));
      const Vector3d c = at(m - 1, m - 1);
      CHECK((c.x() > 0 && c.y() > 0 && c.z() < 0));
      const Vector3d d = at(1, 1);
      CHECK((d.x() < 0 && d.y() < 0 && d.z() < 0));
    }
  }
}

TEST_CASE("octahedral map: folded borders give identical sphere points", "[gim]") {
  for (int n : {3, 5, 17, 129}) {
    const int m = n - 1;
    const auto at = [n](int i, int j) {
      const Eigen::Vector2d uv = texel_to_octahedral(i, j, n);
      return octahedral_to_sphere(uv.x(), uv.y());
    };
    for (int s = 0; s < n; ++s) {
      CHECK(bit_equal(at(0, s), at(0, m - s)));
      CHECK(bit_equal(at(m, s), at(m, m - s)));
      CHECK(bit_equal(at(s, 0), at(m - s, 0)));
      CHECK(bit_equal(at(s, m), at(m - s, m)));
      CHECK(canonical_texel(0, s, n) == canonical_texel(0, m - s, n));
      CHECK(canonical_texel(s, m, n) == canonical_texel(m - s, m, n));
    }
    CHECK(canonical_texel(m, m, n) == Eigen::Vector2i(0, 0));
    CHECK(canonical_texel(m, 0, n) == Eigen::Vector2i(0, 0));
    CHECK(canonical_texel(1, 1, n) == Eigen::Vector2i(1, 1));
    // Distinct canonical texels are distinct sphere points.
    std::set<std::pair<int, int>> canon;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const Eigen::Vector2i c = canonical_texel(i, j, n);
        canon.insert({c.x(), c.y()});
      }
    CHECK(static_cast<int>(canon.size()) == (n - 2) * (n - 2) + 2 * n - 1);
  }
}

TEST_CASE("geometry image sizes must be 2^k+1", "[gim]") {
  for (int n : {3, 5, 9, 17, 33, 65, 129, 257, 513}) CHECK(is_geometry_image_size(n));
  for (int n : {-1, 0, 1, 2, 4, 6, 10, 100, 256, 258}) CHECK_FALSE(is_geometry_image_size(n));
  const TriMesh m = test::icosphere(1);
  auto r = sample_geometry_image(m, radial(m), 100);
  REQUIRE_FALSE(r.ok());
  CHECK(r.status().code() == ErrorCode::InvalidArgument);
  RowMat3d short_map = radial(m).topRows(5);
  auto r2 = sample_geometry_image(m, short_map, 9);
  REQUIRE_FALSE(r2.ok());
  CHECK(r2.status().code() == ErrorCode::InvalidInput);
}

TEST_CASE("sphere locator agrees with a brute-force search (both ways)", "[gim]") {
  for (int which = 0; which < 3; ++which) {
    const TriMesh m = which == 0 ? test::icosphere(3) : which == 1 ? test::random_blob(3, 11) : test::octahedron();
    const RowMat3d S = radial(m);
    const SphereLocator locator(m.F, S);
    CAPTURE(which, locator.grid_size());
    std::mt19937_64 rng(17 + which);
    // Way 1: random directions -> the locator's face is the brute-force best face (or ties
    // with it on an edge) and its barycentrics reproduce the direction.
    for (int k = 0; k < 3000; ++k) {
      const Vector3d p = random_direction(rng);
      const SphereLocation loc = locator.locate(p);
      double best;
      const int bf = brute_force_face(m.F, S, p, best);
      REQUIRE(best > -1e-12);
      REQUIRE(loc.inside);
      REQUIRE(loc.face >= 0);
      Vector3d b;
      REQUIRE(gnomonic_barycentrics(srow(S, m.F(loc.face, 0)), srow(S, m.F(loc.face, 1)), srow(S, m.F(loc.face, 2)),
                                    p, b));
      if (loc.face != bf) REQUIRE(b.minCoeff() > -1e-9);  // tie on a shared edge
      const Vector3d q = loc.bary[0] * srow(S, m.F(loc.face, 0)) + loc.bary[1] * srow(S, m.F(loc.face, 1)) +
                         loc.bary[2] * srow(S, m.F(loc.face, 2));
      REQUIRE((q.normalized() - p).norm() < 1e-9);
    }
    // Way 2: a point made from a known face and barycentrics is found in that face.
    std::uniform_real_distribution<double> U(0.02, 1.0);
    std::uniform_int_distribution<int> pick(0, static_cast<int>(m.F.rows()) - 1);
    for (int k = 0; k < 3000; ++k) {
      const int f = pick(rng);
      Vector3d w(U(rng), U(rng), U(rng));
      w /= w.sum();
      const Vector3d q = w[0] * srow(S, m.F(f, 0)) + w[1] * srow(S, m.F(f, 1)) + w[2] * srow(S, m.F(f, 2));
      const SphereLocation loc = locator.locate(q.normalized());
      REQUIRE(loc.face == f);
      REQUIRE((loc.bary - w).norm() < 1e-9);
    }
    // Vertices and edge midpoints: always found, inside.
    for (int f = 0; f < m.F.rows(); f += 7)
      for (int c = 0; c < 3; ++c) {
        const Vector3d a = srow(S, m.F(f, c)), b = srow(S, m.F(f, (c + 1) % 3));
        for (const Vector3d& p : {a, Vector3d((a + b).normalized())}) {
          const SphereLocation loc = locator.locate(p);
          REQUIRE(loc.inside);
          REQUIRE(loc.bary.minCoeff() >= 0);
          REQUIRE(std::abs(loc.bary.sum() - 1) < 1e-12);
        }
      }
  }
}

TEST_CASE("sphere locator: directions in a hole get the nearest face", "[gim]") {
  const TriMesh m = test::sphere_with_holes(3, 2);
  const RowMat3d S = radial(m);
  const SphereLocator locator(m.F, S);
  std::mt19937_64 rng(5);
  int in_holes = 0;
  for (int k = 0; k < 4000; ++k) {
    const Vector3d p = random_direction(rng);
    const SphereLocation loc = locator.locate(p);
    double best;
    brute_force_face(m.F, S, p, best);
    REQUIRE(loc.face >= 0);
    if (best >= 1e-9) REQUIRE(loc.inside);
    if (loc.inside) continue;
    ++in_holes;
    REQUIRE(best < 1e-6);
    // The chosen face is the nearest (chord distance to the flat triangle) within 1e-12.
    const auto point = [&](int f, const Vector3d& w) {
      return Vector3d(w[0] * srow(S, m.F(f, 0)) + w[1] * srow(S, m.F(f, 1)) + w[2] * srow(S, m.F(f, 2)));
    };
    const double d = (point(loc.face, loc.bary) - p).norm();
    double brute = 1e300;
    for (int f = 0; f < m.F.rows(); ++f) {
      // Dense barycentric grid: an upper bound on the distance to face f.
      for (int a = 0; a <= 20; ++a)
        for (int b = 0; a + b <= 20; ++b) brute = std::min(brute, (point(f, Vector3d(a, b, 20 - a - b) / 20) - p).norm());
    }
    REQUIRE(d <= brute + 1e-12);
  }
  CHECK(in_holes > 0);
}

TEST_CASE("geometry image of the unit icosphere lies on the unit sphere", "[gim]") {
  const TriMesh m = test::icosphere(3);
  // Chord error of the icosphere: the largest sagitta 1 - cos(edge/2) over its edges.
  double sagitta = 0;
  for (int f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Vector3d mid = (Vector3d(m.V.row(m.F(f, k))) + Vector3d(m.V.row(m.F(f, (k + 1) % 3)))) / 2;
      sagitta = std::max(sagitta, 1 - mid.norm());
    }
  // A face's centre is farther in than its edges' midpoints: bound by 2x the edge sagitta.
  auto r = sample_geometry_image(m, radial(m), 65);
  REQUIRE(r.ok());
  const GeometryImage& gi = r.value();
  REQUIRE(gi.size == 65);
  CHECK(gi.texels_in_holes == 0);
  for (int i = 0; i < 65; ++i)
    for (int j = 0; j < 65; ++j) {
      const Eigen::Vector3d p = gi.position(i, j).cast<double>();
      REQUIRE(p.norm() <= 1 + 1e-6);
      REQUIRE(p.norm() >= 1 - 2 * sagitta);
      // The point lies in the direction of the texel's sphere point (identity map, gnomonic).
      const Eigen::Vector2d uv = texel_to_octahedral(i, j, 65);
      REQUIRE((p.normalized() - octahedral_to_sphere(uv.x(), uv.y())).norm() < 1e-6);
      REQUIRE(gi.normal(i, j).cast<double>().dot(p.normalized()) > 0.99);
      REQUIRE(gi.face_ids[static_cast<std::size_t>(i) * 65 + j] >= 0);
    }
  // Folded duplicates hold identical values.
  for (int s = 0; s < 65; ++s) {
    CHECK(gi.position(0, s) == gi.position(0, 64 - s));
    CHECK(gi.position(s, 64) == gi.position(64 - s, 64));
    CHECK(gi.normal(s, 0) == gi.normal(64 - s, 0));
  }
}

TEST_CASE("the remesh of a geometry image is a closed, consistently oriented genus-0 manifold", "[gim]") {
  const TriMesh blob = test::random_blob(3, 5);
  for (int n : {3, 5, 17, 65}) {
    CAPTURE(n);
    auto r = sample_geometry_image(blob, radial(blob), n);
    REQUIRE(r.ok());
    const TriMesh rm = geometry_image_mesh(r.value());
    CHECK(rm.V.rows() == (n - 2) * (n - 2) + 2 * n - 1);
    CHECK(rm.F.rows() == 2 * (n - 1) * (n - 1));
    const EdgeCount e = count_edges(rm);
    for (const auto& [edge, count] : e.undirected) REQUIRE(count == 2);
    for (const auto& [edge, count] : e.directed) REQUIRE(count == 1);  // consistent orientation
    for (int f = 0; f < rm.F.rows(); ++f)
      REQUIRE((rm.F(f, 0) != rm.F(f, 1) && rm.F(f, 1) != rm.F(f, 2) && rm.F(f, 0) != rm.F(f, 2)));
    const auto V = static_cast<long>(rm.V.rows()), E = static_cast<long>(e.undirected.size()),
               F = static_cast<long>(rm.F.rows());
    CHECK(V - E + F == 2);
    CHECK(remesh_signed_volume(rm) > 0);  // outward
    // Octahedron edges are mesh edges.
    const int h = (n - 1) / 2;
    if (n >= 5) {
      // The diamond edge from +x, texel (h, n-1), to +y, texel (n-1, h), runs through texel
      // (h+1, n-2); vertex ids follow the documented welding order.
      std::map<std::pair<int, int>, int> id;
      int next = 0;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const Eigen::Vector2i c = canonical_texel(i, j, n);
          if (!id.count({c.x(), c.y()})) id[{c.x(), c.y()}] = next++;
        }
      const int a = id[{h, n - 1}], b = id[{h + 1, n - 2}];
      CHECK(e.undirected.count({std::min(a, b), std::max(a, b)}) == 1);
    }
  }
}

TEST_CASE("remesh PSNR: a mesh against itself is very high and coarser images score lower", "[gim]") {
  const TriMesh blob = test::random_blob(4, 7);
  RemeshErrorOptions opts;
  opts.samples = 100000;
  const RemeshError self = remesh_error(blob, blob, opts);
  CHECK((std::isinf(self.psnr) || self.psnr > 100));
  CHECK(self.peak > 0);
  double previous = 0;
  for (int n : {33, 65, 129}) {
    auto r = sample_geometry_image(blob, radial(blob), n);
    REQUIRE(r.ok());
    const double psnr = remesh_psnr(blob, geometry_image_mesh(r.value()), opts);
    CAPTURE(n, psnr);
    CHECK(psnr > previous);
    CHECK(psnr < 100);
    previous = psnr;
  }
  CHECK(previous > 45);
  // Symmetric: an offset copy is measured the same either way round.
  TriMesh shifted = blob;
  shifted.V.col(0).array() += 0.01;
  const RemeshError e = remesh_error(blob, shifted, opts);
  CHECK(e.rms > 0);
  CHECK(e.rms <= 0.01 + 1e-12);
  CHECK(std::isfinite(e.psnr));
}

TEST_CASE("geometry image of a mesh with holes: hole texels and hole faces", "[gim]") {
  const TriMesh m = test::sphere_with_holes(3, 2);
  auto r = sample_geometry_image(m, radial(m), 65);
  REQUIRE(r.ok());
  const GeometryImage& gi = r.value();
  REQUIRE(gi.texels_in_holes > 0);
  int count = 0;
  for (auto h : gi.in_hole) count += h;
  CHECK(count == gi.texels_in_holes);
  // Every texel still has a face and lies on the (unit) mesh.
  for (int i = 0; i < 65; ++i)
    for (int j = 0; j < 65; ++j) REQUIRE(std::abs(gi.position(i, j).norm() - 1) < 0.05);
  const TriMesh rm = geometry_image_mesh(gi);
  const auto hole_faces = geometry_image_hole_faces(gi);
  REQUIRE(hole_faces.size() == static_cast<std::size_t>(rm.F.rows()));
  int excluded = 0;
  for (auto h : hole_faces) excluded += h;
  CHECK(excluded > 0);
  CHECK(excluded < rm.F.rows() / 4);
  RemeshErrorOptions opts;
  opts.samples = 50000;
  const double all = remesh_psnr(m, rm, opts), kept = remesh_psnr(m, rm, opts, hole_faces);
  CAPTURE(all, kept);
  CHECK(kept > all);
  // The open remesh: the kept faces, in order, on the same positions, and no unused vertex.
  const TriMesh open = geometry_image_open_mesh(gi);
  REQUIRE(open.F.rows() == rm.F.rows() - excluded);
  std::vector<int> used(static_cast<std::size_t>(open.V.rows()), 0);
  Eigen::Index row = 0;
  for (Eigen::Index f = 0; f < rm.F.rows(); ++f) {
    if (hole_faces[static_cast<std::size_t>(f)]) continue;
    for (int c = 0; c < 3; ++c) {
      REQUIRE(open.V.row(open.F(row, c)) == rm.V.row(rm.F(f, c)));
      used[static_cast<std::size_t>(open.F(row, c))] = 1;
    }
    ++row;
  }
  CHECK(std::count(used.begin(), used.end(), 0) == 0);
  CHECK(open.V.rows() < rm.V.rows());
  // Closed meshes have no hole faces.
  const TriMesh ico = test::icosphere(2);
  auto r2 = sample_geometry_image(ico, radial(ico), 17);
  REQUIRE(r2.ok());
  for (auto h : geometry_image_hole_faces(r2.value())) REQUIRE(h == 0);
  const TriMesh closed = geometry_image_mesh(r2.value()), same = geometry_image_open_mesh(r2.value());
  CHECK(same.V == closed.V);
  CHECK(same.F == closed.F);
}

// ---------------------------------------------------------------------------------------
// Least-squares texel positions (fit_geometry_image_positions)

TEST_CASE("fitted geometry image: lower remesh error than the sampled one, same layout", "[gim]") {
  const TriMesh blob = test::random_blob(4, 7);
  RemeshErrorOptions opts;
  opts.samples = 100000;
  GeometryImageOptions fit;
  fit.fit_positions = true;
  for (int n : {17, 33, 65}) {
    CAPTURE(n);
    auto sampled = sample_geometry_image(blob, radial(blob), n);
    auto fitted = sample_geometry_image(blob, radial(blob), n, fit);
    REQUIRE(sampled.ok());
    REQUIRE(fitted.ok());
    const GeometryImage& a = sampled.value();
    const GeometryImage& b = fitted.value();
    // Only the positions change.
    CHECK(a.normals == b.normals);
    CHECK(a.face_ids == b.face_ids);
    CHECK(a.in_hole == b.in_hole);
    CHECK(a.positions != b.positions);
    // Folded border pairs stay bit-identical (one unknown each).
    for (int s = 0; s < n; ++s) {
      REQUIRE(b.position(0, s) == b.position(0, n - 1 - s));
      REQUIRE(b.position(n - 1, s) == b.position(n - 1, n - 1 - s));
      REQUIRE(b.position(s, 0) == b.position(n - 1 - s, 0));
      REQUIRE(b.position(s, n - 1) == b.position(n - 1 - s, n - 1));
    }
    const double psnr_sampled = remesh_psnr(blob, geometry_image_mesh(a), opts);
    const double psnr_fitted = remesh_psnr(blob, geometry_image_mesh(b), opts);
    CAPTURE(psnr_sampled, psnr_fitted);
    // Interpolation leaves the remesh on one side of a curved surface; the L2 fit centres it,
    // which is worth several decibels on a smooth blob.
    CHECK(psnr_fitted > psnr_sampled + 3.0);
    // Deterministic, whatever the sampling threads.
    GeometryImageOptions fit1 = fit;
    fit1.threads = 1;
    auto again = sample_geometry_image(blob, radial(blob), n, fit1);
    REQUIRE(again.ok());
    CHECK(again.value().positions == b.positions);
  }
}

TEST_CASE("fitted geometry image of the octahedron reproduces it (the grid represents it exactly)", "[gim]") {
  // The octahedral map sends each grid triangle linearly onto the octahedron |x|+|y|+|z| = 1
  // (the grid is split along the diamond edges), so the sampled image is already the exact
  // least-squares solution: the fit must return it. This pins the fit's barycentrics and
  // split rule to those of geometry_image_mesh.
  TriMesh oct = test::octahedron();
  oct.V = oct.V.rowwise().normalized();  // vertices on the axes, faces on |x|+|y|+|z| = 1
  for (int n : {3, 9, 33}) {
    CAPTURE(n);
    auto sampled = sample_geometry_image(oct, radial(oct), n);
    REQUIRE(sampled.ok());
    GeometryImage fitted = sampled.value();
    REQUIRE(fit_geometry_image_positions(oct, radial(oct), &fitted).ok());
    double worst = 0;
    for (std::size_t k = 0; k < fitted.positions.size(); ++k)
      worst = std::max(worst, static_cast<double>(std::abs(fitted.positions[k] - sampled.value().positions[k])));
    CHECK(worst < 1e-5);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const Eigen::Vector3d p = fitted.position(i, j).cast<double>();
        REQUIRE(std::abs(p.cwiseAbs().sum() - 1) < 1e-5);
      }
  }
}

TEST_CASE("hole faces: a face is in a hole when two or three of its texels are", "[gim]") {
  // A 5 x 5 image (4 x 4 cells; quadrant i, j < 2 splits along the anti-diagonal: faces ABD,
  // BCD of cell (i, j) with A (i,j), B (i,j+1), C (i+1,j+1), D (i+1,j)).
  GeometryImage gi;
  gi.size = 5;
  gi.positions.assign(5 * 5 * 3, 0.0f);
  gi.in_hole.assign(25, 0);
  const auto face = [](int i, int j, int second) { return static_cast<std::size_t>(2 * (i * 4 + j) + second); };
  // One hole texel: no face is in the hole.
  gi.in_hole[1 * 5 + 1] = 1;
  auto flags = geometry_image_hole_faces(gi);
  REQUIRE(flags.size() == 32);
  CHECK(std::count(flags.begin(), flags.end(), 1) == 0);
  // Texels (1,1) and (1,2): the faces holding both, and only those.
  gi.in_hole[1 * 5 + 2] = 1;
  flags = geometry_image_hole_faces(gi);
  CHECK(std::count(flags.begin(), flags.end(), 1) == 2);
  CHECK(flags[face(1, 1, 0)] == 1);  // A (1,1), B (1,2), D (2,1)
  CHECK(flags[face(0, 1, 1)] == 1);  // B (0,2), C (1,2), D (1,1)
  // All three texels of face ABD of cell (1, 1): it, and the faces holding two of them.
  gi.in_hole[2 * 5 + 1] = 1;
  flags = geometry_image_hole_faces(gi);
  CHECK(flags[face(1, 1, 0)] == 1);
  CHECK(flags[face(1, 1, 1)] == 1);  // B (1,2), C (2,2), D (2,1)
  CHECK(flags[face(0, 1, 1)] == 1);
  CHECK(flags[face(1, 0, 1)] == 1);  // B (1,1), C (2,1), D (2,0)
  CHECK(std::count(flags.begin(), flags.end(), 1) == 4);
}

TEST_CASE("hole faces leave a manifold: no vertex where kept faces meet in two fans", "[gim]") {
  // Random hole texels (a third of them; fold pairs alike) make many places where the
  // majority rule alone would leave two fans of kept faces joined at one vertex.
  const int n = 17;
  int count = 0;
  const std::vector<int> id = geometry_image_welded_ids(n, &count);
  const RowMat3i grid = geometry_image_grid_faces(n);
  std::mt19937 rng(5);
  int repaired = 0;
  for (int round = 0; round < 20; ++round) {
    GeometryImage gi;
    gi.size = n;
    gi.positions.assign(static_cast<std::size_t>(n) * n * 3, 0.0f);
    gi.in_hole.assign(static_cast<std::size_t>(n) * n, 0);
    std::vector<std::uint8_t> welded_hole(static_cast<std::size_t>(count));
    for (auto& h : welded_hole) h = rng() % 3 == 0 ? 1 : 0;
    for (std::size_t t = 0; t < gi.in_hole.size(); ++t) gi.in_hole[t] = welded_hole[static_cast<std::size_t>(id[t])];
    const auto flags = geometry_image_hole_faces(gi);
    REQUIRE(flags.size() == static_cast<std::size_t>(grid.rows()));
    std::map<std::pair<int, int>, int> kept_on_edge;  // welded edge -> kept faces on it
    for (Eigen::Index f = 0; f < grid.rows(); ++f) {
      int corners = 0;
      for (int k = 0; k < 3; ++k) corners += gi.in_hole[static_cast<std::size_t>(grid(f, k))];
      // Only faces with two or three hole corners may be left out.
      if (corners < 2) REQUIRE(flags[static_cast<std::size_t>(f)] == 0);
      if (corners >= 2 && !flags[static_cast<std::size_t>(f)]) ++repaired;
      for (int k = 0; k < 3; ++k) {
        const int a = id[static_cast<std::size_t>(grid(f, k))], b = id[static_cast<std::size_t>(grid(f, (k + 1) % 3))];
        kept_on_edge[{std::min(a, b), std::max(a, b)}] += flags[static_cast<std::size_t>(f)] ? 0 : 1;
      }
    }
    std::vector<int> boundary(static_cast<std::size_t>(count), 0);
    for (const auto& [edge, kept] : kept_on_edge)
      if (kept == 1) ++boundary[static_cast<std::size_t>(edge.first)], ++boundary[static_cast<std::size_t>(edge.second)];
    for (int b : boundary) REQUIRE(b <= 2);
  }
  CHECK(repaired > 0);  // the case arose and was mended
}

TEST_CASE("fitted geometry image: a mesh with holes keeps its hole texels and gets no worse", "[gim]") {
  const TriMesh m = test::sphere_with_holes(4, 3);
  GeometryImageOptions fit;
  fit.fit_positions = true;
  auto a = sample_geometry_image(m, radial(m), 33);
  auto b = sample_geometry_image(m, radial(m), 33, fit);
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  REQUIRE(a.value().texels_in_holes > 0);
  CHECK(a.value().in_hole == b.value().in_hole);
  for (float x : b.value().positions) REQUIRE(std::isfinite(x));
  // Hole texels are held exactly where the sampler put them (on the rims); the others move.
  int moved = 0;
  for (std::size_t t = 0; t < a.value().in_hole.size(); ++t) {
    const bool same = std::equal(&a.value().positions[3 * t], &a.value().positions[3 * t + 3], &b.value().positions[3 * t]);
    if (a.value().in_hole[t]) REQUIRE(same);
    else moved += same ? 0 : 1;
  }
  CHECK(moved > static_cast<int>(a.value().in_hole.size()) / 2);
  RemeshErrorOptions opts;
  opts.samples = 100000;
  const double pa = remesh_psnr(m, geometry_image_mesh(a.value()), opts, geometry_image_hole_faces(a.value()));
  const double pb = remesh_psnr(m, geometry_image_mesh(b.value()), opts, geometry_image_hole_faces(b.value()));
  CAPTURE(pa, pb);
  CHECK(pb > pa);
}

TEST_CASE("fitted geometry image: input that is not a sampled image is refused", "[gim]") {
  const TriMesh blob = test::random_blob(2, 3);
  GeometryImage empty;
  CHECK(fit_geometry_image_positions(blob, radial(blob), &empty).code() == ErrorCode::InvalidArgument);
  auto r = sample_geometry_image(blob, radial(blob), 9);
  REQUIRE(r.ok());
  GeometryImage gi = r.value();
  const RowMat3d wrong = radial(blob).topRows(4);
  CHECK(fit_geometry_image_positions(blob, wrong, &gi).code() == ErrorCode::InvalidInput);
  CHECK(gi.positions == r.value().positions);
}

TEST_CASE("remove_faces keeps the other faces in order and drops only unused vertices", "[gim]") {
  const TriMesh ico = test::icosphere(1);
  std::vector<std::uint8_t> drop(static_cast<std::size_t>(ico.F.rows()), 0);
  drop[0] = 1;
  std::vector<int> index;
  const TriMesh out = remove_faces(ico, drop, &index);
  CHECK(out.F.rows() == ico.F.rows() - 1);
  CHECK(out.V.rows() == ico.V.rows());  // every vertex still has a face
  for (Eigen::Index f = 1; f < ico.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) REQUIRE(out.V.row(out.F(f - 1, k)) == ico.V.row(ico.F(f, k)));
  // A face index out of range, or flags of the wrong count: unchanged, identity map.
  TriMesh bad = ico;
  bad.F(3, 1) = static_cast<int>(ico.V.rows());
  const TriMesh same = remove_faces(bad, drop, &index);
  CHECK(same.F == bad.F);
  CHECK(index.size() == static_cast<std::size_t>(ico.V.rows()));
  CHECK(index.back() == static_cast<int>(ico.V.rows()) - 1);
  CHECK(remove_faces(ico, {}).F == ico.F);
}
