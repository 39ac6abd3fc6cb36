// Vertex colours, texture coordinates, normals and materials next to the mesh: hand-written
// OBJ/PLY files with known values, write/read round trips, and the malformed cases.
#include "spherekit/formats/mesh_attributes.h"

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <string>

#include "spherekit/formats/atomic_file.h"
#include "test_meshes.h"
#include "test_paths.h"

namespace {

namespace fs = std::filesystem;
using namespace spherekit;
using namespace spherekit::formats;

std::string put(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

AttributedMesh read_attributed_ok(const std::string& path) {
  auto r = read_mesh_with_attributes(path);
  INFO(r.status().message());
  REQUIRE(r.ok());
  return std::move(r).value();
}

// A unit square split into two triangles; texture seam-free, four vertices.
//   4 --- 3
//   | \   |
//   1 --- 2      (vertex numbers as in the OBJ, 1-based)
const char* kSquareObj =
    "mtllib sq.mtl\n"
    "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 0.5 0.25 1\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "usemtl skin\n"
    "f 1/1 2/2 4/4\nf 2/2/1 3/3/1 4/4/1\n";

}  // namespace

TEST_CASE("OBJ colours, texture coordinates and materials are read", "[formats][attributes]") {
  const std::string dir = spherekit::test::temp_dir("attr_obj_read");
  const AttributedMesh m = read_attributed_ok(put(dir, "sq.obj", kSquareObj));
  REQUIRE(m.mesh.V.rows() == 4);
  REQUIRE(m.attributes.colors.rows() == 4);
  CHECK(m.attributes.colors.row(3) == Eigen::RowVector3d(0.5, 0.25, 1));
  CHECK(m.attributes.colors.row(1) == Eigen::RowVector3d(0, 1, 0));
  REQUIRE(m.attributes.UV.rows() == 4);
  REQUIRE(m.attributes.FT.rows() == 2);
  CHECK(m.attributes.FT.row(1) == Eigen::RowVector3i(1, 2, 3));
  CHECK(m.attributes.UV.row(2) == Eigen::RowVector2d(1, 1));
  REQUIRE(m.attributes.material_libraries.size() == 1);
  CHECK(m.attributes.material_libraries[0] == "sq.mtl");
  CHECK(m.attributes.material == "skin");
  // read_mesh still gives the same geometry and ignores the attributes.
  auto plain = read_mesh(dir + "/sq.obj");
  REQUIRE(plain.ok());
  CHECK(plain->V == m.mesh.V);
  CHECK(plain->F == m.mesh.F);
}

TEST_CASE("OBJ texture indices follow the fan triangulation of polygons", "[formats][attributes]") {
  const std::string dir = spherekit::test::temp_dir("attr_obj_quad");
  // One quad; texture indices deliberately differ from the vertex indices, and a relative one.
  const AttributedMesh m = read_attributed_ok(put(dir, "q.obj",
                                       "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                       "vt 0.1 0.1\nvt 0.9 0.1\nvt 0.9 0.9\nvt 0.1 0.9\nvt 0.5 0.5\n"
                                       "f 1/5 2/1 3/2 4/-2\n"));
  REQUIRE(m.mesh.F.rows() == 2);
  REQUIRE(m.attributes.FT.rows() == 2);
  CHECK(m.attributes.FT.row(0) == Eigen::RowVector3i(4, 0, 1));
  CHECK(m.attributes.FT.row(1) == Eigen::RowVector3i(4, 1, 3));
  CHECK(m.attributes.colors.rows() == 0);
}

TEST_CASE("OBJ without texture indices on every corner has neither UV nor FT", "[formats][attributes]") {
  // Found by the attributes fuzz harness: UV kept without FT were dropped by the writer (a
  // `vt` is reachable only from an `f`), so a round trip changed the attributes.
  const std::string dir = spherekit::test::temp_dir("attr_obj_partial");
  const AttributedMesh m = read_attributed_ok(put(dir, "p.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\n"
                                                     "f 1/1 2/1 3/1\nf 1 3 4\n"));
  CHECK(m.attributes.UV.rows() == 0);
  CHECK(m.attributes.FT.rows() == 0);
  REQUIRE(write_mesh_with_attributes(dir + "/back.obj", m.mesh, m.attributes).ok());
  const AttributedMesh back = read_attributed_ok(dir + "/back.obj");
  CHECK(back.attributes.UV.rows() == 0);
  CHECK(back.mesh.F == m.mesh.F);
}

TEST_CASE("PLY red green blue are read as fractions of their type", "[formats][attributes]") {
  const std::string dir = spherekit::test::temp_dir("attr_ply_read");
  const std::string path = put(dir, "c.ply",
                               "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                               "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
                               "property uchar alpha\nelement face 1\nproperty list uchar int vertex_indices\n"
                               "end_header\n0 0 0 255 0 51 9\n1 0 0 0 255 0 9\n0 1 0 102 102 102 9\n3 0 1 2\n");
  const AttributedMesh m = read_attributed_ok(path);
  REQUIRE(m.attributes.colors.rows() == 3);
  CHECK(m.attributes.colors(0, 0) == 1.0);
  CHECK(m.attributes.colors(0, 2) == Approx(0.2));
  CHECK(m.attributes.colors(2, 1) == Approx(0.4));
  // A PLY with only some of the channels has no colours.
  const AttributedMesh g = read_attributed_ok(put(dir, "g.ply",
                                       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                       "property float z\nproperty uchar red\nelement face 1\n"
                                       "property list uchar int vertex_indices\nend_header\n"
                                       "0 0 0 255\n1 0 0 0\n0 1 0 102\n3 0 1 2\n"));
  CHECK(g.attributes.colors.rows() == 0);
}

TEST_CASE("attributes survive a write/read round trip (OBJ exactly, PLY to 8 bits)", "[formats][attributes]") {
  const std::string dir = spherekit::test::temp_dir("attr_round_trip");
  const TriMesh mesh = spherekit::test::icosphere(2);
  MeshAttributes a;
  a.colors = (mesh.V.array() * 0.5 + 0.5).matrix();
  a.normals = mesh.V.rowwise().normalized();
  a.UV.resize(mesh.V.rows(), 2);
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) a.UV.row(v) << 0.3 * mesh.V(v, 0) + 0.5, 0.2 * mesh.V(v, 1) + 0.5;
  a.FT = mesh.F;
  a.material_libraries = {"ball.mtl"};
  a.material = "ball";
  REQUIRE(write_mesh_with_attributes(dir + "/ball.obj", mesh, a).ok());
  const AttributedMesh back = read_attributed_ok(dir + "/ball.obj");
  CHECK(back.mesh.V == mesh.V);
  CHECK(back.mesh.F == mesh.F);
  CHECK(back.attributes.colors == a.colors);
  CHECK(back.attributes.UV == a.UV);
  CHECK(back.attributes.FT == a.FT);
  CHECK(back.attributes.material == "ball");
  CHECK(back.attributes.material_libraries == a.material_libraries);

