// Sphere-map files: exact round trip with provenance, the header layout, and rejections.
#include "spherekit/formats/sphere_map_io.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/version.h"
#include "test_meshes.h"
#include "test_paths.h"

namespace {

namespace fs = std::filesystem;
using namespace spherekit;
using namespace spherekit::formats;

/// A map of the blob onto the sphere: its radial projection (the blob is star-shaped).
SphereMap radial_map(const TriMesh& mesh) {
  SphereMap map;
  map.S = mesh.V.rowwise().normalized();
  map.provenance = {"0.0.9-test", "unconstrained", "00ff10ab", std::numeric_limits<std::uint64_t>::max()};
  return map;
}

void check_map_error(const Status& s, ErrorCode code, const std::string& path, const std::string& word) {
  INFO("message: " << s.message());
  REQUIRE_FALSE(s.ok());
  CHECK(s.code() == code);
  CHECK(s.message().rfind(path, 0) == 0);
  CHECK(s.message().find(word) != std::string::npos);
  CHECK(s.message().find('\n') == std::string::npos);
}

}  // namespace

TEST_CASE("sphere map: exact round trip with provenance", "[formats]") {
  const std::string dir = test::temp_dir("formats_sphere_map");
  const TriMesh mesh = test::random_blob(2, 3);
  const SphereMap map = radial_map(mesh);
  const std::string path = dir + "/blob.sphere.obj";
  REQUIRE(write_sphere_map(path, mesh, map).ok());

  const std::string text = read_file(path).value();
  CHECK(text.rfind("# spherekit sphere map v" + std::to_string(kFormatVersion) + "\n", 0) == 0);
  CHECK(text.find("# method unconstrained\n") != std::string::npos);
  CHECK(text.find("# seed 18446744073709551615\n") != std::string::npos);

  Result<SphereMap> back = read_sphere_map(path, mesh);
  INFO(back.status().message());
  REQUIRE(back.ok());
  CHECK(back->S == map.S);  // bit-exact: unit rows are not re-normalised
  CHECK(back->provenance.library_version == "0.0.9-test");
  CHECK(back->provenance.method == "unconstrained");
  CHECK(back->provenance.options_digest == "00ff10ab");
  CHECK(back->provenance.seed == map.provenance.seed);

  // The file is an ordinary OBJ of the sphere with the mesh's faces.
  Result<TriMesh> as_mesh = read_mesh(path);
  REQUIRE(as_mesh.ok());
  CHECK(as_mesh->F == mesh.F);
}

TEST_CASE("sphere map: any mesh format, normalised, without provenance", "[formats]") {
  const std::string dir = test::temp_dir("formats_sphere_map_ply");
  const TriMesh mesh = test::icosphere(1);
  TriMesh scaled = mesh;
  scaled.V *= 3.0;
  const std::string path = dir + "/map.ply";
  REQUIRE(write_mesh(path, scaled).ok());
  Result<SphereMap> back = read_sphere_map(path, mesh);
  REQUIRE(back.ok());
  CHECK((back->S - mesh.V).cwiseAbs().maxCoeff() < 1e-15);
  CHECK(back->provenance.method.empty());
  CHECK(back->provenance.seed == 0);
}

TEST_CASE("sphere map: points of any finite, non-zero length normalise exactly", "[formats]") {
  // Fuzzing finding (fuzz_sphere_points; the same normalisation was here): |p|^2 overflowed
  // for huge points, which came back as (0, 0, 0) or were refused as "not finite"; subnormal
  // points lost their precision in |p|.
  const std::string dir = test::temp_dir("formats_sphere_map_range");
  const TriMesh mesh = test::octahedron();  // its vertices are the unit axes
  for (double scale : {1e303, 1.7e308, 1e-320, 4.9e-324}) {
    INFO("scale " << scale);
    TriMesh scaled = mesh;
    scaled.V *= scale;
    const std::string path = dir + "/map.ply";
    REQUIRE(write_mesh(path, scaled).ok());
    Result<SphereMap> back = read_sphere_map(path, mesh);
    REQUIRE(back.ok());
    CHECK(back->S == mesh.V);
  }
  RowMat3d diagonal(1, 3);
  diagonal << 1.7e308, -1.7e308, 1.7e308;
  TriMesh one{diagonal, RowMat3i()};
  const std::string path = dir + "/diagonal.obj";
  REQUIRE(write_file_atomic(path, "v 1.7e308 -1.7e308 1.7e308\nf 1 1 1\n").ok());
  Result<SphereMap> back = read_sphere_map(path, one);
  REQUIRE(back.ok());
  CHECK((back->S.row(0) - Eigen::RowVector3d(1, -1, 1) / std::sqrt(3.0)).norm() < 1e-15);
}

