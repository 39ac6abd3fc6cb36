// check_mesh / require_genus0 / repair_pinched_vertices: exact counts on hand-made meshes,
// one test per refusal message, and agreement with shared/meshes/manifest.json (the
// independent checker's results) on every shared mesh.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "spherekit/check_mesh.h"
#include "spherekit/sphere_param.h"
#include "test_meshes.h"
#include "test_paths.h"

using namespace spherekit;

namespace spherekit::test {

// Minimal reader for the shared meshes (OBJ `v`/`f` triangles, binary little-endian PLY
// with float xyz and uchar/int faces: exactly the two layouts shared/meshes uses), so
// these tests do not depend on the formats library. Also used by fill_holes_test.cpp.
TriMesh read_shared_mesh(const std::string& path) {
  std::vector<double> v;
  std::vector<int> f;
  if (path.size() > 4 && path.compare(path.size() - 4, 4, ".ply") == 0) {
    std::ifstream in(path, std::ios::binary);
    std::string line;
    long nv = 0, nf = 0;
    while (std::getline(in, line) && line.rfind("end_header", 0) != 0) {
      if (line.rfind("element vertex ", 0) == 0) nv = std::stol(line.substr(15));
      if (line.rfind("element face ", 0) == 0) nf = std::stol(line.substr(13));
    }
    for (long i = 0; i < nv; ++i) {
      float p[3];
      in.read(reinterpret_cast<char*>(p), sizeof p);
      v.insert(v.end(), {p[0], p[1], p[2]});
    }
    for (long i = 0; i < nf; ++i) {
      unsigned char n = 0;
      std::int32_t idx[3];
      in.read(reinterpret_cast<char*>(&n), 1);
      in.read(reinterpret_cast<char*>(idx), sizeof idx);
      f.insert(f.end(), {idx[0], idx[1], idx[2]});
    }
  } else {
    std::ifstream in(path);
    std::string line;
    while (std::getline(in, line)) {
      double a, b, c;
      int i, j, k;
      if (std::sscanf(line.c_str(), "v %lf %lf %lf", &a, &b, &c) == 3) v.insert(v.end(), {a, b, c});
      if (std::sscanf(line.c_str(), "f %d %d %d", &i, &j, &k) == 3) f.insert(f.end(), {i - 1, j - 1, k - 1});
    }
  }
  TriMesh m;
  m.V = Eigen::Map<RowMat3d>(v.data(), static_cast<Eigen::Index>(v.size() / 3), 3);
  m.F = Eigen::Map<RowMat3i>(f.data(), static_cast<Eigen::Index>(f.size() / 3), 3);
  return m;
}

}  // namespace spherekit::test

namespace {

TriMesh with_face(TriMesh m, int a, int b, int c) {
  m.F.conservativeResize(m.F.rows() + 1, 3);
  m.F.row(m.F.rows() - 1) << a, b, c;
  return m;
}

std::string refusal(const TriMesh& m, bool allow_boundary = true) {
  const Status s = require_genus0(check_mesh(m), allow_boundary);
  if (s.ok()) return "";
  CHECK(s.code() == ErrorCode::InvalidInput);
  CHECK(s.message().find('\n') == std::string::npos);  // one line
  return s.message();
}

// A sphere where two far-apart vertices are identified: one component, one pinched vertex.
TriMesh sphere_with_identified_vertices() {
  TriMesh m = test::icosphere(2);
  // Vertices 0 and 3 are antipodal icosahedron vertices, so their stars share nothing.
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (m.F(f, k) == 3) m.F(f, k) = 0;
  // Drop the now unused vertex 3 by moving the last vertex into its slot.
  const int last = static_cast<int>(m.V.rows()) - 1;
  m.V.row(3) = m.V.row(last);
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (m.F(f, k) == last) m.F(f, k) = 3;
  m.V.conservativeResize(last, 3);
  return m;
}

// Moebius strip: n quads around a loop, the last one glued back with a half twist.
//   top    0 --- 1 --- ... --- n-1 --(twist)-- bottom 0
//   bottom n --- n+1 - ... --- 2n-1 --(twist)-- top 0
TriMesh moebius_strip(int n) {
  TriMesh m;
  m.V.resize(2 * n, 3);
  for (int i = 0; i < n; ++i) {
    const double t = 2 * M_PI * i / n, w = 0.3 * std::cos(t / 2), h = 0.3 * std::sin(t / 2);
    m.V.row(i) << (1 + w) * std::cos(t), (1 + w) * std::sin(t), h;
    m.V.row(n + i) << (1 - w) * std::cos(t), (1 - w) * std::sin(t), -h;
  }
  m.F.resize(2 * n, 3);
  for (int i = 0; i < n; ++i) {
    const int a = i, b = n + i;
    const int c = i + 1 < n ? i + 1 : n, d = i + 1 < n ? n + i + 1 : 0;  // twist at the seam
    m.F.row(2 * i) << a, b, d;
    m.F.row(2 * i + 1) << a, d, c;
  }
  return m;
}

}  // namespace

