// Polygon faces: triangulate_polygon on convex, non-convex and non-planar polygons (no folded
// triangle, the polygon's area exactly covered), and the readers on a mixed triangle / quad /
// n-gon mesh (same triangles from OBJ, OFF and PLY, every triangle's source polygon recorded).
#include "spherekit/formats/polygon_triangulation.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "spherekit/check_mesh.h"
#include "spherekit/formats/mesh_attributes.h"
#include "spherekit/formats/mesh_io.h"
#include "test_meshes.h"
#include "test_paths.h"

namespace {

using namespace spherekit;
using namespace spherekit::formats;
using Points = std::vector<Eigen::Vector3d>;
using Triangles = std::vector<std::array<std::uint32_t, 3>>;
constexpr double kPi = 3.14159265358979323846;

std::string write_text(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

/// Newell's normal (twice the vector area) of a polygon, about its first corner (precise far
/// from the origin).
Eigen::Vector3d vector_area(const Points& p) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (std::size_t i = 1; i + 1 < p.size(); ++i) n += (p[i] - p[0]).cross(p[i + 1] - p[0]);
  return n;
}

Eigen::Vector3d triangle_normal(const Points& p, const std::array<std::uint32_t, 3>& t) {
  return (p[t[1]] - p[t[0]]).cross(p[t[2]] - p[t[0]]);
}

/// The contract on any simple polygon: n - 2 triangles with corners in range, each facing the
/// polygon's side of its best-fit plane (none folded), and together exactly the polygon's
/// area in that plane (no overlap, nothing missing).
void require_valid(const Points& p, const Triangles& tris) {
  REQUIRE(tris.size() == p.size() - 2);
  const Eigen::Vector3d n = vector_area(p).normalized();
  double projected = 0;
  for (const auto& t : tris) {
    for (std::uint32_t c : t) REQUIRE(c < p.size());
    const double a = triangle_normal(p, t).dot(n);
    CHECK(a > 0);
    projected += a;
  }
  CHECK(projected == Approx(vector_area(p).norm()).epsilon(1e-12));
}

Triangles fan(std::size_t n) {
  Triangles t;
  for (std::uint32_t i = 1; i + 1 < n; ++i) t.push_back({0, i, i + 1});
  return t;
}

Points star(int points, double inner, Eigen::Vector3d offset = Eigen::Vector3d::Zero()) {
  Points p;
  for (int i = 0; i < 2 * points; ++i) {
    const double r = i % 2 == 0 ? 1.0 : inner, a = kPi * i / points;
    p.push_back(offset + Eigen::Vector3d(r * std::cos(a), r * std::sin(a), 0));
  }
  return p;
}

}  // namespace

TEST_CASE("triangulate_polygon: convex polygons", "[formats]") {
  for (int n = 3; n <= 40; ++n) {
    INFO("n = " << n);
    Points p;
    for (int i = 0; i < n; ++i) p.emplace_back(std::cos(2 * kPi * i / n), std::sin(2 * kPi * i / n), 0.0);
    Triangles tris;
    triangulate_polygon(p, tris);
    require_valid(p, tris);
  }
}

