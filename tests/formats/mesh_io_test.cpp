// Mesh readers and writers: round trips, every format on small hand-written files, the error
// path of each malformed input, robustness against corrupted files, and the shared meshes.
#include "spherekit/formats/mesh_io.h"

#include <algorithm>
#include <bit>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "test_meshes.h"
#include "test_paths.h"

namespace {

namespace fs = std::filesystem;
using namespace spherekit;
using namespace spherekit::formats;
using nlohmann::json;

std::string write_file(const std::string& dir, const std::string& name, const std::string& bytes) {
  const std::string path = dir + "/" + name;
  // Replace rather than truncate: ext4 flushes a truncated-and-rewritten file on close, which
  // makes thousands of rewrites (the robustness test) take seconds instead of milliseconds.
  std::error_code ec;
  fs::remove(path, ec);
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

/// An error must have the expected code and be one line that starts with the path and
/// names the problem.
void check_error(const Status& s, ErrorCode code, const std::string& path, const std::string& word) {
  INFO("message: " << s.message());
  REQUIRE_FALSE(s.ok());
  CHECK(s.code() == code);
  CHECK(s.message().rfind(path, 0) == 0);
  CHECK(s.message().find(fs::path(path).filename().string()) != std::string::npos);
  CHECK(s.message().find(word) != std::string::npos);
  CHECK(s.message().find('\n') == std::string::npos);
}

void check_read_error(const std::string& path, ErrorCode code, const std::string& word,
                      const ReadOptions& options = {}) {
  Result<TriMesh> r = read_mesh(path, options);
  REQUIRE_FALSE(r.ok());
  check_error(r.status(), code, path, word);
}

TriMesh read_ok(const std::string& path, const ReadOptions& options = {}, ReadInfo* info = nullptr) {
  Result<TriMesh> r = read_mesh(path, options, info);
  INFO(r.status().message());
  REQUIRE(r.ok());
  return std::move(r).value();
}

RowMat3i faces(std::initializer_list<std::array<int, 3>> rows) {
  RowMat3i F(static_cast<Eigen::Index>(rows.size()), 3);
  Eigen::Index i = 0;
  for (const auto& r : rows) F.row(i++) << r[0], r[1], r[2];
  return F;
}

/// Appends `value` converted to the PLY type `type` in the given byte order.
void put(std::string& out, const std::string& type, double value, bool big_endian) {
  auto raw = [&](auto v) {
    char b[sizeof v];
    std::memcpy(b, &v, sizeof v);
    if (big_endian != (std::endian::native == std::endian::big)) std::reverse(b, b + sizeof v);
    out.append(b, sizeof v);
  };
  if (type == "char") raw(static_cast<std::int8_t>(value));
  else if (type == "uchar") raw(static_cast<std::uint8_t>(value));
  else if (type == "short") raw(static_cast<std::int16_t>(value));
  else if (type == "ushort") raw(static_cast<std::uint16_t>(value));
  else if (type == "int") raw(static_cast<std::int32_t>(value));
  else if (type == "uint") raw(static_cast<std::uint32_t>(value));
  else if (type == "float") raw(static_cast<float>(value));
  else raw(value);
}

struct PlyTypes {
  std::string coord = "float", count = "uchar", index = "int";
};

/// A binary PLY of `mesh` with an extra vertex property, an extra face property and an extra
/// element, all of which the reader must skip.
std::string binary_ply(const TriMesh& mesh, bool big, const PlyTypes& t, const std::string& list_name = "vertex_indices") {
  std::string s = "ply\nformat ";
  s += big ? "binary_big_endian 1.0\n" : "binary_little_endian 1.0\n";
  s += "comment test file\nelement vertex " + std::to_string(mesh.V.rows()) + "\n";
  s += "property " + t.coord + " x\nproperty " + t.coord + " y\nproperty " + t.coord + " z\n";
  s += "property uchar red\nproperty list uchar short texture\n";
  s += "element face " + std::to_string(mesh.F.rows()) + "\n";
  s += "property list " + t.count + " " + t.index + " " + list_name + "\nproperty int flags\n";
  s += "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n";
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    for (int k = 0; k < 3; ++k) put(s, t.coord, mesh.V(i, k), big);
    put(s, "uchar", 200, big);
    put(s, "uchar", 2, big);
    put(s, "short", -1, big);
    put(s, "short", 7, big);
  }
  for (Eigen::Index i = 0; i < mesh.F.rows(); ++i) {
    put(s, t.count, 3, big);
    for (int k = 0; k < 3; ++k) put(s, t.index, mesh.F(i, k), big);
    put(s, "int", 12345, big);
  }
  put(s, "int", 0, big);
  put(s, "int", 1, big);
  return s;
}

/// The octahedron moved to non-negative integer coordinates, exact in every PLY type.
TriMesh integer_octahedron() {
  TriMesh m = test::octahedron();
  m.V.array() += 1.0;
  return m;
}

const char* kCubeQuadsObj =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

}  // namespace

// ---- writers and round trips ------------------------------------------------------------------

TEST_CASE("OBJ and PLY writers round-trip exactly", "[formats]") {
  const std::string dir = test::temp_dir("formats_roundtrip");
  TriMesh mesh = test::random_blob(2, 7);
  // Values that need all 17 digits, signed zero, tiny and huge magnitudes, subnormals.
  mesh.V(0, 0) = 0.1;
  mesh.V(0, 1) = 1.0 / 3.0;
  mesh.V(0, 2) = -0.0;
  mesh.V(1, 0) = 1e-300;
  mesh.V(1, 1) = 4.9e-324;
  mesh.V(1, 2) = -1.7976931348623157e308;
  mesh.V(2, 0) = 123456789.123456789;

  auto [name, options] = GENERATE(table<std::string, WriteOptions>({
      {"m.obj", WriteOptions{}},
      {"ascii.ply", WriteOptions{false, 17}},
      {"binary.ply", WriteOptions{true, 17}},
  }));
  SECTION(name) {
    const std::string path = dir + "/" + name;
    REQUIRE(write_mesh(path, mesh, options).ok());
    ReadInfo info;
    TriMesh back = read_ok(path, {}, &info);
    CHECK(back.F == mesh.F);
    CHECK(back.V.rows() == mesh.V.rows());
    // Bitwise equality (operator== would call -0.0 == 0.0 equal).
    CHECK(std::memcmp(back.V.data(), mesh.V.data(), sizeof(double) * static_cast<std::size_t>(mesh.V.size())) == 0);
    CHECK(info.format == (name == "m.obj" ? "obj" : name == "ascii.ply" ? "ply-ascii" : "ply-binary-le"));
  }
}

