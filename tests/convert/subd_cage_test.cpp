// Tests of the Catmull–Clark cage on the sphere domain, its fit, the displacement maps and
// their EXR atlas (convert/src/subd_cage.cpp, displacement.cpp, displacement_exr.cpp).
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include "spherekit/convert/cage_uv_atlas.h"
#include "spherekit/convert/displacement.h"
#include "spherekit/convert/displacement_exr.h"
#include "spherekit/convert/geometry_image_exr.h"
#include "spherekit/convert/subd_cage.h"
#include "spherekit/geometry_image.h"
#include "test_meshes.h"
#include "test_paths.h"

namespace fs = std::filesystem;
using namespace spherekit;
using namespace spherekit::convert;

TEST_CASE("cube lattice: ids are a bijection onto the distinct cube points", "[convert][cage]") {
  for (int m : {1, 2, 3, 7}) {
    // Two lattice points get one id exactly when they are the same point of the cube.
    std::map<int, Eigen::Vector3d> point_of_id;
    for (int k = 0; k < 6; ++k)
      for (int j = 0; j <= m; ++j)
        for (int i = 0; i <= m; ++i) {
          const int id = cube_lattice_id(m, k, i, j);
          REQUIRE(id >= 0);
          REQUIRE(id < cube_lattice_points(m));
          const Eigen::Vector3d p = cube_domain_point(k, double(i) / m, double(j) / m);
          auto [it, fresh] = point_of_id.emplace(id, p);
          if (!fresh) CHECK((it->second - p).norm() < 1e-14);
        }
    CHECK(static_cast<long long>(point_of_id.size()) == cube_lattice_points(m));
    std::set<std::tuple<long long, long long, long long>> distinct;
    for (const auto& [id, p] : point_of_id)
      distinct.emplace(std::llround(p.x() * 1e9), std::llround(p.y() * 1e9), std::llround(p.z() * 1e9));
    CHECK(distinct.size() == point_of_id.size());
  }
}

TEST_CASE("cube cage domain: closed quad mesh, ccw from outside, 8 valence-3 corners", "[convert][cage]") {
  auto d = cube_cage_domain(3);
  REQUIRE(d.ok());
  const CageDomain& dom = d.value();
  CHECK(dom.quads.size() == 54);
  CHECK(dom.sphere.rows() == 56);
  std::map<std::pair<int, int>, int> directed;
  std::vector<int> valence(static_cast<std::size_t>(dom.sphere.rows()), 0);
  for (std::size_t f = 0; f < dom.quads.size(); ++f) {
    const auto& q = dom.quads[f];
    Eigen::Vector3d centre = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::Zero();
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d a = dom.sphere.row(q[c]), b = dom.sphere.row(q[(c + 1) % 4]);
      centre += a / 4;
      normal += a.cross(b);
      ++directed[{q[c], q[(c + 1) % 4]}];
      ++valence[static_cast<std::size_t>(q[c])];
    }
    CHECK(normal.dot(centre) > 0);  // counter-clockwise seen from outside
    // The domain point of the quad's (u, v) = (0, 0) and (1, 1) are its corners 0 and 2.
    CHECK((cage_domain_point(dom, static_cast<int>(f), 0, 0) - Eigen::Vector3d(dom.sphere.row(q[0]))).norm() < 1e-14);
    CHECK((cage_domain_point(dom, static_cast<int>(f), 1, 1) - Eigen::Vector3d(dom.sphere.row(q[2]))).norm() < 1e-14);
  }
  // Every directed edge once, its reverse once: closed, consistently oriented, manifold.
  for (const auto& [e, count] : directed) {
    CHECK(count == 1);
    CHECK(directed.count({e.second, e.first}) == 1);
  }
  int valence3 = 0;
  for (int v : valence) {
    CHECK((v == 3 || v == 4));
    valence3 += v == 3;
  }
  CHECK(valence3 == 8);
  // Euler characteristic 2.
  CHECK(dom.sphere.rows() - static_cast<long long>(directed.size() / 2) + static_cast<long long>(dom.quads.size()) == 2);
}