TEST_CASE("check_mesh counts a tetrahedron exactly", "[param][check]") {
  //      0
  //     /|\      4 vertices, 6 edges, 4 faces: Euler 2, genus 0, closed
  //    1-+-2
  //     \|/
  //      3
  const MeshCheck c = check_mesh(test::tetrahedron());
  CHECK(c.vertices == 4);
  CHECK(c.faces == 4);
  CHECK(c.edges == 6);
  CHECK(c.boundary_edges == 0);
  CHECK(c.boundary_loops == 0);
  CHECK(c.nonmanifold_edges == 0);
  CHECK(c.nonmanifold_vertices == 0);
  CHECK(c.orientation_conflicts == 0);
  CHECK(c.components == 1);
  CHECK(c.euler == 2);
  CHECK(c.genus == 0);
  CHECK(c.orientable);
  CHECK(c.bbox_diag == Approx(2.0));  // cube [-1/sqrt3, 1/sqrt3]^3
  CHECK(c.genus0_ok());
  CHECK(require_genus0(c, false).ok());
}

TEST_CASE("check_mesh accepts closed spheres of every size", "[param][check]") {
  for (const TriMesh& m : {test::octahedron(), test::icosphere(0), test::icosphere(3), test::random_blob(2, 7)}) {
    const MeshCheck c = check_mesh(m);
    CHECK(c.euler == 2);
    CHECK(c.genus == 0);
    CHECK(c.edges == 3 * c.faces / 2);
    CHECK(c.zero_area_faces == 0);
    CHECK(c.genus0_ok());
  }
}

TEST_CASE("require_genus0 names the genus of a torus", "[param][check]") {
  const MeshCheck c = check_mesh(test::torus());
  CHECK(c.euler == 0);
  CHECK(c.genus == 1);
  CHECK_FALSE(c.genus0_ok());
  CHECK(refusal(test::torus()) ==
        "mesh has genus 1 (Euler characteristic 0, 0 boundary loops); only genus-0 surfaces can be mapped to the "
        "sphere");
}

TEST_CASE("require_genus0 refuses several components", "[param][check]") {
  const MeshCheck c = check_mesh(test::two_tetrahedra());
  CHECK(c.components == 2);
  CHECK(c.euler == 4);
  CHECK(c.genus == -1);
  CHECK(refusal(test::two_tetrahedra()) == "mesh has 2 connected components; split it or pass one component");
}

TEST_CASE("pinched tetrahedra: one non-manifold vertex, two components after repair", "[param][check]") {
  TriMesh m = test::pinched_tetrahedra();
  MeshCheck c = check_mesh(m);
  CHECK(c.nonmanifold_vertices == 1);
  REQUIRE(c.nonmanifold_vertex_ids == std::vector<int>{0});
  CHECK(c.nonmanifold_vertex_fans == std::vector<int>{2});
  CHECK(c.nonmanifold_edges == 0);
  CHECK(c.components == 1);  // connected through the shared vertex
  CHECK(c.euler == 3);       // 7 - 12 + 8
  CHECK(c.genus == -1);
  CHECK(refusal(m) ==
        "vertex 0 is non-manifold (2 face fans meet there; 1 such vertex); run `spherekit check --repair`");

  std::vector<int> new_to_old;
  CHECK(repair_pinched_vertices(m, &new_to_old) == 1);
  CHECK(new_to_old == std::vector<int>{0});
  REQUIRE(m.V.rows() == 8);
  CHECK(m.V.row(7) == m.V.row(0));
  // The first fan (faces 0-3) keeps vertex 0, the second tetrahedron gets vertex 7.
  CHECK(m.F.topRows(4) == test::pinched_tetrahedra().F.topRows(4));
  c = check_mesh(m);
  CHECK(c.nonmanifold_vertices == 0);
  CHECK(c.components == 2);  // what is true: two separate closed tetrahedra
  CHECK(c.euler == 4);
  CHECK(c.genus == -1);      // genus is defined per single component only
  CHECK(refusal(m) == "mesh has 2 connected components; split it or pass one component");
}