TEST_CASE("writers honour a reduced precision and reject unknown extensions", "[formats]") {
  const std::string dir = test::temp_dir("formats_write_options");
  TriMesh mesh = test::icosphere(1);
  const std::string path = dir + "/short.obj";
  REQUIRE(write_mesh(path, mesh, WriteOptions{true, 6}).ok());
  TriMesh back = read_ok(path);
  CHECK(back.F == mesh.F);
  CHECK((back.V - mesh.V).cwiseAbs().maxCoeff() < 1e-5);
  CHECK((back.V - mesh.V).cwiseAbs().maxCoeff() > 0);

  check_error(write_mesh(dir + "/m.stl", mesh), ErrorCode::Unsupported, dir + "/m.stl", ".stl");
  check_error(write_mesh(dir + "/missing/m.obj", mesh), ErrorCode::IoError, dir + "/missing/m.obj", "does not exist");
  CHECK_FALSE(fs::exists(dir + "/missing"));
}

TEST_CASE("a folder given as a mesh is named as a folder, with a hint", "[formats]") {
  const std::string dir = test::temp_dir("formats_folder_as_mesh");
  fs::create_directories(dir + "/meshes.obj");  // even with a mesh-like name
  for (const std::string& p : {dir, dir + "/meshes.obj"})
    check_error(read_mesh(p).status(), ErrorCode::IoError, p, "is a directory, not a mesh file (name the meshes in it");
}

TEST_CASE("file_extension is lower case without the dot", "[formats]") {
  CHECK(file_extension("a/b/Mesh.OBJ") == "obj");
  CHECK(file_extension("x.sphere.ply") == "ply");
  CHECK(file_extension("dir.v1/noext") == "");
  CHECK(file_extension(".hidden") == "");
  CHECK(file_extension("") == "");
}

// ---- OBJ ----------------------------------------------------------------------------------

TEST_CASE("OBJ reader: corner forms, relative indices, ignored statements", "[formats]") {
  const std::string dir = test::temp_dir("formats_obj_read");
  const std::string path = write_file(dir, "forms.obj",
                                      "# comment\r\n"
                                      "mtllib forms.mtl\no thing\n"
                                      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1 1.0 0.5 0.5\n"
                                      "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n"
                                      "g group1\nusemtl mat\ns off\n\n"
                                      "f 1 2 3\n"
                                      "f 1/1 3/2 4/3\n"
                                      "f 1/1/1 2/2/1 5/3/1 # trailing comment\n"
                                      "f 2//1 3//1 5//1\n"
                                      "f -5 -2 -1\n"
                                      "l 1 2\n");
  ReadInfo info;
  TriMesh m = read_ok(path, {}, &info);
  CHECK(info.format == "obj");
  CHECK(info.polygons_triangulated == 0);
  REQUIRE(m.V.rows() == 5);
  CHECK(m.V.row(4) == Eigen::RowVector3d(0, 0, 1));
  CHECK(m.F == faces({{0, 1, 2}, {0, 2, 3}, {0, 1, 4}, {1, 2, 4}, {0, 3, 4}}));
}

TEST_CASE("OBJ reader: polygon policies", "[formats]") {
  const std::string dir = test::temp_dir("formats_obj_polygons");
  const std::string quads = write_file(dir, "cube.obj", kCubeQuadsObj);
  ReadInfo info;
  TriMesh cube = read_ok(quads, {}, &info);
  CHECK(cube.F.rows() == 12);
  CHECK(info.polygons_triangulated == 6);
  CHECK(cube.F.row(0) == Eigen::RowVector3i(0, 3, 2));  // fan of the first quad
  CHECK(cube.F.row(1) == Eigen::RowVector3i(0, 2, 1));

  check_read_error(quads, ErrorCode::InvalidInput, "4 corners", ReadOptions{PolygonPolicy::Reject});

  const std::string mixed = write_file(dir, "m.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4 5\n");
  TriMesh all = read_ok(mixed, {}, &info);  // the default triangulates a mix
  CHECK(all.F.rows() == 3);
  CHECK(info.polygons_triangulated == 1);
  CHECK(info.face_polygon == std::vector<std::int32_t>{0, 1, 1});
  Result<TriMesh> r = read_mesh(mixed, ReadOptions{PolygonPolicy::TriangulateUniform});
  check_error(r.status(), ErrorCode::InvalidInput, mixed, "mixed triangle and 4-corner faces");
  CHECK(r.status().message().find("Triangulate") != std::string::npos);
}

