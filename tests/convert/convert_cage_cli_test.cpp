// End-to-end tests of `spherekit convert --cage` (Catmull–Clark cage + displacement atlas) and
// `spherekit convert --collection` (every member of a consistent collection, one layout).
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "cli_shorthands.h"
#include "spherekit/convert/displacement_exr.h"
#include "spherekit/convert/geometry_image_exr.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/geometry_image.h"
#include "test_meshes.h"
#include "test_paths.h"

#include "cli_test_prelude.h"

using namespace spherekit;

namespace {

// The "f" lines of an OBJ (the cage's topology).
std::vector<std::string> face_lines(const std::string& path) {
  std::vector<std::string> out;
  std::istringstream in(slurp(path));
  for (std::string line; std::getline(in, line);)
    if (line.rfind("f ", 0) == 0) out.push_back(line);
  return out;
}

// `name x y z` lines.
std::map<std::string, Eigen::Vector3d> named_points(const std::string& path) {
  std::map<std::string, Eigen::Vector3d> out;
  std::istringstream in(slurp(path));
  for (std::string line; std::getline(in, line);) {
    std::istringstream f(line);
    std::string name;
    Eigen::Vector3d p;
    if (f >> name >> p.x() >> p.y() >> p.z()) out[name] = p;
  }
  return out;
}

}  // namespace

TEST_CASE("convert --cage writes the cage and the displacement atlas, and the displaced surface is closer",
          "[convert][cage]") {
  const std::string dir = test::temp_dir("convert_cage_cli"), cap = test::temp_dir("convert_cage_cli_capture");
  const TriMesh blob = test::random_blob(3, 21);
  REQUIRE(formats::write_mesh(dir + "/blob.obj", blob).ok());
  SphereMap map;
  map.S = blob.V.rowwise().normalized();
  REQUIRE(formats::write_sphere_map(dir + "/blob.sphere.obj", blob, map).ok());
  const std::string in = q(dir + "/blob.obj") + " " + q(dir + "/blob.sphere.obj");

  const CliRun r = sk("convert " + in + " -o " + q(dir + "/blob.exr") + " --size 17 --cage 2 --cage-tile 9" +
                          " --report " + q(dir + "/blob.json") + " --psnr-samples 30000",
                      cap);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json j = read_json(dir + "/blob.json");
  REQUIRE(j.contains("cage"));
  const json& c = j["cage"];
  CHECK(c["quads"] == 24);
  CHECK(c["control_points"] == 26);
  CHECK(c["file"] == dir + "/blob_cage.obj");
  CHECK(c["psnr_db"].get<double>() > c["psnr_db_limit"].get<double>() + 6);
  const std::vector<std::string> faces = face_lines(dir + "/blob_cage.obj");
  CHECK(faces.size() == 24);
  auto atlas = convert::read_displacement_exr(dir + "/blob_disp.exr");
  REQUIRE(atlas.ok());
  CHECK(atlas->map.tile == 9);
  // Texture coordinates: four per quad, `f v/vt` corners, each the centre of a corner texel of
  // the quad's tile in the texture.
  std::vector<Eigen::Vector2d> vt;
  {
    std::istringstream in(slurp(dir + "/blob_cage.obj"));
    for (std::string line; std::getline(in, line);)
      if (line.rfind("vt ", 0) == 0) {
        std::istringstream f(line.substr(3));
        Eigen::Vector2d t;
        f >> t.x() >> t.y();
        vt.push_back(t);
      }
  }
  REQUIRE(vt.size() == 96);
  const int W = atlas->atlas.width(), H = atlas->atlas.height();
  for (int f = 0; f < 24; ++f) {
    int corners[4][2];
    REQUIRE(std::sscanf(faces[static_cast<std::size_t>(f)].c_str(), "f %*d/%d %*d/%d %*d/%d %*d/%d", &corners[0][1],
                        &corners[1][1], &corners[2][1], &corners[3][1]) == 4);
    const int cu[4] = {0, 8, 8, 0}, cv[4] = {0, 0, 8, 8};
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d t = vt[static_cast<std::size_t>(corners[k][1] - 1)];
      CHECK(t.x() * W == Approx(atlas->atlas.texel_x(f, cu[k]) + 0.5).margin(1e-4));
      CHECK(t.y() * H == Approx(atlas->atlas.texel_y(f, cv[k]) + 0.5).margin(1e-4));
    }
  }
  CHECK(atlas->map.kind == convert::DisplacementKind::Scalar);
  CHECK(atlas->attributes.at("source_mesh") == dir + "/blob.obj");

  // Bad flags: usage error, one line, nothing written.
  for (const std::string bad : {"--displacement sideways", "--cage -1", "--cage-tile 1"}) {
    const std::string out = dir + "/bad.exr";
    const CliRun b = sk("convert " + in + " -o " + q(out) + " --cage 2 " + bad, cap);
    INFO(bad << ": " << b.err);
    CHECK(b.exit_code == 2);
    CHECK(std::count(b.err.begin(), b.err.end(), '\n') == 1);
    CHECK_FALSE(fs::exists(out));
    CHECK_FALSE(fs::exists(dir + "/bad_cage.obj"));
  }
}

