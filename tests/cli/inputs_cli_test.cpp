// The inputs people have (issue 24) through the program: polygon meshes (a DCC-style mix of
// triangles, twisted quads and non-convex n-gons; a quad-only mesh) are read, reported and
// mapped bijectively; compressed glTF (Draco as `convert` writes it, meshopt as gltfpack does)
// is read and mapped.
#include <array>
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "compressed_glb.h"
#include "test_meshes.h"
#include "test_paths.h"

namespace fs = std::filesystem;

namespace {

using spherekit::test::CliRun;

std::string quote(const std::string& s) { return spherekit::test::shell_quote(s); }
CliRun run_cli(const std::string& args, const std::string& dir) { return spherekit::test::run_cli(SPHEREKIT_EXE, args, dir); }

void write_text(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

/// param, then eval of its map: exit 0 and 0 flipped faces by the exact predicate.
void require_mapped(const std::string& mesh, const std::string& dir) {
  INFO("mesh " << mesh);
  const std::string sphere = dir + "/" + fs::path(mesh).stem().string() + ".sphere.obj";
  const std::string report = dir + "/" + fs::path(mesh).stem().string() + ".report.json";
  const CliRun p = run_cli("param " + quote(mesh) + " -o " + quote(sphere) + " --report " + quote(report) + " --quiet", dir);
  INFO("stderr: " << p.err);
  REQUIRE(p.exit_code == 0);
  const CliRun e = run_cli("eval --json " + quote(mesh) + " " + quote(sphere), dir);
  INFO("stderr: " << e.err);
  CHECK(e.exit_code == 0);
  CHECK(e.out.find("\"flipped_exact\":0") != std::string::npos);
}

/// A cube with n x n quads per face (quads only, 6 n^2 faces).
std::string quad_cube_obj(int n) {
  std::string out;
  std::vector<std::array<int, 3>> points;
  auto vertex = [&](std::array<int, 3> p) {
    for (std::size_t i = 0; i < points.size(); ++i)
      if (points[i] == p) return static_cast<int>(i) + 1;
    points.push_back(p);
    out += "v " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
    return static_cast<int>(points.size());
  };
  std::string faces;
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          auto at = [&](int a, int b) {
            std::array<int, 3> p{};
            p[static_cast<std::size_t>(axis)] = side * n;
            p[static_cast<std::size_t>(u)] = a;
            p[static_cast<std::size_t>(v)] = b;
            return vertex(p);
          };
          int c[4] = {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)};
          if (side == 0) std::swap(c[1], c[3]);  // outward on both sides
          faces += "f " + std::to_string(c[0]) + " " + std::to_string(c[1]) + " " + std::to_string(c[2]) + " " +
                   std::to_string(c[3]) + "\n";
        }
      }
    }
  }
  return out + faces;
}

}  // namespace

TEST_CASE("inputs: a mixed triangle / quad / n-gon mesh is reported and mapped", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("cli_inputs_polygons");
  const spherekit::test::PolygonMesh poly = spherekit::test::star_prism_polygons();
  for (const std::string format : {"obj", "off", "ply"}) {
    const std::string mesh = dir + "/star." + format;
    write_text(mesh, spherekit::test::polygon_mesh_text(poly, format));
    const CliRun c = run_cli("check " + quote(mesh), dir);
    INFO("stdout: " << c.out << "stderr: " << c.err);
    CHECK(c.exit_code == 0);
    CHECK(c.out.find("26 vertices, 48 faces") != std::string::npos);
    CHECK(c.out.find("file faces 25: 11 triangles, 12 quads, 2 n-gons") != std::string::npos);
    require_mapped(mesh, dir);
  }
  // check --json and param --report give every triangle's source face.
  const CliRun j = run_cli("check --json " + quote(dir + "/star.obj"), dir);
  const nlohmann::json checks = nlohmann::json::parse(j.out);
  const nlohmann::json& faces = checks[0]["source_faces"];
  CHECK(faces["faces"] == 25);
  CHECK(faces["ngons"] == 2);
  REQUIRE(faces["face_polygon"].size() == 48);
  CHECK(faces["face_polygon"][0] == 0);   // the 12-gon first: 10 triangles
  CHECK(faces["face_polygon"][9] == 0);
  CHECK(faces["face_polygon"][10] == 1);  // then the pentagon
  const nlohmann::json report = nlohmann::json::parse(spherekit::test::slurp(dir + "/star.report.json"));
  CHECK(report["source_faces"]["face_polygon"] == faces["face_polygon"]);
}