TEST_CASE("repairing a sphere with two identified vertices gives a genus-0 sphere", "[param][check]") {
  TriMesh m = sphere_with_identified_vertices();
  MeshCheck c = check_mesh(m);
  CHECK(c.components == 1);
  CHECK(c.nonmanifold_vertices == 1);
  CHECK(c.nonmanifold_vertex_ids == std::vector<int>{0});
  CHECK(c.euler == 1);
  CHECK(c.genus == -1);
  const int nv = static_cast<int>(m.V.rows());
  CHECK(repair_pinched_vertices(m) == 1);
  CHECK(m.V.rows() == nv + 1);
  c = check_mesh(m);
  CHECK(c.nonmanifold_vertices == 0);
  CHECK(c.components == 1);
  CHECK(c.euler == 2);
  CHECK(c.genus == 0);
  CHECK(c.genus0_ok());
  // A manifold mesh is left alone.
  const TriMesh before = m;
  CHECK(repair_pinched_vertices(m) == 0);
  CHECK(m.F == before.F);
  CHECK(m.V.rows() == before.V.rows());
}

TEST_CASE("require_genus0 names the first blocking problem", "[param][check]") {
  const TriMesh tet = test::tetrahedron();

  SECTION("NaN coordinate") {
    TriMesh m = tet;
    m.V(2, 1) = std::numeric_limits<double>::quiet_NaN();
    const MeshCheck c = check_mesh(m);
    CHECK(c.nonfinite_vertices == 1);
    CHECK(c.zero_area_faces == 0);  // non-finite faces are not also zero-area
    CHECK(refusal(m) == "vertex 2 has a NaN/Inf coordinate (1 such vertex)");
  }
  SECTION("index out of range") {
    TriMesh m = tet;
    m.F(1, 2) = 9;
    const MeshCheck c = check_mesh(m);
    CHECK(c.invalid_indices == 1);
    CHECK(c.faces == 4);
    CHECK(c.edges == 6);  // the three remaining faces
    CHECK(refusal(m) == "face 1 has vertex index 9 outside [0, 4) (1 invalid index)");
  }
  SECTION("degenerate face") {
    const TriMesh m = with_face(tet, 0, 0, 1);
    const MeshCheck c = check_mesh(m);
    CHECK(c.degenerate_faces == 1);
    CHECK(c.edges == 6);
    CHECK(c.euler == 2);
    CHECK(refusal(m) == "face 4 repeats a vertex (degenerate; 1 such face); remove degenerate faces");
  }
  SECTION("duplicate face") {
    const TriMesh m = with_face(tet, tet.F(0, 1), tet.F(0, 2), tet.F(0, 0));
    const MeshCheck c = check_mesh(m);
    CHECK(c.duplicate_faces == 1);
    CHECK(c.nonmanifold_edges == 3);  // a consequence, not the cause, so not named
    CHECK(refusal(m) == "face 4 has the same vertices as face 0 (1 duplicate face); remove duplicates");
  }
  SECTION("non-manifold edge") {
    TriMesh m = tet;
    m.V.conservativeResize(5, 3);
    m.V.row(4) << 2, 2, 2;
    m = with_face(m, 1, 0, 4);  // a fin on edge (0,1)
    const MeshCheck c = check_mesh(m);
    CHECK(c.nonmanifold_edges == 1);
    CHECK(c.nonmanifold_edge_ids == std::vector<int>{0, 1});
    CHECK(c.nonmanifold_edge_face_counts == std::vector<int>{3});
    CHECK(c.genus == -1);
    CHECK(refusal(m) == "edge (0,1) is shared by 3 faces (non-manifold; 1 such edge)");
  }
  SECTION("unreferenced vertex") {
    TriMesh m = tet;
    m.V.conservativeResize(5, 3);
    m.V.row(4) << 5, 5, 5;
    const MeshCheck c = check_mesh(m);
    CHECK(c.unreferenced_vertices == 1);
    CHECK(c.bbox_diag == Approx(2.0));  // unreferenced vertices do not count
    CHECK(c.genus == 0);
    CHECK(refusal(m) ==
          "vertex 4 is used by no face (1 unreferenced vertex); a sphere map needs every vertex on the surface: drop "
          "them with `spherekit check MESH --repair -o OUT` (vertex numbers change: remap landmark files)");
  }
  SECTION("one face flipped") {
    TriMesh m = test::icosphere(1);
    std::swap(m.F(5, 1), m.F(5, 2));
    const MeshCheck c = check_mesh(m);
    CHECK(c.orientation_conflicts == 3);
    CHECK(c.orientable);
    CHECK(c.genus == 0);
    CHECK(refusal(m).rfind("faces are inconsistently oriented (3 edges used twice in the same direction, first (", 0) ==
          0);
  }
  SECTION("Moebius strip") {
    const TriMesh m = moebius_strip(12);
    const MeshCheck c = check_mesh(m);
    CHECK_FALSE(c.orientable);
    CHECK(c.boundary_loops == 1);  // the strip's boundary is a single circle
    CHECK(c.genus == -1);
    CHECK(refusal(m) == "mesh is not orientable (like a Moebius strip); no consistent face orientation exists");
  }
  SECTION("empty mesh") {
    CHECK(refusal(TriMesh{}) == "mesh has no faces");
    const MeshCheck c = check_mesh(TriMesh{});
    CHECK(c.bbox_diag == 0);
    CHECK(c.components == 0);
  }
}