TEST_CASE("convert --collection: one layout for every member, features on the same texels", "[convert][collection]") {
  const std::string dir = test::temp_dir("convert_collection_cli"), cap = test::temp_dir("convert_collection_capture");
  const std::string samples = dir + "/samples", col = dir + "/col", out = dir + "/assets";
  REQUIRE(sk("samples -o " + q(samples) + " --members 2 --vertices 1500", cap).exit_code == 0);
  {
    const CliRun r = sk("consistent -o " + q(col) + " " + q(samples + "/sample_a.obj") + " " +
                            q(samples + "/sample_b.obj") + " --remesh-size 17 -q",
                        cap);
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
  }
  const int n = 33;
  const CliRun r = sk("convert --collection " + q(col) + " -o " + q(out) + " --gi 33 --lods 2 --cage 2 --cage-tile 5" +
                          " --psnr-samples 20000 -q",
                      cap);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json rep = read_json(out + "/convert_report.json");
  REQUIRE(rep["members"].size() == 2);
  for (const std::string name : {"sample_a", "sample_b"})
    for (const std::string suffix : {".exr", "_lod0.glb", "_lod1.glb", "_lods.glb", "_cage.obj", "_disp.exr"})
      CHECK(fs::is_regular_file(out + "/" + name + suffix));
  CHECK(rep["morph"]["targets"] == 1);
  CHECK(fs::is_regular_file(out + "/collection_morph.glb"));
  // The cage is the same quad mesh for both members.
  CHECK(face_lines(out + "/sample_a_cage.obj") == face_lines(out + "/sample_b_cage.obj"));

  // Features: the texel nearest each collection location F_k (computed here independently)
  // holds, in both members' images, a point near that member's own feature vertex: within
  // the local texel spacing. With maps that were not consistent the feature would sit
  // elsewhere on the sphere and the texel would show another part of the shape.
  auto a = convert::read_geometry_image_exr(out + "/sample_a.exr");
  auto b = convert::read_geometry_image_exr(out + "/sample_b.exr");
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  const auto F = named_points(col + "/features.txt");
  const json manifest = read_json(col + "/collection.json");
  REQUIRE(rep["feature_texels"].size() == F.size());
  const GeometryImage* images[2] = {&a->image, &b->image};
  for (const json& e : rep["feature_texels"]) {
    const std::string name = e["name"];
    INFO(name);
    const Eigen::Vector2d uv = sphere_to_octahedral(F.at(name));
    const int i = static_cast<int>(std::lround((uv.y() + 1) / 2 * (n - 1)));
    const int jj = static_cast<int>(std::lround((uv.x() + 1) / 2 * (n - 1)));
    CHECK(e["texel"][0] == i);
    CHECK(e["texel"][1] == jj);
    // The texel's sphere point is within a texel diagonal of F_k.
    const Eigen::Vector2d t = texel_to_octahedral(i, jj, n);
    CHECK(octahedral_to_sphere(t.x(), t.y()).dot(F.at(name)) > std::cos(2.0 * 3.14159 / (n - 1)));
    for (int m = 0; m < 2; ++m) {
      const json& mem = manifest["meshes"][static_cast<std::size_t>(m)];
      const std::string member = mem["name"];
      auto mesh = formats::read_mesh(mem["source"].get<std::string>());
      REQUIRE(mesh.ok());
      std::size_t k = 0;
      for (; k < manifest["features"].size(); ++k)
        if (manifest["features"][k]["name"] == name) break;
      REQUIRE(k < mem["feature_vertices"].size());
      const Eigen::Vector3d v = mesh->V.row(mem["feature_vertices"][k].get<int>());
      const Eigen::Vector3d p = images[m]->position(i, jj).cast<double>();
      double spacing = 0;
      for (int di = -1; di <= 1; ++di)
        for (int dj = -1; dj <= 1; ++dj) {
          const int i2 = std::clamp(i + di, 0, n - 1), j2 = std::clamp(jj + dj, 0, n - 1);
          spacing = std::max(spacing, (images[m]->position(i2, j2).cast<double>() - p).norm());
        }
      INFO(member << ": distance " << (p - v).norm() << ", spacing " << spacing);
      CHECK((p - v).norm() <= spacing);
    }
  }

  // Failures: nothing created, an unrelated folder never replaced.
  const CliRun both = sk("convert --collection " + q(col) + " " + q(samples + "/sample_a.obj") + " -o " +
                             q(dir + "/x") + " --gi 17",
                         cap);
  CHECK(both.exit_code == 2);
  CHECK_FALSE(fs::exists(dir + "/x"));
  const CliRun missing = sk("convert --collection " + q(dir + "/nowhere") + " -o " + q(dir + "/y") + " --gi 17", cap);
  CHECK(missing.exit_code != 0);
  CHECK(std::count(missing.err.begin(), missing.err.end(), '\n') == 1);
  CHECK_FALSE(fs::exists(dir + "/y"));
  fs::create_directories(dir + "/mine");
  std::ofstream(dir + "/mine/keep.txt") << "user data";
  const CliRun refuse = sk("convert --collection " + q(col) + " -o " + q(dir + "/mine") + " --gi 17", cap);
  CHECK(refuse.exit_code == 4);
  CHECK(slurp(dir + "/mine/keep.txt") == "user data");
  // Re-running into its own output folder replaces it.
  CHECK(sk("convert --collection " + q(col) + " -o " + q(out) + " --gi 17 --psnr-samples 0 -q", cap).exit_code == 0);
  CHECK_FALSE(fs::exists(out + "/sample_a_cage.obj"));
  CHECK(read_json(out + "/convert_report.json")["size"] == 17);
}

