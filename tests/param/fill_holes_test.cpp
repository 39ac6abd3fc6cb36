// fill_holes: centre-vertex fans close every boundary loop, original elements come first
// and unchanged, fans are oriented with the mesh, and non-simple boundaries are refused.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "spherekit/check_mesh.h"
#include "spherekit/fill_holes.h"
#include "test_meshes.h"
#include "test_paths.h"

using namespace spherekit;

namespace spherekit::test {
// Defined in check_mesh_test.cpp: reads the OBJ/PLY layouts of shared/meshes.
TriMesh read_shared_mesh(const std::string& path);
}  // namespace spherekit::test

namespace {

// The closed result must be one oriented genus-0 sphere with the input as its prefix.
void require_closed_prefix(const TriMesh& open, const FilledMesh& filled) {
  CHECK(filled.original_vertices == open.V.rows());
  CHECK(filled.original_faces == open.F.rows());
  CHECK(filled.mesh.V.rows() == open.V.rows() + filled.holes);
  CHECK(filled.mesh.V.topRows(open.V.rows()) == open.V);
  CHECK(filled.mesh.F.topRows(open.F.rows()) == open.F);
  const MeshCheck c = check_mesh(filled.mesh);
  CHECK(c.boundary_edges == 0);
  CHECK(c.orientation_conflicts == 0);  // fans oriented like their neighbours
  CHECK(c.genus == 0);
  CHECK(require_genus0(c, /*allow_boundary=*/false).ok());
}

}  // namespace

TEST_CASE("fill_holes closes three holes of an icosphere", "[param][holes]") {
  const TriMesh open = test::sphere_with_holes(2, 3);
  auto filled = fill_holes(open);
  REQUIRE(filled.ok());
  CHECK(filled->holes == 3);
  REQUIRE(filled->loops.size() == 3);
  int boundary = 0;
  for (const auto& loop : filled->loops) {
    CHECK(loop.size() == 5);  // each hole is the star of an icosahedron vertex
    boundary += static_cast<int>(loop.size());
  }
  CHECK(filled->mesh.F.rows() == open.F.rows() + boundary);
  require_closed_prefix(open, *filled);
  CHECK_FALSE(filled->is_hole_face(filled->original_faces - 1));
  CHECK(filled->is_hole_face(filled->original_faces));

  // Each hole is a regular pentagon around a removed unit vector, so its centroid lies on
  // that direction: the centres point along the original icosahedron vertices 0, 3, 8.
  const TriMesh sphere = test::icosphere(2);
  std::vector<Eigen::RowVector3d> removed = {sphere.V.row(0), sphere.V.row(3), sphere.V.row(8)};
  for (int h = 0; h < 3; ++h) {
    const Eigen::RowVector3d centre = filled->mesh.V.row(filled->original_vertices + h).normalized();
    double best = 0;
    for (const auto& r : removed) best = std::max(best, centre.dot(r));
    CHECK(best == Approx(1.0).epsilon(1e-12));
  }
}

TEST_CASE("fill_holes orders loops along their faces", "[param][holes]") {
  //  2
  //  | \      one triangle: its boundary 0->1->2 runs along the face; the fan adds
  //  0--1     (1,0,c) (2,1,c) (0,2,c), giving a closed tetrahedron
  TriMesh tri;
  tri.V.resize(3, 3);
  tri.V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  tri.F.resize(1, 3);
  tri.F << 0, 1, 2;
  auto filled = fill_holes(tri);
  REQUIRE(filled.ok());
  REQUIRE(filled->loops.size() == 1);
  CHECK(filled->loops[0] == std::vector<int>{0, 1, 2});
  // Length-weighted centroid of the outline: edge midpoints weighted 1, sqrt2, 1, which
  // gives x = y = 1 / (2 sqrt2) (the vertex average 1/3 would ignore the long edge).
  CHECK(filled->mesh.V(3, 0) == Approx(1 / (2 * std::sqrt(2.0))));
  CHECK(filled->mesh.V(3, 1) == Approx(1 / (2 * std::sqrt(2.0))));
  CHECK(filled->mesh.V(3, 2) == 0);
  RowMat3i want(4, 3);
  want << 0, 1, 2, 1, 0, 3, 2, 1, 3, 0, 2, 3;
  CHECK(filled->mesh.F == want);
  require_closed_prefix(tri, *filled);
}

TEST_CASE("fill_holes returns a closed mesh unchanged", "[param][holes]") {
  const TriMesh m = test::icosphere(1);
  auto filled = fill_holes(m);
  REQUIRE(filled.ok());
  CHECK(filled->holes == 0);
  CHECK(filled->loops.empty());
  CHECK(filled->mesh.F == m.F);
  CHECK(filled->mesh.V == m.V);
}

TEST_CASE("fill_holes refuses boundaries that are not simple loops", "[param][holes]") {
  SECTION("two triangles touching at a vertex") {
    TriMesh bow;
    bow.V.resize(5, 3);
    bow.V << 0, 0, 0, 1, 0, 0, 1, 1, 0, -1, 0, 0, -1, -1, 0;
    bow.F.resize(2, 3);
    bow.F << 0, 1, 2, 0, 3, 4;
    auto r = fill_holes(bow);
    REQUIRE_FALSE(r.ok());
    CHECK(r.status().code() == ErrorCode::InvalidInput);
    CHECK(r.status().message().find("vertex 0 is on the boundary twice") != std::string::npos);
    // After splitting the pinched vertex both triangles close.
    CHECK(repair_pinched_vertices(bow) == 1);
    CHECK(fill_holes(bow).ok());
  }
  SECTION("non-manifold edge") {
    TriMesh fin = test::sphere_with_holes(1, 1);
    fin.V.conservativeResize(fin.V.rows() + 1, 3);
    fin.V.row(fin.V.rows() - 1) << 3, 3, 3;
    fin.F.conservativeResize(fin.F.rows() + 1, 3);
    fin.F.row(fin.F.rows() - 1) << fin.F(0, 0), fin.F(0, 1), static_cast<int>(fin.V.rows()) - 1;
    auto r = fill_holes(fin);
    REQUIRE_FALSE(r.ok());
    CHECK(r.status().message().find("is shared by 3 faces") != std::string::npos);
  }
  SECTION("inconsistent orientation") {
    TriMesh m = test::sphere_with_holes(1, 1);
    std::swap(m.F(3, 1), m.F(3, 2));
    auto r = fill_holes(m);
    REQUIRE_FALSE(r.ok());
    CHECK(r.status().message().find("inconsistently oriented") != std::string::npos);
  }
}

TEST_CASE("fill_holes closes woody and bunny", "[param][holes][shared]") {
  SPHEREKIT_REQUIRE_SHARED_MESHES(dir);
  for (const auto& [file, holes] : std::vector<std::pair<std::string, int>>{{"woody.obj", 1}, {"bunny.obj", 5}}) {
    INFO(file);
    const TriMesh open = test::read_shared_mesh(dir + "/" + file);
    REQUIRE(open.F.rows() > 0);
    const MeshCheck before = check_mesh(open);
    auto filled = fill_holes(open);
    REQUIRE(filled.ok());
    CHECK(filled->holes == holes);
    CHECK(filled->mesh.F.rows() == open.F.rows() + before.boundary_edges);
    require_closed_prefix(open, *filled);
  }
}