TEST_CASE("triangulate_polygon: non-convex polygons are not folded", "[formats]") {
  SECTION("a star, far from the origin") {
    const Points p = star(6, 0.4, Eigen::Vector3d(1e6, -2e6, 3e5));
    Triangles tris;
    triangulate_polygon(p, tris);
    require_valid(p, tris);
    // The test can fail: a fan of the same star folds.
    const Eigen::Vector3d n = vector_area(p);
    int folded = 0;
    for (const auto& t : fan(p.size())) folded += triangle_normal(p, t).dot(n) <= 0;
    CHECK(folded > 0);
  }
  SECTION("a comb (many reflex corners)") {
    Points comb = {{0, 0, 0}, {15, 0, 0}, {15, 5, 0}};
    for (int i = 7; i >= 1; --i) {
      comb.emplace_back(2.0 * i, 5, 0);
      comb.emplace_back(2.0 * i, 1, 0);
      comb.emplace_back(2.0 * i - 1, 1, 0);
      comb.emplace_back(2.0 * i - 1, 5, 0);
    }
    comb.emplace_back(0, 5, 0);
    Triangles tris;
    triangulate_polygon(comb, tris);
    require_valid(comb, tris);
  }
  SECTION("a dart quad: only one diagonal is inside") {
    for (int reflex = 0; reflex < 4; ++reflex) {
      Points p = {{0, 0, 0}, {2, 1, 0}, {0, 2, 0}, {0.7, 1, 0}};  // corner 3 is reflex
      std::rotate(p.begin(), p.begin() + reflex, p.end());
      Triangles tris;
      triangulate_polygon(p, tris);
      require_valid(p, tris);
    }
  }
  SECTION("a polygon with more corners than kBestEarCorners (first ear)") {
    const Points p = star(static_cast<int>(kBestEarCorners), 0.8);
    Triangles tris;
    triangulate_polygon(p, tris);
    require_valid(p, tris);
  }
}

TEST_CASE("triangulate_polygon: non-planar polygons, shorter quad diagonal", "[formats]") {
  // Non-planar convex quads: both diagonals keep the triangles facing up; the shorter is chosen.
  for (double lift : {0.3, -0.3}) {
    const Points short02 = {{0, 0, 0}, {3, 0, lift}, {1, 1, 0}, {0, 1, lift}};
    const Points short13 = {{0, 0, 0}, {1, 0, lift}, {3, 1, 0}, {0, 1, lift}};
    Triangles a, b;
    triangulate_polygon(short02, a);
    triangulate_polygon(short13, b);
    require_valid(short02, a);
    require_valid(short13, b);
    CHECK(a == Triangles{{0, 1, 2}, {0, 2, 3}});
    CHECK(b == Triangles{{0, 1, 3}, {1, 2, 3}});
  }
  // A non-planar hexagon (a ring with alternating heights): still n - 2 unfolded triangles.
  Points hex;
  for (int i = 0; i < 6; ++i) hex.emplace_back(std::cos(kPi * i / 3), std::sin(kPi * i / 3), i % 2 ? 0.4 : -0.4);
  Triangles tris;
  triangulate_polygon(hex, tris);
  REQUIRE(tris.size() == 4);
  const Eigen::Vector3d n = vector_area(hex);
  for (const auto& t : tris) CHECK(triangle_normal(hex, t).dot(n) > 0);
}

TEST_CASE("triangulate_polygon: degenerate polygons still give n - 2 triangles", "[formats]") {
  const std::vector<Points> cases = {
      {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {4, 0, 0}},                // collinear
      {{0, 0, 0}, {1, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}},                // repeated corner
      {{0, 0, 0}, {2, 2, 0}, {2, 0, 0}, {0, 2, 0}, {1, 3, 0}, {-1, 1, 0}},    // self-intersecting
      {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}},     // one point
  };
  for (const Points& p : cases) {
    Triangles tris;
    triangulate_polygon(p, tris);
    REQUIRE(tris.size() == p.size() - 2);
    // Every corner index in range and each triangle made of three distinct corners.
    for (const auto& t : tris) {
      for (std::uint32_t c : t) CHECK(c < p.size());
      CHECK((t[0] != t[1] && t[1] != t[2] && t[0] != t[2]));
    }
  }
}