TEST_CASE("eval-surface measures two surfaces with convert's remesh_error", "[convert][cli]") {
  const std::string dir = test::temp_dir("eval_surface_cli"), cap = test::temp_dir("eval_surface_capture");
  const TriMesh blob = test::random_blob(3, 7);
  TriMesh round = blob;
  round.V = blob.V.rowwise().normalized();
  REQUIRE(formats::write_mesh(dir + "/blob.obj", blob).ok());
  REQUIRE(formats::write_mesh(dir + "/round.obj", round).ok());
  const CliRun r = sk("eval-surface " + q(dir + "/blob.obj") + " " + q(dir + "/round.obj") + " --samples 20000 --json", cap);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json j = json::parse(r.out);
  RemeshErrorOptions opts;
  opts.samples = 20000;
  const RemeshError e = remesh_error(blob, round, opts);
  CHECK(j["psnr_db"].get<double>() == Approx(e.psnr).epsilon(1e-12));
  CHECK(j["rms_forward"].get<double>() == Approx(e.rms_forward).epsilon(1e-12));
  CHECK(j["peak"].get<double>() == Approx(e.peak).epsilon(1e-12));
  // A missing file: one line naming it, I/O exit code.
  const CliRun bad = sk("eval-surface " + q(dir + "/blob.obj") + " " + q(dir + "/none.obj"), cap);
  CHECK(bad.exit_code == 4);
  CHECK(std::count(bad.err.begin(), bad.err.end(), '\n') == 1);
  CHECK(bad.err.find("none.obj") != std::string::npos);
}
