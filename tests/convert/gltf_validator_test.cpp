// Every .glb the glTF tests write passes the Khronos glTF validator with 0 errors and 0
// warnings and decodes with Google's draco3d (npm), both installed on first use by
// scripts/setup_npm_tools.sh. Skips with a message when node/npm or the registry is missing.
//
// The files are rebuilt here from the same fixtures the other tests use (gltf_test_support.h),
// because each test case runs as its own process. Infos the validator reports and that are
// expected: UNSUPPORTED_EXTENSION (it cannot check Draco or MSFT_lod payloads) and
// UNUSED_OBJECT (the Draco bitstream views, the MSFT_lod levels reachable only through "ids",
// TEXCOORD_0 while no material samples a texture: the texture is the user's to add).
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "cli_runner.h"
#include "gltf_test_support.h"
#include "spherekit/convert/gltf_lods.h"
#include "spherekit/convert/gltf_morph.h"
#include "spherekit/formats/atomic_file.h"
#include "test_meshes.h"
#include "test_paths.h"

using namespace spherekit;
using namespace spherekit::convert;

TEST_CASE("glTF files pass the Khronos validator and decode with draco3d", "[convert][npm]") {
  const test::NpmTools& tools = test::npm_tools();
  if (!tools.available) {
    SPHEREKIT_SKIP("the npm validators are unavailable (scripts/setup_npm_tools.sh said: " << tools.why << ")");
  }
  const std::string dir = test::temp_dir("gltf_validator");
  std::vector<std::string> files;
  auto write = [&](const std::string& name, const std::string& bytes) {
    REQUIRE(formats::write_file_atomic(dir + "/" + name, bytes).ok());
    files.push_back(dir + "/" + name);
  };
  // A set of levels as convert writes it: each level's file and the MSFT_lod file.
  auto write_lods = [&](const std::string& prefix, const GltfLods& lods) {
    auto paths = write_gltf_lods(dir + "/" + prefix, lods);
    REQUIRE(paths.ok());
    files.insert(files.end(), paths->levels.begin(), paths->levels.end());
    files.push_back(paths->combined);
  };

  // gltf_lods_test: the levels, the MSFT_lod file, a single level.
  auto lods = build_gltf_lods(test::lod_test_image(), test::lod_test_options());
  REQUIRE(lods.ok());
  write_lods("blob", lods.value());
  GltfLodOptions one = test::lod_test_options();
  one.levels = 1;
  auto single = build_gltf_lods(test::blob_geometry_image(17), one);
  REQUIRE(single.ok());
  write("single_lods.glb", single->combined_glb);
  // A mesh with holes: levels fitted at their sizes, hole faces left out (as `convert` does).
  {
    const test::HoledLodImages holed = test::holed_lod_images(33, 3);
    GltfLodOptions open = test::lod_test_options();
    open.drop_hole_faces = true;
    auto holed_lods = build_gltf_lods(holed.levels, open);
    REQUIRE(holed_lods.ok());
    write_lods("holed", holed_lods.value());
  }

  // Adaptive levels (adaptive_lods_test): a mesh with holes left open, a collection's levels and
  // each level's morph-target file.
  {
    GltfLodOptions adaptive = test::lod_test_options();
    adaptive.mode = LodMode::Adaptive;
    adaptive.drop_hole_faces = true;
    auto holed = build_gltf_lods(test::holed_lod_images(33, 3).levels, adaptive);
    REQUIRE(holed.ok());
    write_lods("adaptive_holed", holed.value());
    adaptive.drop_hole_faces = false;
    auto collection = build_consistent_gltf_lods(
        {test::blob_geometry_image(33, 3, 7), test::blob_geometry_image(33, 3, 8)}, {adaptive, adaptive});
    REQUIRE(collection.ok());
    for (std::size_t m = 0; m < 2; ++m) write("adaptive_member" + std::to_string(m) + ".glb", (*collection)[m].combined_glb);
    for (std::size_t k = 0; k < (*collection)[0].levels.size(); ++k) {
      auto morph = build_gltf_morph_targets(
          std::vector<GltfMesh>{(*collection)[0].levels[k].mesh, (*collection)[1].levels[k].mesh});
      REQUIRE(morph.ok());
      write("adaptive_morph_plain_lod" + std::to_string(k) + ".glb", morph->glb);
    }
  }

  // Levels simplified from the original mesh (original_lods_test): a closed blob and a mesh with
  // holes, texture coordinates on the octahedral domain with seams at the fold.
  {
    GltfLodOptions original = test::lod_test_options();
    original.mode = LodMode::Original;
    original.position_bits_rule = PositionBitsRule::RateDistortion;
    const TriMesh blob = test::random_blob(3, 7);
    const RowMat3d blob_S = blob.V.rowwise().normalized();
    auto closed = build_original_gltf_lods(blob, blob_S, 65, original);
    REQUIRE(closed.ok());
    write_lods("original", closed.value());
    // Without texture coordinates (convert --no-lod-texcoords): the fold's copies are one point.
    GltfLodOptions plain_original = original;
    plain_original.texcoords = false;
    auto untextured = build_original_gltf_lods(blob, blob_S, 65, plain_original);
    REQUIRE(untextured.ok());
    write_lods("original_untextured", untextured.value());
    const test::HoledLodImages holed = test::holed_lod_images(33, 1);
    auto open = build_original_gltf_lods(holed.mesh, holed.S, 33, original);
    REQUIRE(open.ok());
    write("original_holed_lods.glb", open->combined_glb);
    // A collection's levels on its template member's mesh (template_lods_test): two blobs of
    // different connectivity, each level's files and its morph-target file.
    const TriMesh other = test::random_blob(4, 8);
    const RowMat3d other_S = other.V.rowwise().normalized();
    const std::vector<TemplateLodMember> members{{&blob, &blob_S}, {&other, &other_S}};
    auto layout = lay_template(members, 1);
    REQUIRE(layout.ok());
    auto laid = build_template_gltf_lods(*layout, members, 65, {original, original});
    REQUIRE(laid.ok());
    for (std::size_t m = 0; m < 2; ++m) write_lods("template_member" + std::to_string(m), (*laid)[m]);
    for (std::size_t k = 0; k < (*laid)[0].levels.size(); ++k) {
      auto morph =
          build_gltf_morph_targets(std::vector<GltfMesh>{(*laid)[0].levels[k].mesh, (*laid)[1].levels[k].mesh});
      REQUIRE(morph.ok());
      write("template_morph_plain_lod" + std::to_string(k) + ".glb", morph->glb);
    }
    auto laid_untextured = build_template_gltf_lods(*layout, members, 65, {plain_original, plain_original});
    REQUIRE(laid_untextured.ok());
    for (std::size_t m = 0; m < 2; ++m) write("template_untextured_member" + std::to_string(m) + ".glb", (*laid_untextured)[m].combined_glb);
    auto untextured_morph = build_gltf_morph_targets(
        std::vector<GltfMesh>{(*laid_untextured)[0].levels[0].mesh, (*laid_untextured)[1].levels[0].mesh});
    REQUIRE(untextured_morph.ok());
    write("template_untextured_morph_plain_lod0.glb", untextured_morph->glb);
  }

  // gltf_morph_test: uncompressed, Draco sequential, from triangle meshes.
  const std::vector<GltfMesh> members = test::collection_test_meshes(17);
  auto plain = build_gltf_morph_targets(members);
  REQUIRE(plain.ok());
  write("morph_plain.glb", plain->glb);
  GltfMorphOptions draco;
  draco.encoding = MorphEncoding::DracoSequential;
  auto compressed = build_gltf_morph_targets(members, draco);
  REQUIRE(compressed.ok());
  write("morph_draco.glb", compressed->glb);
  auto trimeshes = build_gltf_morph_targets(std::vector<TriMesh>{test::random_blob(2, 1), test::random_blob(2, 2)});
  REQUIRE(trimeshes.ok());
  write("morph_trimesh.glb", trimeshes->glb);
  auto lone = build_gltf_morph_targets(std::vector<TriMesh>{test::random_blob(2, 1)});
  REQUIRE(lone.ok());
  write("morph_single.glb", lone->glb);

#ifdef SPHEREKIT_EXE
  // gltf_cli_test: what `spherekit convert --lods` writes.
  test::write_blob_inputs(dir);
  const test::CliRun r = test::run_cli(SPHEREKIT_EXE,
                                       "convert " + test::shell_quote(dir + "/blob.obj") + " " +
                                           test::shell_quote(dir + "/blob.sphere.obj") + " -o " +
                                           test::shell_quote(dir + "/cli.exr") + " --gi 33 --lods 3 --psnr-samples 0",
                                       test::temp_dir("gltf_validator_capture"));
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  for (const char* name : {"cli_lod0.glb", "cli_lod1.glb", "cli_lod2.glb", "cli_lods.glb"}) files.push_back(dir + "/" + name);

  // What a collection's commands write: `convert --collection` (levels, members as morph
  // targets), `morph` (frames as targets, with an animation) and `pca` (components).
  const std::string cap = test::temp_dir("gltf_validator_collection");
  auto sk = [&](const std::string& args) {
    const test::CliRun run = test::run_cli(SPHEREKIT_EXE, args, cap);
    INFO("spherekit " << args << "\n" << run.err);
    REQUIRE(run.exit_code == 0);
  };
  const std::string q = test::shell_quote(dir);
  sk("samples -o " + q + "/in --members 2 --vertices 300");
  sk("consistent -o " + q + "/col " + q + "/in/sample_a.obj " + q + "/in/sample_b.obj --no-refine --quiet");
  sk("convert --collection " + q + "/col -o " + q + "/conv --gi 17 --lods 2 --psnr-samples 0 --quiet");
  sk("morph " + q + "/col sample_a sample_b -o " + q + "/morph --frames 3 --size 17 --quiet");
  sk("pca " + q + "/col -o " + q + "/pca --size 17 --quiet");
  for (const char* name : {"conv/sample_a_lod0.glb", "conv/sample_b_lods.glb", "conv/collection_morph.glb",
                           "morph/morph.glb", "pca/pca.glb"})
    files.push_back(dir + "/" + name);
#endif

  const nlohmann::json report = test::run_npm_validators(tools, files);
  REQUIRE(report.at("files").size() == files.size());
  for (const auto& f : report["files"]) {
    INFO(f.dump(1));
    CHECK(f.at("errors") == 0);
    CHECK(f.at("warnings") == 0);
    CHECK(f.at("draco_problems").empty());
    const std::string name = f.at("file");
    // Every file but the uncompressed morph targets has Draco primitives, all decoded.
    const bool uncompressed = name.find("morph_plain") != std::string::npos ||
                              name.find("morph_trimesh") != std::string::npos ||
                              name.find("morph_single") != std::string::npos ||
                              name.find("collection_morph") != std::string::npos ||
                              name.find("morph.glb") != std::string::npos || name.find("pca.glb") != std::string::npos;
    CHECK((f.at("draco_primitives").get<int>() > 0) == !uncompressed);
  }
}