TEST_CASE("readers: a mixed triangle, quad and n-gon mesh from OBJ, OFF and PLY", "[formats]") {
  const std::string dir = test::temp_dir("formats_mixed_polygons");
  const test::PolygonMesh poly = test::star_prism_polygons();
  std::vector<TriMesh> meshes;
  for (const std::string format : {"obj", "off", "ply"}) {
    INFO("format " << format);
    const std::string path = write_text(dir, "star." + format, test::polygon_mesh_text(poly, format));
    ReadInfo info;
    Result<TriMesh> r = read_mesh(path, {}, &info);
    INFO(r.status().message());
    REQUIRE(r.ok());
    const TriMesh& m = r.value();
    CHECK(info.faces.faces == 25);
    CHECK(info.faces.triangles == 11);
    CHECK(info.faces.quads == 12);
    CHECK(info.faces.ngons == 2);
    CHECK(info.polygons_triangulated == 14);
    REQUIRE(m.F.rows() == 48);
    REQUIRE(info.face_polygon.size() == 48);
    // Every triangle is made of its source polygon's corners, faces the polygon's way, and
    // each polygon of n corners gives n - 2 triangles.
    std::map<int, int> per_polygon;
    for (Eigen::Index t = 0; t < m.F.rows(); ++t) {
      const int f = info.face_polygon[static_cast<std::size_t>(t)];
      REQUIRE(f >= 0);
      REQUIRE(f < 25);
      ++per_polygon[f];
      const std::vector<int>& corners = poly.faces[static_cast<std::size_t>(f)];
      Points pts;
      for (int c : corners) pts.push_back(poly.V.row(c).transpose());
      const Eigen::Vector3d n = vector_area(pts);
      for (int k = 0; k < 3; ++k) CHECK(std::find(corners.begin(), corners.end(), m.F(t, k)) != corners.end());
      const Eigen::Vector3d a = m.V.row(m.F(t, 0)), b = m.V.row(m.F(t, 1)), c = m.V.row(m.F(t, 2));
      CHECK((b - a).cross(c - a).dot(n) > 0);
    }
    for (const auto& [f, count] : per_polygon) CHECK(count == static_cast<int>(poly.faces[static_cast<std::size_t>(f)].size()) - 2);
    const MeshCheck c = check_mesh(m);
    CHECK(c.genus0_ok());
    CHECK(c.boundary_loops == 0);
    CHECK(require_genus0(c).ok());
    meshes.push_back(m);
  }
  CHECK(meshes[0].F == meshes[1].F);
  CHECK(meshes[0].F == meshes[2].F);

  // The policies: TriangulateUniform refuses the mix, Reject any polygon.
  const std::string obj = dir + "/star.obj";
  Result<TriMesh> uniform = read_mesh(obj, ReadOptions{PolygonPolicy::TriangulateUniform});
  REQUIRE_FALSE(uniform.ok());
  CHECK(uniform.status().message().find("mixed") != std::string::npos);
  CHECK_FALSE(read_mesh(obj, ReadOptions{PolygonPolicy::Reject}).ok());
}

TEST_CASE("OBJ reader: texture coordinates follow the polygon triangulation", "[formats]") {
  // A non-convex pentagon (a house shape pushed in at the roof) with texture coordinates equal
  // to the positions' x, y: every triangle corner's UV must be its vertex's x, y.
  const std::string dir = test::temp_dir("formats_polygon_uv");
  const std::string path = write_text(dir, "dent.obj",
                                      "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 1 0.5 0\nv 0 2 0\n"
                                      "vt 0 0\nvt 2 0\nvt 2 2\nvt 1 0.5\nvt 0 2\n"
                                      "f 1/1 2/2 3/3 4/4 5/5\n");
  Result<AttributedMesh> r = read_mesh_with_attributes(path);
  INFO(r.status().message());
  REQUIRE(r.ok());
  const TriMesh& m = r->mesh;
  const MeshAttributes& a = r->attributes;
  REQUIRE(m.F.rows() == 3);
  REQUIRE(a.FT.rows() == 3);
  for (Eigen::Index t = 0; t < 3; ++t) {
    for (int k = 0; k < 3; ++k) {
      CHECK(a.UV(a.FT(t, k), 0) == m.V(m.F(t, k), 0));
      CHECK(a.UV(a.FT(t, k), 1) == m.V(m.F(t, k), 1));
    }
    const Eigen::Vector3d p = m.V.row(m.F(t, 0)), q = m.V.row(m.F(t, 1)), s = m.V.row(m.F(t, 2));
    CHECK((q - p).cross(s - p).z() > 0);  // none folded (a fan from corner 0 or 1 would fold)
  }
}