TEST_CASE("cage of a sphere reproduces the sphere", "[convert][cage]") {
  // The unit icosphere with its own normalized vertices as sphere map. Its faces lie inside the
  // sphere by at most the sagitta 1 - cos(theta/2) of its longest edge's angle theta. A
  // Catmull-Clark limit surface cannot be exactly round (its curvature degenerates at the
  // valence-3 corners), so the bound is: within 0.2 % of the radius (plus the sagitta) with
  // 96 quads, and the error must shrink when the cage is refined (n = 4 -> 8).
  const TriMesh sphere = test::icosphere(5);
  double theta = 0;
  for (Eigen::Index f = 0; f < sphere.F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d a = sphere.V.row(sphere.F(f, c)).normalized(),
                            b = sphere.V.row(sphere.F(f, (c + 1) % 3)).normalized();
      theta = std::max(theta, std::acos(std::clamp(a.dot(b), -1.0, 1.0)));
    }
  const double sagitta = 1 - std::cos(theta / 2);
  const RowMat3d S = sphere.V.rowwise().normalized();
  double worst_of[2] = {0, 0};
  for (int pass = 0; pass < 2; ++pass) {
    const int n = pass == 0 ? 4 : 8;
    auto dom = cube_cage_domain(n);
    REQUIRE(dom.ok());
    auto limit = CageLimit::create(dom.value());
    REQUIRE(limit.ok());
    auto cage = fit_subd_cage(sphere, S, limit.value(), dom.value());
    REQUIRE(cage.ok());
    const double quad_angle = 1.5707963267948966 / n;
    double worst = 0;
    for (int f = 0; f < limit->faces(); ++f)
      for (double u : {0.0, 0.3, 0.5, 1.0})
        for (double v : {0.0, 0.7, 1.0}) {
          Eigen::Vector3d P, N;
          limit->evaluate(cage->points, f, u, v, P, N);
          worst = std::max(worst, std::abs(P.norm() - 1));
          CHECK(N.dot(P.normalized()) > 0.99);  // outward unit normal
          // The limit point stays above its own domain point (within a quarter quad): the
          // cage follows the sphere map, so cage vertex k means the same place on every mesh.
          CHECK(std::acos(std::min(1.0, P.normalized().dot(cage_domain_point(dom.value(), f, u, v)))) <
                quad_angle / 4);
        }
    worst_of[pass] = worst;
    CHECK(cage->fit_rms < 0.002);
  }
  INFO("sagitta " << sagitta << ", worst radial error n=4 " << worst_of[0] << ", n=8 " << worst_of[1]);
  CHECK(worst_of[0] < sagitta + 2e-3);
  CHECK(worst_of[1] < 0.6 * worst_of[0]);
}

TEST_CASE("displacement: scalar and vector reconstruct a bumpy mesh, better than the bare limit", "[convert][cage]") {
  const TriMesh blob = test::random_blob(4, 5);
  const RowMat3d S = blob.V.rowwise().normalized();
  auto dom = cube_cage_domain(3);
  REQUIRE(dom.ok());
  auto limit = CageLimit::create(dom.value());
  REQUIRE(limit.ok());
  auto cage = fit_subd_cage(blob, S, limit.value(), dom.value());
  REQUIRE(cage.ok());
  RemeshErrorOptions eo;
  eo.samples = 40000;
  const double bare = remesh_psnr(blob, displaced_surface_mesh(cage.value(), limit.value(), nullptr, 17), eo);
  for (DisplacementKind kind : {DisplacementKind::Scalar, DisplacementKind::Vector}) {
    DisplacementOptions o;
    o.tile = 17;
    o.kind = kind;
    auto map = sample_displacement(blob, S, cage.value(), limit.value(), o);
    REQUIRE(map.ok());
    CHECK(map->samples_in_holes == 0);
    const TriMesh recon = displaced_surface_mesh(cage.value(), limit.value(), &map.value(), 0);
    // Welded: a closed genus-0 triangle mesh on the lattice (V - E + F = 2 with E = 3F/2).
    CHECK(recon.V.rows() - recon.F.rows() / 2 == 2);
    const double psnr = remesh_psnr(blob, recon, eo);
    INFO("bare limit " << bare << " dB, displaced " << psnr << " dB");
    CHECK(psnr > bare + 10);
    if (kind == DisplacementKind::Scalar) CHECK(map->mean_ray_residual < 1e-6);
    // Vector displacement lands on the mesh point the sphere map pairs with each sample.
    if (kind == DisplacementKind::Vector) {
      const SphereLocator loc(blob.F, S);
      const int f = 7, r = 5, c = 11, T = o.tile;
      Eigen::Vector3d P, N;
      limit->evaluate(cage->points, f, double(c) / (T - 1), double(r) / (T - 1), P, N);
      const std::size_t s = (static_cast<std::size_t>(f) * T + r) * T + c;
      const Eigen::Vector3d D(map->values[3 * s], map->values[3 * s + 1], map->values[3 * s + 2]);
      const SphereLocation at = loc.locate(cage_domain_point(dom.value(), f, double(c) / (T - 1), double(r) / (T - 1)));
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) x += at.bary[k] * blob.V.row(blob.F(at.face, k)).transpose();
      CHECK((P + D - x).norm() < 1e-6);
    }
  }
}