TEST_CASE("OBJ reader: error paths", "[formats]") {
  const std::string dir = test::temp_dir("formats_obj_errors");
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

  SECTION("empty file") {
    check_read_error(write_file(dir, "empty.obj", ""), ErrorCode::ParseError, "empty");
  }
  SECTION("index out of range names the line") {
    std::string text;
    for (int i = 0; i < 8; ++i) text += "v " + std::to_string(i) + " 0 0\n";
    for (int i = 0; i < 8; ++i) text += "f 1 2 3\n";
    text += "f 1 2 9\n";  // line 17
    const std::string path = write_file(dir, "m.obj", text);
    Result<TriMesh> r = read_mesh(path);
    REQUIRE_FALSE(r.ok());
    CHECK(r.status().code() == ErrorCode::InvalidInput);
    CHECK(r.status().message() == path + ":17: face index 9 out of range (8 vertices)");
  }
  SECTION("relative index before the first vertex") {
    check_read_error(write_file(dir, "rel.obj", tri + "f -1 -2 -4\n"), ErrorCode::InvalidInput, "out of range");
  }
  SECTION("index 0") {
    check_read_error(write_file(dir, "zero.obj", tri + "f 0 1 2\n"), ErrorCode::InvalidInput, "out of range");
  }
  SECTION("NaN, Inf and overflowing coordinates") {
    for (const char* bad : {"nan", "inf", "-Infinity", "1e400", "-2e308"}) {
      const std::string path = write_file(dir, "m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 " + std::string(bad) +
                                                            " 0\nf 1 2 3\n");
      Result<TriMesh> r = read_mesh(path);
      REQUIRE_FALSE(r.ok());
      CHECK(r.status().code() == ErrorCode::InvalidInput);
      CHECK(r.status().message() == path + ": vertex 3 has a non-finite coordinate");
    }
  }
  SECTION("underflow is a tiny finite number, not an error") {
    TriMesh m = read_ok(write_file(dir, "tiny.obj", "v 1e-400 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
    CHECK(m.V(0, 0) == 0.0);
  }
  SECTION("face with fewer than 3 corners") {
    check_read_error(write_file(dir, "two.obj", tri + "f 1 2\n"), ErrorCode::ParseError, "2 corners");
  }
  SECTION("truncated vertex line") {
    check_read_error(write_file(dir, "trunc.obj", tri + "f 1 2 3\nv 1 2"), ErrorCode::ParseError, "fewer than 3");
  }
  SECTION("bad number and bad corner") {
    check_read_error(write_file(dir, "num.obj", "v 0 zero 0\n"), ErrorCode::ParseError, "bad number 'zero'");
    check_read_error(write_file(dir, "corner.obj", tri + "f 1 x/2 3\n"), ErrorCode::ParseError, "bad face corner");
  }
  SECTION("no faces") {
    check_read_error(write_file(dir, "points.obj", tri + "# only points\n"), ErrorCode::InvalidInput, "no faces");
  }
  SECTION("missing file, directory, unknown extension") {
    check_read_error(dir + "/absent.obj", ErrorCode::IoError, "cannot open");
    fs::create_directories(dir + "/folder.obj");
    check_read_error(dir + "/folder.obj", ErrorCode::IoError, "directory");
    check_read_error(write_file(dir, "mesh.xyz", tri), ErrorCode::Unsupported, ".xyz");
    check_read_error(write_file(dir, "noext", tri), ErrorCode::Unsupported, "extension");
  }
}

// ---- PLY ----------------------------------------------------------------------------------

TEST_CASE("PLY reader: ascii with skipped properties and elements", "[formats]") {
  const std::string dir = test::temp_dir("formats_ply_ascii");
  const std::string path = write_file(dir, "quad.ply",
                                      "ply\r\nformat ascii 1.0\r\ncomment hello\r\nobj_info x\r\n"
                                      "element vertex 4\r\nproperty double x\r\nproperty double y\r\n"
                                      "property double z\r\nproperty float nx\r\nproperty list uchar int junk\r\n"
                                      "element face 2\r\nproperty uchar flags\r\nproperty list uchar uint vertex_index\r\n"
                                      "element material 1\r\nproperty float shininess\r\nend_header\r\n"
                                      "0 0 0 1.5 0\r\n1 0 0 1.5 2 7 8\r\n1 1 0 1.5 1 9\r\n0 1 0.25 1.5 0\r\n"
                                      "9 3 0 1 2\r\n9 3 0 2 3\r\n"
                                      "0.5\r\n");
  ReadInfo info;
  TriMesh m = read_ok(path, {}, &info);
  CHECK(info.format == "ply-ascii");
  CHECK(m.V.rows() == 4);
  CHECK(m.V(3, 2) == 0.25);
  CHECK(m.F == faces({{0, 1, 2}, {0, 2, 3}}));
}

TEST_CASE("PLY reader: binary byte orders and numeric types", "[formats]") {
  const std::string dir = test::temp_dir("formats_ply_binary");
  const TriMesh mesh = integer_octahedron();
  const bool big = GENERATE(false, true);
  auto types = GENERATE(values<PlyTypes>({
      {"float", "uchar", "int"},
      {"double", "uchar", "uint"},
      {"uchar", "ushort", "ushort"},
      {"short", "int", "short"},
      {"int", "uint", "uchar"},
      {"char", "char", "int"},
  }));
  const std::string list_name = big ? "vertex_indices" : "vertex_index";
  const std::string path = write_file(dir, "oct.ply", binary_ply(mesh, big, types, list_name));
  ReadInfo info;
  INFO("big endian " << big << ", types " << types.coord << "/" << types.count << "/" << types.index);
  TriMesh m = read_ok(path, {}, &info);
  CHECK(info.format == (big ? "ply-binary-be" : "ply-binary-le"));
  CHECK(m.V == mesh.V);
  CHECK(m.F == mesh.F);
}

TEST_CASE("PLY reader: error paths", "[formats]") {
  const std::string dir = test::temp_dir("formats_ply_errors");
  const std::string good = binary_ply(integer_octahedron(), false, {});
  const std::string header_end = "end_header\n";
  const std::size_t body = good.find(header_end) + header_end.size();
  const std::string ascii_head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                 "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

  SECTION("truncated binary vertices and faces") {
    // 6 vertices of 3 floats + uchar + list(uchar count=2, 2 shorts) = 18 bytes each;
    // 8 faces of list(uchar count=3, 3 ints) + int = 17 bytes each.
    const std::string path = write_file(dir, "bad.ply", good.substr(0, body + 2 * 18 + 10));
    Result<TriMesh> r = read_mesh(path);
    REQUIRE_FALSE(r.ok());
    CHECK(r.status().code() == ErrorCode::ParseError);
    CHECK(r.status().message() ==
          path + ": binary PLY ends after 2 of 6 vertices (truncated, or wrong counts in the header?)");
    check_read_error(write_file(dir, "faces.ply", good.substr(0, body + 6 * 18 + 3 * 17 + 5)), ErrorCode::ParseError,
                     "ends after 3 of 8 faces");
  }
  SECTION("truncated ascii") {
    check_read_error(write_file(dir, "short.ply", ascii_head + "0 0 0\n1 0 0\n"), ErrorCode::ParseError,
                     "ascii PLY ends after 2 of 3 vertices");
    check_read_error(write_file(dir, "short2.ply", ascii_head + "0 0 0\n1 0 0\n0 1 0\n3 0 1"), ErrorCode::ParseError,
                     "ends after 0 of 1 faces");
  }
  SECTION("wrong counts in the header") {
    check_read_error(write_file(dir, "extra.ply", ascii_head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 1\n"),
                     ErrorCode::ParseError, "wrong counts");
    check_read_error(write_file(dir, "extra_bin.ply", good + std::string(30, 'x')), ErrorCode::ParseError,
                     "wrong counts");
  }
  SECTION("absurd counts fail fast without allocating") {
    std::string huge = good;
    huge.replace(huge.find("element vertex 6"), 16, "element vertex 1099511627776");
    check_read_error(write_file(dir, "huge.ply", huge), ErrorCode::ParseError, "of 1099511627776 vertices");
    std::string ascii_huge = ascii_head;
    ascii_huge.replace(ascii_huge.find("element face 1"), 14, "element face 1099511627776");
    check_read_error(write_file(dir, "huge_ascii.ply", ascii_huge + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
                     ErrorCode::ParseError, "of 1099511627776 faces");
    std::string big_list = ascii_head + "0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n";
    big_list.replace(big_list.find("list uchar int"), 14, "list uint int");
    check_read_error(write_file(dir, "big_list.ply", big_list), ErrorCode::ParseError, "ends after 0 of 1 faces");
  }
  SECTION("header problems") {
    check_read_error(write_file(dir, "magic.ply", "plx\nformat ascii 1.0\nend_header\n"), ErrorCode::ParseError,
                     "not a PLY");
    check_read_error(write_file(dir, "noend.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"), ErrorCode::ParseError,
                     "end_header");
    check_read_error(write_file(dir, "type.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty real x\nend_header\n"),
                     ErrorCode::ParseError, "unknown property type 'real'");
    check_read_error(write_file(dir, "fmt.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n"),
                     ErrorCode::ParseError, "unknown PLY format");
    check_read_error(write_file(dir, "noz.ply", "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\n"
                                                "property float y\nend_header\n"),
                     ErrorCode::ParseError, "'z'");
    std::string float_list = ascii_head;
    float_list.replace(float_list.find("uchar int"), 9, "uchar float");
    check_read_error(write_file(dir, "flist.ply", float_list + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"), ErrorCode::ParseError,
                     "non-integer");
  }
  SECTION("index out of range, negative index, bad token, no faces") {
    check_read_error(write_file(dir, "range.ply", ascii_head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n"),
                     ErrorCode::InvalidInput, "face 0 index 9 out of range (3 vertices)");
    check_read_error(write_file(dir, "neg.ply", ascii_head + "0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n"),
                     ErrorCode::InvalidInput, "index -1 out of range");
    check_read_error(write_file(dir, "token.ply", ascii_head + "0 0 0\n1 oops 0\n0 1 0\n3 0 1 2\n"),
                     ErrorCode::ParseError, ":11: bad number 'oops'");
    check_read_error(write_file(dir, "nan.ply", ascii_head + "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"),
                     ErrorCode::InvalidInput, "vertex 1 has a non-finite coordinate");
    std::string no_faces = ascii_head;
    no_faces.replace(no_faces.find("element face 1"), 14, "element face 0");
    check_read_error(write_file(dir, "nofaces.ply", no_faces + "0 0 0\n1 0 0\n0 1 0\n"), ErrorCode::InvalidInput,
                     "no faces");
    check_read_error(write_file(dir, "corners.ply", ascii_head + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n"),
                     ErrorCode::ParseError, "face 0 has 2 corners");
  }
}

// ---- OFF ----------------------------------------------------------------------------------

TEST_CASE("OFF reader: header variants, comments, colours", "[formats]") {
  const std::string dir = test::temp_dir("formats_off");
  SECTION("plain with comments") {
    TriMesh m = read_ok(write_file(dir, "tet.off", "OFF\n# a comment\n4 4 6\n0 0 0\n1 0 0 # inline\n0 1 0\n\n0 0 1\n"
                                                   "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"));
    CHECK(m.V.rows() == 4);
    CHECK(m.F == faces({{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}));
  }
  SECTION("COFF with colours, counts on the keyword line, face colours") {
    ReadInfo info;
    TriMesh m = read_ok(write_file(dir, "c.off", "COFF 3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n"
                                                 "0 1 0 0 0 255 255\n3 0 1 2 0.5 0.5 0.5\n"),
                        {}, &info);
    CHECK(info.format == "off");
    CHECK(m.V(1, 0) == 1.0);
    CHECK(m.F == faces({{0, 1, 2}}));
  }
  SECTION("NOFF with normals and a quad") {
    ReadInfo info;
    TriMesh m = read_ok(write_file(dir, "n.off", "NOFF\n4 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n"
                                                 "4 0 1 2 3\n"),
                        {}, &info);
    CHECK(m.F.rows() == 2);
    CHECK(info.polygons_triangulated == 1);
  }
  SECTION("errors") {
    const std::string head = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n";
    check_read_error(write_file(dir, "tv.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n"), ErrorCode::ParseError,
                     "ends after 2 of 3 vertices");
    check_read_error(write_file(dir, "tf.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"), ErrorCode::ParseError,
                     "ends after 1 of 2 faces");
    check_read_error(write_file(dir, "extra.off", head + "3 0 1 2\n3 0 2 1\n"), ErrorCode::ParseError, "wrong counts");
    check_read_error(write_file(dir, "short.off", head + "4 0 1 2\n"), ErrorCode::ParseError, "only 3 indices");
    check_read_error(write_file(dir, "range.off", head + "3 0 1 3\n"), ErrorCode::InvalidInput, "out of range");
    check_read_error(write_file(dir, "counts.off", "OFF\nthree 1 0\n"), ErrorCode::ParseError, "counts");
    check_read_error(write_file(dir, "4d.off", "4OFF\n"), ErrorCode::Unsupported, "4OFF");
    check_read_error(write_file(dir, "comment.off", "# nothing\n"), ErrorCode::ParseError, "no header");
    check_read_error(write_file(dir, "inf.off", "OFF\n3 1 0\n0 0 0\n1e999 0 0\n0 1 0\n3 0 1 2\n"),
                     ErrorCode::InvalidInput, "non-finite");
  }
}

// ---- STL ----------------------------------------------------------------------------------

namespace {

/// The tetrahedron as STL triangles (every vertex repeated once per face).
std::string ascii_stl(const TriMesh& m, const std::string& name = "tet") {
  std::string s = "solid " + name + "\n";
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    s += "  facet normal 0 0 1\n    outer loop\n";
    for (int k = 0; k < 3; ++k) {
      const auto v = m.V.row(m.F(f, k));
      s += "      vertex " + std::to_string(v[0]) + " " + std::to_string(v[1]) + " " + std::to_string(v[2]) + "\n";
    }
    s += "    endloop\n  endfacet\n";
  }
  return s + "endsolid " + name + "\n";
}

/// Welding renumbers vertices in order of first use: compare face by face, corner by corner.
bool same_faces(const TriMesh& a, const TriMesh& b) {
  if (a.F.rows() != b.F.rows()) return false;
  for (Eigen::Index f = 0; f < a.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (a.V.row(a.F(f, k)) != b.V.row(b.F(f, k))) return false;
    }
  }
  return true;
}

std::string binary_stl(const TriMesh& m, const std::string& header_text) {
  std::string s = header_text;
  s.resize(80, ' ');
  put(s, "uint", static_cast<double>(m.F.rows()), false);
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) put(s, "float", 0, false);
    for (int c = 0; c < 3; ++c) {
      for (int k = 0; k < 3; ++k) put(s, "float", m.V(m.F(f, c), k), false);
    }
    s.append(2, '\0');
  }
  return s;
}

}  // namespace

TEST_CASE("STL reader: ascii and binary, welded", "[formats]") {
  const std::string dir = test::temp_dir("formats_stl");
  const TriMesh mesh = integer_octahedron();
  SECTION("ascii") {
    ReadInfo info;
    TriMesh m = read_ok(write_file(dir, "oct.stl", ascii_stl(mesh)), {}, &info);
    CHECK(info.format == "stl-ascii");
    CHECK(m.V.rows() == 6);  // 24 corners welded to 6 vertices
    CHECK(same_faces(m, mesh));
  }
  SECTION("ascii: upper case keywords, two solids, -0 welded with +0") {
    std::string text = ascii_stl(mesh, "a");
    for (char& c : text) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    std::string second = "solid b\nfacet normal 0 0 0\nouter loop\nvertex -0 1 1\nvertex 1 1 2\nvertex 2 1 1\n"
                         "endloop\nendfacet\nendsolid b\n";
    TriMesh m = read_ok(write_file(dir, "two.stl", text + second));
    CHECK(m.V.rows() == 6);
    REQUIRE(m.F.rows() == 9);
    CHECK(m.V.row(m.F(8, 0)) == mesh.V.row(1));  // -0 met +0: same vertex
    CHECK(m.V.row(m.F(8, 1)) == mesh.V.row(4));
    CHECK(m.V.row(m.F(8, 2)) == mesh.V.row(0));
  }
  SECTION("binary, even with a header that starts with 'solid'") {
    for (const char* header : {"binary stl", "solid but actually binary"}) {
      ReadInfo info;
      TriMesh m = read_ok(write_file(dir, "oct.stl", binary_stl(mesh, header)), {}, &info);
      CHECK(info.format == "stl-binary");
      CHECK(m.V.rows() == 6);
      CHECK(same_faces(m, mesh));
    }
  }
  SECTION("errors") {
    const std::string bin = binary_stl(mesh, "x");
    check_read_error(write_file(dir, "tb.stl", bin.substr(0, 84 + 3 * 50 + 20)), ErrorCode::ParseError,
                     "binary STL ends after 3 of 8 triangles");
    check_read_error(write_file(dir, "tiny.stl", "abc"), ErrorCode::ParseError, "too short");
    std::string huge = bin.substr(0, 84);
    huge[80] = huge[81] = huge[82] = huge[83] = '\xff';
    check_read_error(write_file(dir, "huge.stl", huge), ErrorCode::ParseError, "of 4294967295 triangles");
    const std::string text = ascii_stl(mesh);
    check_read_error(write_file(dir, "noend.stl", text.substr(0, text.find("endsolid"))), ErrorCode::ParseError,
                     "endsolid");
    check_read_error(write_file(dir, "mid.stl", text.substr(0, text.find("endloop", 300))), ErrorCode::ParseError,
                     "ends inside facet");
    check_read_error(write_file(dir, "word.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvortex\n"),
                     ErrorCode::ParseError, "'vortex'");
    check_read_error(write_file(dir, "empty.stl", "solid x\nendsolid x\n"), ErrorCode::InvalidInput, "no faces");
  }
}

// ---- glTF ---------------------------------------------------------------------------------

namespace {

std::string base64(const std::string& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::uint32_t bits = 0;
  int n = 0;
  for (unsigned char c : bytes) {
    bits = (bits << 8) | c;
    n += 8;
    while (n >= 6) {
      n -= 6;
      out += kAlphabet[(bits >> n) & 63];
    }
  }
  if (n > 0) out += kAlphabet[(bits << (6 - n)) & 63];
  while (out.size() % 4) out += '=';
  return out;
}

/// A glTF document with one mesh: the tetrahedron, one primitive, u16 indices (or none),
/// and a buffer holding float positions then indices.
struct GltfFixture {
  json doc;
  std::string bin;
};

GltfFixture tetra_gltf(bool indexed, int index_type = 5123) {
  const TriMesh tet = test::tetrahedron();
  GltfFixture g;
  std::size_t nv = indexed ? 4 : 12;
  for (std::size_t i = 0; i < nv; ++i) {
    const Eigen::Index v = indexed ? static_cast<Eigen::Index>(i) : tet.F(static_cast<Eigen::Index>(i / 3), i % 3);
    for (int k = 0; k < 3; ++k) put(g.bin, "float", tet.V(v, k), false);
  }
  const std::size_t pos_bytes = g.bin.size();
  json accessors = json::array();
  accessors.push_back({{"bufferView", 0}, {"componentType", 5126}, {"count", nv}, {"type", "VEC3"}});
  json views = json::array();
  views.push_back({{"buffer", 0}, {"byteLength", pos_bytes}});
  json prim = {{"attributes", {{"POSITION", 0}}}};
  if (indexed) {
    const std::string type = index_type == 5121 ? "uchar" : index_type == 5123 ? "ushort" : "uint";
    for (Eigen::Index f = 0; f < tet.F.rows(); ++f) {
      for (int k = 0; k < 3; ++k) put(g.bin, type, tet.F(f, k), false);
    }
    while (g.bin.size() % 4) g.bin += '\0';
    views.push_back({{"buffer", 0}, {"byteOffset", pos_bytes}, {"byteLength", g.bin.size() - pos_bytes}});
    accessors.push_back({{"bufferView", 1}, {"componentType", index_type}, {"count", 12}, {"type", "SCALAR"}});
    prim["indices"] = 1;
    prim["mode"] = 4;
  }
  g.doc = {{"asset", {{"version", "2.0"}}},
           {"scene", 0},
           {"scenes", {{{"nodes", {0}}}}},
           {"nodes", {{{"mesh", 0}}}},
           {"meshes", {{{"primitives", {prim}}}}},
           {"accessors", accessors},
           {"bufferViews", views},
           {"buffers", {{{"byteLength", g.bin.size()}}}}};
  return g;
}

std::string glb(const json& doc, const std::string& bin) {
  std::string text = doc.dump();
  while (text.size() % 4) text += ' ';
  std::string padded = bin;
  while (padded.size() % 4) padded += '\0';
  std::string out;
  put(out, "uint", 0x46546C67, false);
  put(out, "uint", 2, false);
  put(out, "uint", static_cast<double>(12 + 8 + text.size() + (bin.empty() ? 0 : 8 + padded.size())), false);
  put(out, "uint", static_cast<double>(text.size()), false);
  put(out, "uint", 0x4E4F534A, false);
  out += text;
  if (!bin.empty()) {
    put(out, "uint", static_cast<double>(padded.size()), false);
    put(out, "uint", 0x004E4942, false);
    out += padded;
  }
  return out;
}

/// Six times the signed volume: positive for a closed mesh with outward (ccw) faces.
double signed_volume(const TriMesh& m) {
  double v = 0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    v += m.V.row(m.F(f, 0)).dot(m.V.row(m.F(f, 1)).cross(m.V.row(m.F(f, 2))));
  }
  return v;
}

RowMat3d float_positions(const TriMesh& m) { return m.V.cast<float>().cast<double>(); }

}  // namespace

TEST_CASE("glTF reader: external buffer, data URI, GLB, index types", "[formats]") {
  const std::string dir = test::temp_dir("formats_gltf");
  const TriMesh tet = test::tetrahedron();
  const int index_type = GENERATE(5121, 5123, 5125);
  GltfFixture g = tetra_gltf(true, index_type);

  SECTION(".gltf with an external .bin") {
    g.doc["buffers"][0]["uri"] = "tet%20data.bin";  // percent-encoded file name
    write_file(dir, "tet data.bin", g.bin);
    ReadInfo info;
    TriMesh m = read_ok(write_file(dir, "tet.gltf", g.doc.dump(1)), {}, &info);
    CHECK(info.format == "gltf");
    CHECK(m.V == float_positions(tet));
    CHECK(m.F == tet.F);
  }
  SECTION(".gltf with a data URI") {
    g.doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64(g.bin);
    TriMesh m = read_ok(write_file(dir, "tet.gltf", g.doc.dump()));
    CHECK(m.V == float_positions(tet));
    CHECK(m.F == tet.F);
  }
  SECTION(".glb") {
    ReadInfo info;
    TriMesh m = read_ok(write_file(dir, "tet.glb", glb(g.doc, g.bin)), {}, &info);
    CHECK(info.format == "glb");
    CHECK(m.V == float_positions(tet));
    CHECK(m.F == tet.F);
  }
}

TEST_CASE("glTF reader: split vertices are welded, unreferenced ones dropped", "[formats]") {
  const std::string dir = test::temp_dir("formats_gltf_weld");
  GltfFixture g = tetra_gltf(false);  // 12 vertices, one per corner, like a flat-shaded export
  const TriMesh tet = test::tetrahedron();
  TriMesh m = read_ok(write_file(dir, "flat.glb", glb(g.doc, g.bin)));
  CHECK(m.V.rows() == 4);
  CHECK(m.F.rows() == 4);
  CHECK(signed_volume(m) > 0);
  // Welded vertex order is first use: faces map back to the same positions.
  for (Eigen::Index f = 0; f < 4; ++f) {
    for (int k = 0; k < 3; ++k) CHECK(m.V.row(m.F(f, k)) == float_positions(tet).row(tet.F(f, k)));
  }

  GltfFixture extra = tetra_gltf(true);
  extra.doc["accessors"][0]["count"] = 3;  // only vertices 0..2 are in range now
  check_read_error(write_file(dir, "range.glb", glb(extra.doc, extra.bin)), ErrorCode::InvalidInput,
                   "index 3 out of range (3 vertices)");
}

TEST_CASE("glTF reader: node transforms, scenes and winding", "[formats]") {
  const std::string dir = test::temp_dir("formats_gltf_nodes");
  const TriMesh tet = test::tetrahedron();
  const RowMat3d P = float_positions(tet);

  SECTION("translation and scale of a child node compose with the parent's rotation") {
    GltfFixture g = tetra_gltf(true);
    // node 0 (root): rotate 90 degrees about z; node 1 (child): scale 2 then translate.
    const double h = std::sqrt(0.5);
    g.doc["nodes"] = {{{"rotation", {0, 0, h, h}}, {"children", {1}}},
                      {{"mesh", 0}, {"translation", {1, 2, 3}}, {"scale", {2, 2, 2}}}};
    TriMesh m = read_ok(write_file(dir, "nodes.glb", glb(g.doc, g.bin)));
    REQUIRE(m.V.rows() == 4);
    for (Eigen::Index i = 0; i < 4; ++i) {
      const Eigen::RowVector3d local = 2 * P.row(i) + Eigen::RowVector3d(1, 2, 3);
      const Eigen::RowVector3d expected(-local[1], local[0], local[2]);
      CHECK((m.V.row(i) - expected).norm() < 1e-12);
    }
    CHECK(m.F == tet.F);
  }
  SECTION("a column-major matrix; a mirroring one reverses the winding") {
    GltfFixture g = tetra_gltf(true);
    g.doc["nodes"][0]["matrix"] = {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 0, 0, 1};
    TriMesh m = read_ok(write_file(dir, "mirror.gltf", [&] {
      g.doc["buffers"][0]["uri"] = "data:application/gltf-buffer;base64," + base64(g.bin);
      return g.doc.dump();
    }()));
    CHECK(m.V(0, 0) == Approx(5 - P(0, 0)).margin(1e-12));
    CHECK(signed_volume(m) > 0);  // still outward after the mirror
    CHECK(m.F.row(0) == Eigen::RowVector3i(tet.F(0, 0), tet.F(0, 2), tet.F(0, 1)));
  }
  SECTION("only the default scene; the same mesh twice; no scenes means all meshes") {
    GltfFixture g = tetra_gltf(true);
    g.doc["nodes"] = {{{"mesh", 0}}, {{"mesh", 0}, {"translation", {10, 0, 0}}}, {{"mesh", 0}}};
    g.doc["scenes"] = {{{"nodes", {2}}}, {{"nodes", {0, 1}}}};
    g.doc["scene"] = 1;
    TriMesh two = read_ok(write_file(dir, "two.glb", glb(g.doc, g.bin)));
    CHECK(two.V.rows() == 8);
    CHECK(two.F.rows() == 8);
    g.doc.erase("scenes");
    g.doc.erase("scene");
    TriMesh all = read_ok(write_file(dir, "noscene.glb", glb(g.doc, g.bin)));
    CHECK(all.V == P);
  }
  SECTION("points and lines are skipped") {
    GltfFixture g = tetra_gltf(true);
    json lines = g.doc["meshes"][0]["primitives"][0];
    lines["mode"] = 1;
    g.doc["meshes"][0]["primitives"].push_back(lines);
    TriMesh m = read_ok(write_file(dir, "lines.glb", glb(g.doc, g.bin)));
    CHECK(m.F.rows() == 4);
  }
}

TEST_CASE("glTF reader: error paths", "[formats]") {
  const std::string dir = test::temp_dir("formats_gltf_errors");
  SECTION("Draco-compressed primitive without Draco data") {
    // Read since issue 24 (round trips in convert_tests, gltf_read_draco_test.cpp): here the
    // extension's malformed forms.
    GltfFixture g = tetra_gltf(true);
    g.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    g.doc["meshes"][0]["primitives"][0]["extensions"] = {{"KHR_draco_mesh_compression", {{"bufferView", 0}}}};
    check_read_error(write_file(dir, "draco.glb", glb(g.doc, g.bin)), ErrorCode::ParseError,
                     "KHR_draco_mesh_compression has no POSITION attribute");
    g.doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["attributes"] = {{"POSITION", 0}};
    check_read_error(write_file(dir, "draco2.glb", glb(g.doc, g.bin)), ErrorCode::ParseError,
                     "KHR_draco_mesh_compression (bufferView 0): not Draco data");
  }
  SECTION("missing buffer file") {
    GltfFixture g = tetra_gltf(true);
    g.doc["buffers"][0]["uri"] = "missing.bin";
    const std::string path = write_file(dir, "m.gltf", g.doc.dump());
    check_read_error(path, ErrorCode::IoError, "missing.bin");
    // Fuzzing finding (fuzz_gltf): the file name, which the document chooses, went into the
    // message unquoted, so a newline in the uri broke the one-line message.
    g.doc["buffers"][0]["uri"] = "missing\nline.bin";
    const std::string newline = write_file(dir, "n.gltf", g.doc.dump());
    check_read_error(newline, ErrorCode::IoError, "buffer 0: uri 'missing?line.bin': cannot open");
    // A device never ends: refused instead of read until memory runs out.
    g.doc["buffers"][0]["uri"] = "/dev/zero";
    check_read_error(write_file(dir, "z.gltf", g.doc.dump()), ErrorCode::InvalidInput, "is not a regular file");
  }
  SECTION("buffer shorter than declared, accessor outside its view") {
    GltfFixture g = tetra_gltf(true);
    check_read_error(write_file(dir, "short.glb", glb(g.doc, g.bin.substr(0, 40))), ErrorCode::ParseError,
                     "byteLength");
    g.doc["accessors"][0]["count"] = 1000000;
    check_read_error(write_file(dir, "outside.glb", glb(g.doc, g.bin)), ErrorCode::ParseError, "outside");
  }
  SECTION("malformed JSON and containers") {
    check_read_error(write_file(dir, "bad.gltf", "{\"asset\": "), ErrorCode::ParseError, "invalid JSON");
    check_read_error(write_file(dir, "array.gltf", "[1, 2]"), ErrorCode::ParseError, "not an object");
    GltfFixture g = tetra_gltf(true);
    const std::string whole = glb(g.doc, g.bin);
    check_read_error(write_file(dir, "trunc.glb", whole.substr(0, whole.size() - 10)), ErrorCode::ParseError,
                     "truncated");
    check_read_error(write_file(dir, "magic.glb", "glTX" + whole.substr(4)), ErrorCode::ParseError, "magic");
    g.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = "zero";
    check_read_error(write_file(dir, "type.glb", glb(g.doc, g.bin)), ErrorCode::ParseError, "POSITION");
  }
  SECTION("node cycles, strips, non-float positions, no triangles") {
    GltfFixture g = tetra_gltf(true);
    g.doc["nodes"] = {{{"children", {1}}}, {{"mesh", 0}, {"children", {0}}}};
    check_read_error(write_file(dir, "cycle.glb", glb(g.doc, g.bin)), ErrorCode::ParseError, "twice");
    g = tetra_gltf(true);
    g.doc["meshes"][0]["primitives"][0]["mode"] = 5;
    check_read_error(write_file(dir, "strip.glb", glb(g.doc, g.bin)), ErrorCode::Unsupported, "strips");
    g = tetra_gltf(true);
    g.doc["accessors"][0]["componentType"] = 5125;  // shorts and bytes are KHR_mesh_quantization's
    check_read_error(write_file(dir, "quant.glb", glb(g.doc, g.bin)), ErrorCode::ParseError, "unsigned int");
    g = tetra_gltf(true);
    g.doc["meshes"][0]["primitives"][0]["mode"] = 0;
    check_read_error(write_file(dir, "points.glb", glb(g.doc, g.bin)), ErrorCode::InvalidInput, "no faces");
  }
}

// ---- robustness ----------------------------------------------------------------------------

namespace {

/// Reads `path`; an error must be a one-line message starting with the path, a success a
/// valid mesh. Returns a description of the first violation, or "".
std::string read_contract_violation(const std::string& path) {
  Result<TriMesh> r = read_mesh(path);
  if (!r.ok()) {
    const std::string& msg = r.status().message();
    if (msg.rfind(path, 0) != 0 || msg.find('\n') != std::string::npos) return "bad message: " + msg;
    return "";
  }
  const TriMesh& m = r.value();
  if (m.F.rows() == 0) return "ok without faces";
  if (!m.V.allFinite()) return "ok with non-finite vertices";
  if (m.F.minCoeff() < 0 || m.F.maxCoeff() >= m.V.rows()) return "ok with bad indices";
  return "";
}

}  // namespace

TEST_CASE("readers survive truncated and corrupted files", "[formats]") {
  const std::string dir = test::temp_dir("formats_fuzz");
  const TriMesh oct = integer_octahedron();
  GltfFixture g = tetra_gltf(true);
  json with_uri = g.doc;
  with_uri["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64(g.bin);
  std::string ascii_ply;
  {
    const std::string p = dir + "/seed.ply";
    REQUIRE(write_mesh(p, oct, WriteOptions{false, 17}).ok());
    std::ifstream in(p, std::ios::binary);
    ascii_ply.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::vector<std::pair<std::string, std::string>> seeds = {
      {"obj", kCubeQuadsObj},
      {"ply", binary_ply(oct, false, {})},
      {"ply", binary_ply(oct, true, {"double", "int", "uint"})},
      {"ply", ascii_ply},
      {"off", "OFF\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"},
      {"stl", ascii_stl(oct)},
      {"stl", binary_stl(oct, "solid")},
      {"gltf", with_uri.dump()},
      {"glb", glb(g.doc, g.bin)},
  };
  std::mt19937 rng(20240229);
  int files = 0;
  std::string first_violation;
  for (std::size_t s = 0; s < seeds.size(); ++s) {
    const std::string& bytes = seeds[s].second;
    const std::string path = dir + "/fuzz" + std::to_string(s) + "." + seeds[s].first;
    auto check = [&](const std::string& content) {
      write_file(dir, fs::path(path).filename().string(), content);
      ++files;
      std::string v = read_contract_violation(path);
      if (!v.empty() && first_violation.empty()) first_violation = v;
    };
    // Every truncation (at most ~300 per seed) ...
    const std::size_t step = std::max<std::size_t>(1, bytes.size() / 300);
    for (std::size_t n = 0; n < bytes.size(); n += step) check(bytes.substr(0, n));
    // ... and random byte corruptions, including the header.
    std::uniform_int_distribution<std::size_t> pos(0, bytes.size() - 1);
    std::uniform_int_distribution<int> byte(0, 255), hits(1, 4);
    for (int trial = 0; trial < 150; ++trial) {
      std::string corrupt = bytes;
      for (int h = hits(rng); h > 0; --h) corrupt[pos(rng)] = static_cast<char>(byte(rng));
      check(corrupt);
    }
  }
  // Pure garbage under every extension.
  for (const char* ext : {"obj", "ply", "off", "stl", "gltf", "glb"}) {
    std::uniform_int_distribution<int> byte(0, 255);
    for (int trial = 0; trial < 20; ++trial) {
      std::string junk(static_cast<std::size_t>(trial * 37 + 1), '\0');
      for (char& c : junk) c = static_cast<char>(byte(rng));
      const std::string path = write_file(dir, std::string("junk.") + ext, junk);
      ++files;
      std::string v = read_contract_violation(path);
      if (!v.empty() && first_violation.empty()) first_violation = v;
    }
  }
  INFO(files << " files read");
  CHECK(first_violation == "");
}

// ---- the shared real meshes ---------------------------------------------------------------------

TEST_CASE("every shared mesh loads with the manifest's vertex and face counts", "[formats]") {
  SPHEREKIT_REQUIRE_SHARED_MESHES(meshes_dir);
  std::ifstream in(meshes_dir + "/manifest.json");
  REQUIRE(in.good());
  const json manifest = json::parse(in);
  REQUIRE(manifest.is_array());
  int checked = 0;
  for (const json& entry : manifest) {
    const std::string file = entry.at("file").get<std::string>();
    const std::string path = meshes_dir + "/" + file;
    if (!fs::exists(path)) continue;  // a partial copy of the folder
    INFO(file);
    Result<TriMesh> m = read_mesh(path);
    INFO(m.status().message());
    REQUIRE(m.ok());
    CHECK(m->V.rows() == entry.at("V").get<long>());
    CHECK(m->F.rows() == entry.at("F").get<long>());
    ++checked;
  }
  CHECK(checked > 0);
}