TEST_CASE("inputs: quad-only meshes and the corpus's triangle + quad pyramid are mapped", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("cli_inputs_quads");
  const std::string cube = dir + "/cube.obj";
  write_text(cube, quad_cube_obj(3));
  const CliRun c = run_cli("check --json " + quote(cube), dir);
  INFO("stderr: " << c.err);
  CHECK(c.exit_code == 0);
  const nlohmann::json checks = nlohmann::json::parse(c.out);
  CHECK(checks[0]["source_faces"]["quads"] == 54);
  CHECK(checks[0]["F"] == 108);
  CHECK(checks[0]["genus0_ok"] == true);
  require_mapped(cube, dir);
  require_mapped(std::string(SPHEREKIT_SOURCE_DIR) + "/tests/data/bad/mixed_polygons.obj", dir);
}

TEST_CASE("inputs: Draco glTF from convert and meshopt glTF are read and mapped", "[cli]") {
  const std::string dir = spherekit::test::temp_dir("cli_inputs_compressed");
  // A smooth blob, its map, and its Draco level of detail from convert.
  const std::string blob = dir + "/blob.obj";
  write_text(blob, spherekit::test::polygon_mesh_text(
                       [] {
                         spherekit::test::PolygonMesh p;
                         const spherekit::TriMesh m = spherekit::test::random_blob(2, 3);
                         p.V = m.V;
                         for (Eigen::Index f = 0; f < m.F.rows(); ++f) p.faces.push_back({m.F(f, 0), m.F(f, 1), m.F(f, 2)});
                         return p;
                       }(),
                       "obj"));
  require_mapped(blob, dir);
  const CliRun conv = run_cli("convert " + quote(blob) + " " + quote(dir + "/blob.sphere.obj") + " -o " +
                                  quote(dir + "/gi.exr") + " --size 33 --lods 2 --psnr-samples 100 --quiet",
                              dir);
  INFO("stderr: " << conv.err);
  REQUIRE(conv.exit_code == 0);
  for (const char* glb : {"gi_lod0.glb", "gi_lod1.glb"}) {
    const CliRun c = run_cli("check " + quote(dir + "/" + glb), dir);
    INFO("stderr: " << c.err);
    CHECK(c.exit_code == 0);
    require_mapped(dir + "/" + glb, dir);
  }
  // Geometry only (--no-lod-texcoords --no-lod-normals): no TEXCOORD_0 or NORMAL in the file,
  // fewer bytes, and still a mesh the toolkit reads and maps.
  const CliRun plain = run_cli("convert " + quote(blob) + " " + quote(dir + "/blob.sphere.obj") + " -o " +
                                   quote(dir + "/plain.exr") + " --size 33 --lods 2 --psnr-samples 100 --no-lod-texcoords " +
                                   "--no-lod-normals --quiet",
                               dir);
  INFO("stderr: " << plain.err);
  REQUIRE(plain.exit_code == 0);
  const std::string with_uv = spherekit::test::slurp(dir + "/gi_lod0.glb"),
                    without = spherekit::test::slurp(dir + "/plain_lod0.glb");
  CHECK(with_uv.find("TEXCOORD_0") != std::string::npos);
  CHECK(without.find("TEXCOORD_0") == std::string::npos);
  CHECK(without.find("NORMAL") == std::string::npos);
  CHECK(without.size() < with_uv.size());
  require_mapped(dir + "/plain_lod0.glb", dir);
  const std::string meshopt = dir + "/blob_meshopt.glb";
  write_text(meshopt, spherekit::test::meshopt_glb(spherekit::test::random_blob(2, 3),
                                                   spherekit::test::MeshoptGlb::QuantizedTriangles));
  require_mapped(meshopt, dir);
}