TEST_CASE("sphere map: rejections", "[formats]") {
  const std::string dir = test::temp_dir("formats_sphere_map_errors");
  const TriMesh mesh = test::icosphere(1);  // 42 vertices
  const SphereMap map = radial_map(mesh);

  SECTION("vertex count differs from the mesh's") {
    const std::string path = dir + "/x.sphere.obj";
    REQUIRE(write_sphere_map(path, mesh, map).ok());
    const TriMesh other = test::icosphere(2);
    Result<SphereMap> r = read_sphere_map(path, other);
    REQUIRE_FALSE(r.ok());
    CHECK(r.status().code() == ErrorCode::InvalidInput);
    CHECK(r.status().message() == path + ": has 42 vertices, mesh has 162");
  }
  SECTION("same vertex count, other faces: a map of another mesh") {
    const std::string path = dir + "/other.sphere.obj";
    TriMesh flipped = mesh;
    flipped.F.row(7) = mesh.F.row(7).reverse();  // same vertices, one face listed the other way round
    REQUIRE(write_sphere_map(path, flipped, map).ok());
    check_map_error(read_sphere_map(path, mesh).status(), ErrorCode::InvalidInput, path, "face 7 differs");
    TriMesh fewer = mesh;
    fewer.F.conservativeResize(mesh.F.rows() - 1, 3);
    REQUIRE(write_sphere_map(path, fewer, map).ok());
    check_map_error(read_sphere_map(path, mesh).status(), ErrorCode::InvalidInput, path, "79 faces, mesh has 80");
  }
  SECTION("a zero point") {
    TriMesh bad = mesh;
    bad.V.row(5).setZero();
    const std::string path = dir + "/zero.obj";
    REQUIRE(write_mesh(path, bad).ok());
    check_map_error(read_sphere_map(path, mesh).status(), ErrorCode::InvalidInput, path, "point 5 is zero");
  }
  SECTION("a non-finite point") {
    const std::string path = dir + "/nan.obj";
    std::string text = "v 1 0 0\nv 0 1 0\nv 0 0 nan\nf 1 2 3\n";
    REQUIRE(write_file_atomic(path, text).ok());
    TriMesh three;
    three.V = RowMat3d::Zero(3, 3);
    check_map_error(read_sphere_map(path, three).status(), ErrorCode::InvalidInput, path, "non-finite");
  }
  SECTION("a newer format version, a bad seed") {
    const std::string path = dir + "/future.obj";
    REQUIRE(write_sphere_map(path, mesh, map).ok());
    std::string text = read_file(path).value();
    std::string future = text;
    future.replace(0, future.find('\n'), "# spherekit sphere map v" + std::to_string(kFormatVersion + 1));
    REQUIRE(write_file_atomic(path, future).ok());
    check_map_error(read_sphere_map(path, mesh).status(), ErrorCode::Unsupported, path, "newer");
    std::string seed = text;
    seed.replace(seed.find("# seed "), 7, "# seed x");
    REQUIRE(write_file_atomic(path, seed).ok());
    check_map_error(read_sphere_map(path, mesh).status(), ErrorCode::ParseError, path + ":5:", "bad seed");
  }
  SECTION("writer preconditions") {
    SphereMap short_map = map;
    short_map.S.conservativeResize(10, 3);
    check_map_error(write_sphere_map(dir + "/s.obj", mesh, short_map), ErrorCode::InvalidInput, dir + "/s.obj",
                "10 points");
    check_map_error(write_sphere_map(dir + "/s.ply", mesh, map), ErrorCode::Unsupported, dir + "/s.ply", ".obj");
    check_map_error(write_sphere_map(dir + "/none/s.obj", mesh, map), ErrorCode::IoError, dir + "/none/s.obj",
                "does not exist");
    CHECK_FALSE(fs::exists(dir + "/s.obj"));
  }
  SECTION("missing file") {
    check_map_error(read_sphere_map(dir + "/absent.obj", mesh).status(), ErrorCode::IoError, dir + "/absent.obj",
                "cannot open");
  }
}