TEST_CASE("cage fit and displacement do not depend on the thread count", "[convert][cage]") {
  const TriMesh blob = test::random_blob(3, 2);
  const RowMat3d S = blob.V.rowwise().normalized();
  auto dom = cube_cage_domain(2);
  auto limit = CageLimit::create(dom.value());
  REQUIRE(limit.ok());
  CageFitOptions f1, f2;
  f1.threads = 1;
  f2.threads = 2;
  auto a = fit_subd_cage(blob, S, limit.value(), dom.value(), f1);
  auto b = fit_subd_cage(blob, S, limit.value(), dom.value(), f2);
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  CHECK(a->points == b->points);
  DisplacementOptions d1, d2;
  d1.threads = 1;
  d2.threads = 2;
  auto m1 = sample_displacement(blob, S, a.value(), limit.value(), d1);
  auto m2 = sample_displacement(blob, S, a.value(), limit.value(), d2);
  REQUIRE(m1.ok());
  REQUIRE(m2.ok());
  CHECK(m1->values == m2->values);
}

TEST_CASE("displacement texture EXR: round trip is bit-exact, bad files are refused", "[convert][cage]") {
  const TriMesh blob = test::random_blob(3, 4);
  const RowMat3d S = blob.V.rowwise().normalized();
  auto dom = cube_cage_domain(2);
  auto limit = CageLimit::create(dom.value());
  auto cage = fit_subd_cage(blob, S, limit.value(), dom.value());
  REQUIRE(cage.ok());
  const std::string dir = test::temp_dir("disp_exr");
  for (DisplacementKind kind : {DisplacementKind::Scalar, DisplacementKind::Vector})
    for (int gutter : {0, 2}) {
      DisplacementOptions o;
      o.tile = 9;
      o.kind = kind;
      auto map = sample_displacement(blob, S, cage.value(), limit.value(), o);
      REQUIRE(map.ok());
      auto atlas = cage_uv_atlas(map->faces, 9, gutter);
      REQUIRE(atlas.ok());
      const std::string path = dir + "/d" + std::to_string(map->channels()) + "_" + std::to_string(gutter) + ".exr";
      REQUIRE(write_displacement_exr(path, map.value(), atlas.value(), {"blob.obj", "blob.sphere.obj", "blob.cage.obj"}).ok());
      auto back = read_displacement_exr(path);
      REQUIRE(back.ok());
      CHECK(back->map.kind == kind);
      CHECK(back->map.tile == 9);
      CHECK(back->map.faces == 24);
      CHECK(back->map.cage_n == 2);
      CHECK(back->atlas.gutter == gutter);
      // 24 tiles in 5 columns x 5 rows of 9 + 2g texels.
      CHECK(back->atlas.columns == 5);
      CHECK(back->atlas.rows == 5);
      CHECK(back->atlas.width() == 5 * (9 + 2 * gutter));
      REQUIRE(back->map.values.size() == map->values.size());
      CHECK(std::memcmp(back->map.values.data(), map->values.data(), map->values.size() * sizeof(float)) == 0);
      CHECK(back->map.samples_in_holes == map->samples_in_holes);
      CHECK(back->attributes.at("layout") == "cage-uv-atlas");
      CHECK(back->attributes.at("source_mesh") == "blob.obj");
      // An atlas of another tile size is refused.
      auto other = cage_uv_atlas(map->faces, 5, gutter);
      CHECK(write_displacement_exr(dir + "/bad.exr", map.value(), other.value()).code() == ErrorCode::InvalidArgument);
      CHECK_FALSE(fs::exists(dir + "/bad.exr"));
    }
  // A geometry image is not a displacement texture.
  auto gi = sample_geometry_image(blob, S, 9);
  REQUIRE(gi.ok());
  REQUIRE(write_geometry_image_exr(dir + "/gi.exr", gi.value()).ok());
  auto wrong = read_displacement_exr(dir + "/gi.exr");
  CHECK(wrong.status().code() == ErrorCode::InvalidInput);
  auto missing = read_displacement_exr(dir + "/none.exr");
  CHECK(missing.status().code() == ErrorCode::IoError);
}

