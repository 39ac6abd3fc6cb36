// End-to-end tests of the collection applications: `transfer` (colours, texture, normals),
// `morph` and `pca` on a small consistent sample collection; exit codes, outputs, reports,
// and failures that leave nothing behind.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.h"
#include "cli_shorthands.h"
#include "spherekit/formats/mesh_attributes.h"
#include "spherekit/formats/mesh_io.h"
#include "test_paths.h"

#include "cli_test_prelude.h"

namespace {

using spherekit::test::require_failure;

bool is_png(const std::string& path) { return slurp(path).rfind("\x89PNG\r\n\x1a\n", 0) == 0; }

}  // namespace

TEST_CASE("transfer, morph and pca on a consistent sample collection", "[cli][applications]") {
  using namespace spherekit;
  const std::string dir = spherekit::test::temp_dir("cli_applications");
  const std::string s = dir + "/samples", col = dir + "/col", out = dir + "/out";
  fs::create_directories(out);
  // One test case, blocks in sequence: the collection is built once (sections would rebuild it).
  REQUIRE(sk("samples -o " + q(s) + " --members 3 --vertices 900", dir).exit_code == 0);
  CliRun r = sk("consistent -o " + q(col) + " " + q(s + "/sample_a.obj") + " " + q(s + "/sample_b.obj") + " " +
                    q(s + "/sample_c.obj") + " --remesh-size 33 --effort 1 -q",
                dir);
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);

  // A coloured copy of sample_a (colour = position in its bounding box).
  auto a = formats::read_mesh(s + "/sample_a.obj");
  REQUIRE(a.ok());
  formats::MeshAttributes colors;
  const Eigen::RowVector3d lo = a->V.colwise().minCoeff(), hi = a->V.colwise().maxCoeff();
  colors.colors = (a->V.rowwise() - lo).array().rowwise() / (hi - lo).array();
  REQUIRE(formats::write_mesh_with_attributes(dir + "/a_colored.ply", a.value(), colors).ok());

  {  // colours there and back
    r = sk("transfer " + q(col) + " --from sample_a --to sample_c --what colors -o " + q(out + "/c.ply") +
               " --attributes " + q(dir + "/a_colored.ply") + " --report " + q(out + "/t.json"),
           dir);
    INFO("stderr: " << r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(r.out.find("transfer colors: sample_a -> sample_c") != std::string::npos);
    auto c = formats::read_mesh_with_attributes(out + "/c.ply");
    REQUIRE(c.ok());
    auto c_mesh = formats::read_mesh(s + "/sample_c.obj");
    REQUIRE(c_mesh.ok());
    CHECK(c->mesh.V == c_mesh->V);
    REQUIRE(c->attributes.colors.rows() == c_mesh->V.rows());
    const json t = read_json(out + "/t.json");
    CHECK(t["what"] == "colors");
    CHECK(t["vertices_in_holes"] == 0);
    // Back to sample_a (through the 8-bit PLY): close to the original on average.
    r = sk("transfer " + q(col) + " --from sample_c --to sample_a --what colors -o " + q(out + "/a_back.obj") +
               " --attributes " + q(out + "/c.ply") + " -q",
           dir);
    REQUIRE(r.exit_code == 0);
    CHECK(r.out.empty());
    auto back = formats::read_mesh_with_attributes(out + "/a_back.obj");
    REQUIRE(back.ok());
    REQUIRE(back->attributes.colors.rows() == a->V.rows());
    CHECK((back->attributes.colors - colors.colors).rowwise().norm().mean() < 0.05);
  }

  {  // texture: coordinates, material and a copy of the image
    formats::MeshAttributes tex;
    tex.UV.resize(a->V.rows(), 2);
    for (Eigen::Index v = 0; v < a->V.rows(); ++v) tex.UV.row(v) << colors.colors(v, 0), colors.colors(v, 1);
    tex.FT = a->F;
    tex.material_libraries = {"a.mtl"};
    tex.material = "skin";
    REQUIRE(formats::write_mesh_with_attributes(dir + "/a_tex.obj", a.value(), tex).ok());
    std::ofstream(dir + "/a.mtl") << "newmtl skin\nmap_Kd skin.png\n";
    std::ofstream(dir + "/skin.png", std::ios::binary) << "\x89PNG\r\n\x1a\nnot really an image";
    r = sk("transfer " + q(col) + " --from sample_a --to sample_b --what texture -o " + q(out + "/b_tex.obj") +
               " --attributes " + q(dir + "/a_tex.obj"),
           dir);
    INFO("stderr: " << r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(slurp(out + "/b_tex_texture.png") == slurp(dir + "/skin.png"));
    auto mtl = formats::read_mtl(out + "/b_tex.mtl");
    REQUIRE(mtl.ok());
    REQUIRE(mtl->size() == 1);
    CHECK((*mtl)[0].diffuse_map == "b_tex_texture.png");
    auto b = formats::read_mesh_with_attributes(out + "/b_tex.obj");
    REQUIRE(b.ok());
    CHECK(b->attributes.material_libraries == std::vector<std::string>{"b_tex.mtl"});
    REQUIRE(b->attributes.FT.rows() == b->mesh.F.rows());
    CHECK(b->attributes.UV.minCoeff() > -0.2);
    CHECK(b->attributes.UV.maxCoeff() < 1.2);
  }

  {  // normals: normal map on the target's consistent remesh
    r = sk("transfer " + q(col) + " --from sample_a --to sample_c --what normals --size 33 -o " + q(out + "/c_n.obj") +
               " --report " + q(out + "/n.json") + " -q",
           dir);
    INFO("stderr: " << r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(is_png(out + "/c_n_normals.png"));
    auto n = formats::read_mesh_with_attributes(out + "/c_n.obj");
    REQUIRE(n.ok());
    CHECK(n->mesh.V.rows() == 31 * 31 + 2 * 33 - 1);  // the 33 x 33 remesh's welded vertices
    CHECK(n->attributes.FT.rows() == n->mesh.F.rows());
    CHECK(read_json(out + "/n.json")["normal_space"] == "object");
  }

  {  // morph: glTF with morph targets and the frames
    r = sk("morph " + q(col) + " sample_a sample_b -o " + q(out + "/morph") + " --frames 4 --size 17", dir);
    INFO("stderr: " << r.err);
    REQUIRE(r.exit_code == 0);
    const json m = read_json(out + "/morph/morph.json");
    REQUIRE(m["frames"].size() == 4);
    CHECK(m["frames"][0]["t"] == 0.0);
    CHECK(m["frames"][3]["t"] == 1.0);
    CHECK(m["aligned"] == true);
    CHECK(slurp(out + "/morph/morph.glb").substr(0, 4) == "glTF");
    auto f0 = formats::read_mesh(out + "/morph/frame_000.obj");
    auto f3 = formats::read_mesh(out + "/morph/frame_003.obj");
    REQUIRE(f0.ok());
    REQUIRE(f3.ok());
    CHECK(f0->V.rows() == 15 * 15 + 2 * 17 - 1);
    CHECK(f0->F == f3->F);
    CHECK((f0->V - f3->V).norm() > 0);
    // Running again replaces the folder (it holds morph.json).
    r = sk("morph " + q(col) + " sample_a sample_b -o " + q(out + "/morph") + " --frames 2 --size 17 -q", dir);
    REQUIRE(r.exit_code == 0);
    CHECK_FALSE(fs::exists(out + "/morph/frame_003.obj"));
    // --threads changes the effort, never the bytes.
    for (const char* t : {"1", "2"})
      REQUIRE(sk("morph " + q(col) + " sample_a sample_b -o " + q(out + "/morph_t" + t) + " --frames 2 --size 17 -q " +
                     "--threads " + t, dir).exit_code == 0);
    for (const char* f : {"morph.glb", "frame_000.obj", "frame_001.obj"})
      CHECK(slurp(out + "/morph_t1/" + f) == slurp(out + "/morph_t2/" + f));
  }

  {  // pca: mean, components, error table, plots, compression
    r = sk("pca " + q(col) + " -o " + q(out + "/pca") + " --size 17", dir);
    INFO("stderr: " << r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(r.out.find("PCA of 3 members") != std::string::npos);
    for (const char* f : {"mean.obj", "pc1_plus.obj", "pc2_minus.obj", "pca.glb", "pca_errors.csv", "pca_errors.png",
                          "compression.csv", "compression.png", "pca.json"})
      CHECK(fs::exists(out + "/pca/" + f));
    CHECK(is_png(out + "/pca/pca_errors.png"));
    const json p = read_json(out + "/pca/pca.json");
    CHECK(p["components"] == 2);
    const json& rows = p["errors"];
    REQUIRE(rows.size() == 3);
    for (std::size_t k = 1; k < rows.size(); ++k)
      CHECK(rows[k]["mean_rms"].get<double>() <= rows[k - 1]["mean_rms"].get<double>() + 1e-12);
    CHECK(rows[2]["max_rms"].get<double>() < 1e-7 * p["members"][0]["peak"].get<double>());
    // The members' coefficients are projections of centred shapes: each component's sum
    // over the members is 0, and its square sum is the squared singular value.
    for (int j = 0; j < 2; ++j) {
      double sum = 0, sq = 0;
      for (const json& m : p["members"]) {
        REQUIRE(m["coefficients"].size() == 2);
        sum += m["coefficients"][j].get<double>();
        sq += std::pow(m["coefficients"][j].get<double>(), 2);
      }
      const double sv = p["singular_values"][j].get<double>();
      CHECK(std::abs(sum) < 1e-9 * sv);
      CHECK(sq == Approx(sv * sv).epsilon(1e-9));
    }
    bool draco = false;
    for (const json& c : p["compression"]) draco = draco || c["method"] == "draco";
    CHECK(draco);
    for (const char* t : {"1", "2"})
      REQUIRE(sk("pca " + q(col) + " -o " + q(out + "/pca_t" + t) + " --size 17 --no-compression -q --threads " + t, dir)
                  .exit_code == 0);
    for (const char* f : {"mean.obj", "pc1_plus.obj", "pca.glb", "pca_errors.csv"})
      CHECK(slurp(out + "/pca_t1/" + f) == slurp(out + "/pca_t2/" + f));
  }

  {  // bad arguments fail cleanly and write nothing
    require_failure(sk("transfer " + q(col) + " --from sample_a --to sample_c --what smells -o " + q(out + "/x.ply"), dir),
                    2, "--what");
    require_failure(sk("transfer " + q(col) + " --from sample_a --to sample_c --what colors -o " + q(out + "/x.ply"), dir),
                    3, "sample_a.obj: no vertex colours");
    require_failure(sk("transfer " + q(col) + " --from nobody --to sample_c --what colors -o " + q(out + "/x.ply"), dir), 3,
                    "nobody: not a member");
    require_failure(sk("transfer " + q(col) + " --from sample_a --to sample_c --what uv -o " + q(out + "/x.ply"), dir), 2,
                    "x.ply");
    CHECK_FALSE(fs::exists(out + "/x.ply"));
    require_failure(sk("morph " + q(col) + " sample_a sample_b -o " + q(out + "/m1") + " --frames 1", dir), 2, "--frames");
    require_failure(sk("morph " + q(col) + " sample_a sample_b -o " + q(out + "/m2") + " --size 20", dir), 2, "--size");
    CHECK_FALSE(fs::exists(out + "/m1"));
    CHECK_FALSE(fs::exists(out + "/m2"));
    require_failure(sk("pca " + q(dir + "/missing") + " -o " + q(out + "/p1"), dir), 4, "missing");
    CHECK_FALSE(fs::exists(out + "/p1"));
    // An unrelated non-empty folder is never replaced.
    fs::create_directories(out + "/keep");
    std::ofstream(out + "/keep/mine.txt") << "precious\n";
    require_failure(sk("pca " + q(col) + " -o " + q(out + "/keep"), dir), 4, "keep");
    CHECK(slurp(out + "/keep/mine.txt") == "precious\n");
    // No staging folders left behind.
    for (const auto& e : fs::directory_iterator(out)) CHECK(e.path().filename().string().find(".partial.") == std::string::npos);
  }
}