  MeshAttributes colors_only;
  colors_only.colors = a.colors;
  for (bool binary : {true, false}) {
    WriteOptions o;
    o.binary = binary;
    REQUIRE(write_mesh_with_attributes(dir + "/ball.ply", mesh, colors_only, o).ok());
    const AttributedMesh p = read_attributed_ok(dir + "/ball.ply");
    REQUIRE(p.attributes.colors.rows() == mesh.V.rows());
    // uchar channels: rounding to the nearest of 256 levels moves a value by at most 1/510.
    CHECK((p.attributes.colors - a.colors).cwiseAbs().maxCoeff() <= 0.5 / 255 + 1e-12);
  }
  // PLY cannot hold texture coordinates: refused, nothing written.
  CHECK(write_mesh_with_attributes(dir + "/uv.ply", mesh, a).code() == ErrorCode::InvalidArgument);
  CHECK_FALSE(fs::exists(dir + "/uv.ply"));
}

TEST_CASE("malformed attributes are refused with the file and line", "[formats][attributes]") {
  const std::string dir = spherekit::test::temp_dir("attr_bad");
  auto fails = [&](const std::string& name, const std::string& text, const std::string& word) {
    const std::string path = put(dir, name, text);
    auto r = read_mesh_with_attributes(path);
    INFO(name << ": " << r.status().message());
    REQUIRE_FALSE(r.ok());
    CHECK(r.status().code() == ErrorCode::ParseError);
    CHECK(r.status().message().rfind(path, 0) == 0);
    CHECK(r.status().message().find(word) != std::string::npos);
  };
  fails("some_colors.obj", "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "have colours");
  fails("bad_vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt x 0\nf 1 2 3\n", "bad number");
  fails("empty_vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt\nf 1 2 3\n", "no value");
  fails("vt_range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/7\n", "out of range");
  fails("vt_zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/0 2/1 3/1\n", "texture index");
  // Fuzz findings: colours and texture coordinates of inf, nan or an overflowing number.
  fails("inf_color.obj", "v 0 0 0 11e308 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\n", ":1: vertex colour is not finite");
  fails("nan_vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt nan 0\nf 1/1 2/1 3/1\n", ":4: texture coordinate is not finite");
  fails("inf_color.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        "property float red\nproperty float green\nproperty float blue\nelement face 1\n"
        "property list uchar int vertex_indices\nend_header\n0 0 0 1 0 0\n1 0 0 0 inf 0\n0 1 0 0 0 1\n3 0 1 2\n",
        "vertex 1 has a non-finite colour");
  // Attribute shapes are checked before writing.
  MeshAttributes wrong;
  wrong.colors = RowMat3d::Zero(2, 3);
  CHECK(write_mesh_with_attributes(dir + "/w.obj", spherekit::test::tetrahedron(), wrong).code() ==
        ErrorCode::InvalidArgument);
  CHECK_FALSE(fs::exists(dir + "/w.obj"));
}

TEST_CASE("MTL files: the maps are read, and written ones read back", "[formats][attributes]") {
  const std::string dir = spherekit::test::temp_dir("attr_mtl");
  const std::string path = put(dir, "m.mtl", "# c\nnewmtl a\nKd 1 1 1\nmap_Kd -s 1 1 1 tex a.png\n"
                                             "newmtl b\nbump -bm 0.5 nb.png\n");
  auto r = read_mtl(path);
  REQUIRE(r.ok());
  REQUIRE(r->size() == 2);
  CHECK((*r)[0].diffuse_map == "a.png");
  CHECK((*r)[1].normal_map == "nb.png");
  REQUIRE(write_file_atomic(dir + "/w.mtl", format_mtl({{"x", "d.png", "n.png"}})).ok());
  auto w = read_mtl(dir + "/w.mtl");
  REQUIRE(w.ok());
  REQUIRE(w->size() == 1);
  CHECK((*w)[0].name == "x");
  CHECK((*w)[0].diffuse_map == "d.png");
  CHECK((*w)[0].normal_map == "n.png");
  auto bad = read_mtl(put(dir, "bad.mtl", "map_Kd a.png\n"));
  REQUIRE_FALSE(bad.ok());
  CHECK(bad.status().code() == ErrorCode::ParseError);
  CHECK(bad.status().message().find("bad.mtl:1:") != std::string::npos);
}