TEST_CASE("zero-area faces are reported but not refused", "[param][check]") {
  TriMesh m = test::tetrahedron();
  m.V.row(3) = 0.5 * (m.V.row(0) + m.V.row(1));  // face (0,3,1) becomes a segment
  const MeshCheck c = check_mesh(m);
  CHECK(c.zero_area_faces == 1);
  CHECK(c.first_zero_area_face == 1);
  CHECK(c.degenerate_faces == 0);
  CHECK(c.genus0_ok());
  // Relative tolerance: the same shape in other units gives the same verdict.
  m.V *= 1e-6;
  CHECK(check_mesh(m).zero_area_faces == 1);
  m.V *= 1e12;
  CHECK(check_mesh(m).zero_area_faces == 1);
}

TEST_CASE("boundary loops and allow_boundary", "[param][check]") {
  const TriMesh m = test::sphere_with_holes(2, 3);
  const MeshCheck c = check_mesh(m);
  CHECK(c.boundary_loops == 3);
  CHECK(c.boundary_edges == 15);  // three pentagonal holes
  CHECK(c.euler == -1);
  CHECK(c.genus == 0);
  CHECK(c.genus0_ok());
  CHECK(refusal(m, true).empty());
  CHECK(refusal(m, false) == "mesh has 3 boundary loops (holes); close them first (fill_holes)");

  // Two triangles touching at one vertex: one component, two fans, and two loops (each
  // traced within its own fan) rather than one figure-eight.
  TriMesh bow;
  bow.V.resize(5, 3);
  bow.V << 0, 0, 0, 1, 0, 0, 1, 1, 0, -1, 0, 0, -1, -1, 0;
  bow.F.resize(2, 3);
  bow.F << 0, 1, 2, 0, 3, 4;
  const MeshCheck b = check_mesh(bow);
  CHECK(b.components == 1);
  CHECK(b.nonmanifold_vertices == 1);
  CHECK(b.boundary_loops == 2);
}

TEST_CASE("check_mesh matches manifest.json on every shared mesh", "[param][check][shared]") {
  SPHEREKIT_REQUIRE_SHARED_MESHES(dir);
  std::ifstream in(dir + "/manifest.json");
  REQUIRE(in);
  const auto manifest = nlohmann::json::parse(in);
  for (const auto& entry : manifest) {
    const std::string file = entry["file"];
    INFO(file);
    const TriMesh m = test::read_shared_mesh(dir + "/" + file);
    const auto& want = entry["check"];
    REQUIRE(m.F.rows() == want["F"].get<int>());
    // (Speed is measured by `spherekit bench`, not asserted in tests.)
    const MeshCheck c = check_mesh(m);
    CHECK(c.vertices == want["V"].get<int>());
    CHECK(c.edges == want["edges"].get<int>());
    CHECK(c.unreferenced_vertices == want["unreferenced_vertices"].get<int>());
    CHECK(c.degenerate_faces == want["degenerate_faces"].get<int>());
    CHECK(c.duplicate_faces == want["duplicate_faces"].get<int>());
    CHECK(c.zero_area_faces == want["zero_area_faces"].get<int>());
    CHECK(c.boundary_edges == want["boundary_edges"].get<int>());
    CHECK(c.nonmanifold_edges == want["nonmanifold_edges"].get<int>());
    CHECK(c.orientation_conflicts == want["orientation_conflicts"].get<int>());
    CHECK(c.boundary_loops == want["boundary_loops"].get<int>());
    CHECK(c.components == want["components"].get<int>());
    CHECK(c.nonmanifold_vertices == want["nonmanifold_vertices"].get<int>());
    CHECK(c.orientable == want["orientable"].get<bool>());
    CHECK(c.euler == want["euler"].get<int>());
    CHECK(c.genus == want["genus"].get<int>());
    CHECK(c.bbox_diag == Approx(want["bbox_diag"].get<double>()).epsilon(1e-5));
    CHECK(c.genus0_ok() == want["genus0_ok"].get<bool>());
  }
}