TEST_CASE("cage UV atlas: corner UVs are tile texel centres, gutters extrapolate linearly", "[convert][cage]") {
  CHECK(cage_uv_atlas(1, 9, 2)->columns == 1);
  CHECK(cage_uv_atlas(6, 9, 2)->columns == 3);
  CHECK(cage_uv_atlas(6, 9, 2)->rows == 2);
  CHECK(cage_uv_atlas(96, 9, 2)->columns == 10);
  CHECK(cage_uv_atlas(0, 9, 2).status().code() == ErrorCode::InvalidArgument);
  CHECK(cage_uv_atlas(6, 1, 2).status().code() == ErrorCode::InvalidArgument);
  CHECK(cage_uv_atlas(6, 9, -1).status().code() == ErrorCode::InvalidArgument);
  const int T = 5, g = 2, faces = 7;
  auto atlas = cage_uv_atlas(faces, T, g);
  REQUIRE(atlas.ok());
  const int W = atlas->width(), H = atlas->height(), P = T + 2 * g;
  CHECK(W == 3 * P);
  CHECK(H == 3 * P);
  // Per tile a linear function of (r, c) in both channels: the gutters must continue it exactly.
  std::vector<float> values(static_cast<std::size_t>(faces) * T * T * 2);
  auto value = [](int f, int r, int c, int ch) { return ch == 0 ? f + 0.25 * r - 0.5 * c : -f * 0.125 + 0.75 * c; };
  for (int f = 0; f < faces; ++f)
    for (int r = 0; r < T; ++r)
      for (int c = 0; c < T; ++c)
        for (int ch = 0; ch < 2; ++ch)
          values[((static_cast<std::size_t>(f) * T + r) * T + c) * 2 + ch] = static_cast<float>(value(f, r, c, ch));
  const std::vector<float> image = cage_atlas_image(atlas.value(), values, 2);
  REQUIRE(image.size() == static_cast<std::size_t>(W) * H * 2);
  for (int f = 0; f < faces; ++f) {
    // The UV of a sample parameter is its texel's centre (y from the bottom).
    for (int r = 0; r < T; ++r)
      for (int c = 0; c < T; ++c) {
        const Eigen::Vector2d uv = atlas->uv(f, double(c) / (T - 1), double(r) / (T - 1));
        const int x = static_cast<int>(std::floor(uv.x() * W)), y = static_cast<int>(std::floor(uv.y() * H));
        CHECK(x == atlas->texel_x(f, c));
        CHECK(y == atlas->texel_y(f, r));
        CHECK(std::abs(uv.x() * W - x - 0.5) < 1e-9);
        CHECK(std::abs(uv.y() * H - y - 0.5) < 1e-9);
      }
    for (int r = -g; r < T + g; ++r)
      for (int c = -g; c < T + g; ++c)
        for (int ch = 0; ch < 2; ++ch) {
          const int x = atlas->texel_x(f, c), y = atlas->texel_y(f, r);
          REQUIRE(x >= 0);
          REQUIRE(x < W);
          CHECK(image[(static_cast<std::size_t>(H - 1 - y) * W + x) * 2 + ch] == Approx(value(f, r, c, ch)).margin(1e-5));
        }
  }
  // Blocks of quads that do not exist stay 0; the samples read back exactly.
  CHECK(image[(static_cast<std::size_t>(H - 1 - atlas->texel_y(8, 0)) * W + atlas->texel_x(8, 0)) * 2] == 0.0f);
  CHECK(cage_atlas_samples(atlas.value(), image, 2) == values);
}