TEST_CASE("require_param_accepts: one verdict for the stages and the command line", "[param][check]") {
  TriMesh m = test::octahedron();
  CHECK(require_param_accepts(m, check_mesh(m)).ok());
  struct Case {
    double scale;
    const char* problem;
  };
  for (const Case c : {Case{1e300, "coordinates reach 1e+300"}, Case{1e-60, "below the supported 1e-50"},
                       Case{0.0, "all vertices are at one point"}}) {
    INFO("scale " << c.scale);
    TriMesh scaled = m;
    scaled.V *= c.scale;
    const Status verdict = require_param_accepts(scaled, check_mesh(scaled));
    REQUIRE(verdict.code() == ErrorCode::InvalidInput);
    CHECK(verdict.message().find(c.problem) != std::string::npos);
    // The stage refuses with the same verdict (not NaN measures).
    auto mapped = parameterize_sphere(scaled, SphereParamOptions{});
    REQUIRE_FALSE(mapped.ok());
    CHECK(mapped.status().message() == verdict.message());
  }
  // Topology first: a torus is refused for its genus whatever its size.
  TriMesh torus = test::torus();
  torus.V *= 1e300;
  CHECK(require_param_accepts(torus, check_mesh(torus)).message() == require_genus0(check_mesh(torus)).message());
}

TEST_CASE("remove_unreferenced_vertices drops unused vertices and renumbers faces", "[param]") {
  // An icosphere with unused vertices put before, between and after the used ones.
  const TriMesh sphere = test::icosphere(1);
  const int nv = static_cast<int>(sphere.V.rows());
  TriMesh m;
  m.V.resize(nv + 3, 3);
  std::vector<int> placed(static_cast<std::size_t>(nv));
  int row = 0;
  m.V.row(row++) << 9, 9, 9;  // unused, first
  for (int v = 0; v < nv; ++v) {
    if (v == nv / 2) m.V.row(row++) << -9, 9, 9;  // unused, in the middle
    placed[static_cast<std::size_t>(v)] = row;
    m.V.row(row++) = sphere.V.row(v);
  }
  m.V.row(row++) << 9, -9, 9;  // unused, last
  m.F = sphere.F;
  for (Eigen::Index i = 0; i < m.F.size(); ++i) m.F.data()[i] = placed[static_cast<std::size_t>(m.F.data()[i])];
  REQUIRE(check_mesh(m).unreferenced_vertices == 3);
  CHECK(!require_genus0(check_mesh(m)).ok());

  std::vector<int> old_to_new;
  CHECK(remove_unreferenced_vertices(m, &old_to_new) == 3);
  CHECK(m.V == sphere.V);  // order kept
  CHECK(m.F == sphere.F);
  REQUIRE(old_to_new.size() == static_cast<std::size_t>(nv + 3));
  CHECK(old_to_new.front() == -1);
  CHECK(old_to_new.back() == -1);
  CHECK(old_to_new[static_cast<std::size_t>(nv / 2 + 1)] == -1);
  for (int v = 0; v < nv; ++v) CHECK(old_to_new[static_cast<std::size_t>(placed[static_cast<std::size_t>(v)])] == v);
  CHECK(require_genus0(check_mesh(m)).ok());

  // Nothing to drop: unchanged, identity map.
  CHECK(remove_unreferenced_vertices(m, &old_to_new) == 0);
  CHECK(m.V == sphere.V);
  CHECK(old_to_new[5] == 5);

  // An index out of range: left alone.
  TriMesh bad = m;
  bad.V.conservativeResize(nv + 1, 3);
  bad.V.row(nv) << 1, 2, 3;
  bad.F(0, 0) = nv + 7;
  const TriMesh before = bad;
  CHECK(remove_unreferenced_vertices(bad) == 0);
  CHECK(bad.V == before.V);
  CHECK(bad.F == before.F);
}
