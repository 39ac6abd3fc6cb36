// Tests of the glTF levels of detail (convert/src/gltf_lods.cpp): every written primitive is
// decoded in C++ (draco::Decoder, gltf_test_support) and compared with its accessors and with
// the geometry image it came from; the MSFT_lod structure of the combined file.
#include <catch2/catch.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include "cli_runner.h"
#include "gltf_test_support.h"
#include "spherekit/convert/gltf_lods.h"
#include "test_meshes.h"
#include "test_paths.h"

namespace fs = std::filesystem;
using namespace spherekit;
using namespace spherekit::convert;

TEST_CASE("glTF LOD files: each Draco primitive decodes to its accessors and to its image's texels", "[convert]") {
  const GeometryImage gi = test::lod_test_image();
  const GltfLodOptions options = test::lod_test_options();
  auto built = build_gltf_lods(gi, options);
  REQUIRE(built.ok());
  const GltfLods& lods = built.value();
  REQUIRE(lods.levels.size() == 3);
  const std::string dir = test::temp_dir("gltf_lods_files");
  auto paths = write_gltf_lods(dir + "/blob", lods);
  REQUIRE(paths.ok());
  CHECK(paths->levels == std::vector<std::string>{dir + "/blob_lod0.glb", dir + "/blob_lod1.glb", dir + "/blob_lod2.glb"});
  CHECK(paths->combined == dir + "/blob_lods.glb");
  int files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
  CHECK(files == 4);  // no temporary file left

  const DracoQuantization& q = lods.quantization.quantization;
  // The budget: 1e-4 RMS, a tenth of it for quantization.
  CHECK(q.position_step() / 2 <= 1e-5);
  CHECK(q.position_bits >= 14);
  const double half_step = q.position_step() / 2, float_slack = 4 * 1.2e-7 * (q.position_range + 2);
  const int T = gi.size;

  const test::GlbFile combined = test::parse_glb(test::slurp(paths->combined));
  std::map<int, Eigen::RowVector3f> level0_positions;  // texel -> decoded position in level 0
  for (int k = 0; k < 3; ++k) {
    INFO("level " << k);
    const int n = (T - 1) / (1 << k) + 1, stride = 1 << k;
    CHECK(lods.levels[static_cast<std::size_t>(k)].image_size == n);
    const test::GlbFile glb = test::parse_glb(test::slurp(paths->levels[static_cast<std::size_t>(k)]));
    CHECK(test::slurp(paths->levels[static_cast<std::size_t>(k)]) == lods.levels[static_cast<std::size_t>(k)].glb);
    const auto& j = glb.json;
    CHECK(j.at("asset").at("version") == "2.0");
    CHECK(j.at("extensionsRequired") == nlohmann::json::array({"KHR_draco_mesh_compression"}));
    CHECK(j.at("scenes").at(0).at("nodes") == nlohmann::json::array({0}));
    CHECK(j.at("nodes").at(0).at("name") == "blob_LOD" + std::to_string(k));
    // Quantization and provenance are recorded in the combined file; the level's own file
    // says only which level it is and the texture side its TEXCOORD_0 refers to.
    const auto& extras = combined.json.at("meshes").at(static_cast<std::size_t>(k)).at("extras").at("spherekit");
    CHECK(extras.at("lod") == k);
    CHECK(extras.at("geometry_image_size") == n);
    CHECK(extras.at("texture_size") == T);
    CHECK(extras.at("quantization").at("position_bits") == q.position_bits);
    CHECK(extras.at("quantization").at("normal_bits") == 10);
    CHECK(extras.at("quantization").at("budget").at("reference_rms_error").get<double>() == 1e-4);
    CHECK(combined.json.at("asset").at("extras").at("spherekit").at("source_mesh") == "blob.obj");
    CHECK(j.at("asset").at("extras") == nlohmann::json{{"spherekit", {{"lod", k}, {"texture_size", T}}}});
    CHECK_FALSE(j.at("meshes").at(0).contains("extras"));

    const auto decoded = test::decode_and_check_draco(glb);
    REQUIRE(decoded.size() == 1);
    const test::DecodedPrimitive& d = decoded[0];
    CHECK(d.F.rows() == 2 * (n - 1) * (n - 1));
    // Every point is a texel of this level (texture coordinates of the full image).
    std::set<int> texels;
    double worst = 0;
    for (Eigen::Index p = 0; p < d.V.rows(); ++p) {
      const int i = static_cast<int>(std::lround(d.UV(p, 1) * T - 0.5)), jj = static_cast<int>(std::lround(d.UV(p, 0) * T - 0.5));
      REQUIRE(i % stride == 0);
      REQUIRE(jj % stride == 0);
      texels.insert(i * T + jj);
      worst = std::max(worst, static_cast<double>((d.V.row(p) - gi.position(i, jj).transpose()).cwiseAbs().maxCoeff()));
      if (k == 0) {
        level0_positions[i * T + jj] = d.V.row(p);
      } else {
        // One grid for all levels: the texel decodes to the same position as in level 0.
        REQUIRE(level0_positions.count(i * T + jj) == 1);
        REQUIRE(level0_positions[i * T + jj] == d.V.row(p));
      }
    }
    CHECK(texels.size() == static_cast<std::size_t>(n) * n);
    CHECK(worst <= half_step + float_slack);
  }
}

TEST_CASE("glTF LODs: the combined file's MSFT_lod structure", "[convert]") {
  const GeometryImage gi = test::lod_test_image();
  auto built = build_gltf_lods(gi, test::lod_test_options());
  REQUIRE(built.ok());
  const test::GlbFile glb = test::parse_glb(built->combined_glb);
  const auto& j = glb.json;
  // The scene shows only level 0, which lists the coarser levels (MSFT_lod README).
  CHECK(j.at("scene") == 0);
  CHECK(j.at("scenes").at(0).at("nodes") == nlohmann::json::array({0}));
  REQUIRE(j.at("nodes").size() == 3);
  REQUIRE(j.at("meshes").size() == 3);
  for (int k = 0; k < 3; ++k) {
    CHECK(j["nodes"][static_cast<std::size_t>(k)].at("mesh") == k);
    CHECK(j["nodes"][static_cast<std::size_t>(k)].at("name") == "blob_LOD" + std::to_string(k));
  }
  const auto& top = j["nodes"][0];
  CHECK(top.at("extensions").at("MSFT_lod").at("ids") == nlohmann::json::array({1, 2}));
  CHECK_FALSE(j["nodes"][1].contains("extensions"));
  const auto coverage = top.at("extras").at("MSFT_screencoverage").get<std::vector<double>>();
  REQUIRE(coverage.size() == 3);
  CHECK(coverage == std::vector<double>{0.5, 0.25, 0.0});
  CHECK(coverage == built->screen_coverage);
  const auto used = j.at("extensionsUsed").get<std::vector<std::string>>();
  CHECK(std::count(used.begin(), used.end(), "MSFT_lod") == 1);
  CHECK(std::count(used.begin(), used.end(), "KHR_draco_mesh_compression") == 1);
  // Only Draco is required: a loader without MSFT_lod still loads the file (and shows level 0).
  CHECK(j.at("extensionsRequired") == nlohmann::json::array({"KHR_draco_mesh_compression"}));

  // Every level's bitstream is the one of its own file, and decodes to its accessors.
  const auto decoded = test::decode_and_check_draco(glb);
  REQUIRE(decoded.size() == 3);
  for (int k = 0; k < 3; ++k) {
    const auto& ext = j["meshes"][static_cast<std::size_t>(k)]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"];
    CHECK(test::buffer_view_bytes(glb, ext.at("bufferView").get<int>()) ==
          built->levels[static_cast<std::size_t>(k)].primitive.bytes);
    CHECK(decoded[static_cast<std::size_t>(k)].V.rows() ==
          built->levels[static_cast<std::size_t>(k)].primitive.decoded.mesh.V.rows());
  }
}

TEST_CASE("glTF LODs: a collection gets one point order per level", "[convert]") {
  // Consistent sphere maps give every member the same texels and faces; edgebreaker's traversal
  // depends on connectivity and seams only, so the decoded point order (read through the
  // texture coordinates) is the same for every member.
  GltfLodOptions options = test::lod_test_options();
  options.levels = 2;
  auto a = build_gltf_lods(test::blob_geometry_image(33, 3, 7), options);
  auto b = build_gltf_lods(test::blob_geometry_image(33, 3, 8), options);
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  for (std::size_t k = 0; k < 2; ++k) {
    const GltfMesh& da = a->levels[k].primitive.decoded.mesh;
    const GltfMesh& db = b->levels[k].primitive.decoded.mesh;
    CHECK(da.UV == db.UV);
    CHECK(da.F == db.F);
  }
}

TEST_CASE("glTF LODs of a mesh with holes: each level fitted at its size, hole faces left out", "[convert]") {
  const test::HoledLodImages holed_images = test::holed_lod_images(65, 3);
  const TriMesh& holed = holed_images.mesh;
  const std::vector<GeometryImage>* levels = &holed_images.levels;
  REQUIRE(levels->size() == 3);
  GeometryImageOptions fit;
  fit.fit_positions = true;
  auto fine = sample_geometry_image(holed, holed_images.S, 65, fit);
  REQUIRE(fine.ok());
  RemeshErrorOptions err;
  err.samples = 50000;
  for (std::size_t k = 0; k < 3; ++k) {
    INFO("level " << k);
    const GeometryImage& level = (*levels)[k];
    const int n = (65 - 1) / (1 << k) + 1;
    REQUIRE(level.size == n);
    auto sub = subsample_geometry_image(fine.value(), n);
    REQUIRE(sub.ok());
    // Same domain points: same hole flags, normals and faces as the finest image's texels.
    CHECK(level.in_hole == sub->in_hole);
    CHECK(level.face_ids == sub->face_ids);
    if (k == 0) {
      CHECK(level.positions == fine->positions);
      continue;
    }
    // Fitted at its own size, the level is closer to the mesh than the subsampled finest image.
    const double own = remesh_psnr(holed, geometry_image_mesh(level), err, geometry_image_hole_faces(level));
    const double subsampled = remesh_psnr(holed, geometry_image_mesh(sub.value()), err, geometry_image_hole_faces(sub.value()));
    CAPTURE(own, subsampled);
    CHECK(own > subsampled);
  }

  GltfLodOptions options = test::lod_test_options();
  auto kept = build_gltf_lods(*levels, options);
  options.drop_hole_faces = true;
  auto dropped = build_gltf_lods(*levels, options);
  REQUIRE(kept.ok());
  REQUIRE(dropped.ok());
  int some_dropped = 0;
  for (std::size_t k = 0; k < 3; ++k) {
    INFO("level " << k);
    const GeometryImage& level = (*levels)[k];
    const int n = level.size;
    const auto flags = geometry_image_hole_faces(level);
    const auto holes = std::count(flags.begin(), flags.end(), 1);
    some_dropped += holes > 0;
    const GltfMesh& all = kept->levels[k].primitive.decoded.mesh;
    const GltfMesh& open = dropped->levels[k].primitive.decoded.mesh;
    CHECK(all.F.rows() == 2 * (n - 1) * (n - 1));
    CHECK(open.F.rows() == all.F.rows() - holes);
    // The faces left with two or three corners in a hole are only those kept for a manifold
    // (geometry_image_hole_faces keeps them), and every point left is used by a face.
    const auto majority_all = gltf_mesh_hole_faces(all, fine.value());
    const auto majority_left = gltf_mesh_hole_faces(open, fine.value());
    CHECK(std::count(majority_left.begin(), majority_left.end(), 1) ==
          std::count(majority_all.begin(), majority_all.end(), 1) - holes);
    std::vector<int> used(static_cast<std::size_t>(open.V.rows()), 0);
    for (Eigen::Index f = 0; f < open.F.rows(); ++f)
      for (int c = 0; c < 3; ++c) used[static_cast<std::size_t>(open.F(f, c))] = 1;
    CHECK(std::count(used.begin(), used.end(), 0) == 0);
    CHECK(open.V.rows() < all.V.rows());
    CHECK(dropped->levels[k].glb.size() < kept->levels[k].glb.size());
  }
  CHECK(some_dropped == 3);

  // Levels of the wrong size are refused.
  std::vector<GeometryImage> wrong{fine.value(), fine.value()};
  CHECK(build_gltf_lods(wrong, options).status().code() == ErrorCode::InvalidArgument);
  CHECK(build_gltf_lods(std::vector<GeometryImage>{}, options).status().code() == ErrorCode::InvalidArgument);
  CHECK(lod_geometry_images(holed, holed_images.S, fine.value(), 7, fit).status().code() == ErrorCode::InvalidArgument);
}

TEST_CASE("glTF LODs: errors and cancellation", "[convert]") {
  const GeometryImage gi = test::blob_geometry_image(17);
  GltfLodOptions options;
  options.levels = 4;  // 17, 9, 5, 3
  CHECK(build_gltf_lods(gi, options).ok());
  options.levels = 5;  // would need a 2 x 2 level
  CHECK(build_gltf_lods(gi, options).status().code() == ErrorCode::InvalidArgument);
  options.levels = 0;
  CHECK(build_gltf_lods(gi, options).status().code() == ErrorCode::InvalidArgument);
  options = GltfLodOptions{};
  options.lowest_coverage = 0.9;
  CHECK(build_gltf_lods(gi, options).status().code() == ErrorCode::InvalidArgument);
  CHECK(build_gltf_lods(GeometryImage{}, GltfLodOptions{}).status().code() == ErrorCode::InvalidArgument);

  int calls = 0;
  auto cancelled = build_gltf_lods(gi, GltfLodOptions{}, [&](const ProgressEvent& e) {
    CHECK(e.stage == "gltf");
    return ++calls < 2;
  });
  CHECK(cancelled.status().code() == ErrorCode::Cancelled);

  // A single level: no MSFT_lod.
  options = GltfLodOptions{};
  options.levels = 1;
  auto one = build_gltf_lods(gi, options);
  REQUIRE(one.ok());
  const auto j = test::parse_glb(one->combined_glb).json;
  CHECK_FALSE(j.at("nodes").at(0).contains("extensions"));
  CHECK(j.at("extensionsUsed") == nlohmann::json::array({"KHR_draco_mesh_compression"}));

  // Unwritable folder: IoError naming the file.
  auto lods = build_gltf_lods(gi, GltfLodOptions{});
  REQUIRE(lods.ok());
  const std::string dir = test::temp_dir("gltf_lods_errors");
  auto w = write_gltf_lods(dir + "/no/such/folder/x", lods.value());
  CHECK(w.status().code() == ErrorCode::IoError);
  CHECK(w.status().message().find("x_lod0.glb") != std::string::npos);
}

TEST_CASE("glTF LOD level files: minimal JSON, POSITION bounds as shortest decimals", "[convert]") {
  // A level's own file is what a viewer downloads and what is compared against other tools'
  // files: only the properties glTF and KHR_draco_mesh_compression require, the names, and a
  // two-field extras object; provenance and quantization are in the combined file.
  auto built = build_gltf_lods(test::lod_test_image(), test::lod_test_options());
  REQUIRE(built.ok());
  for (std::size_t k = 0; k < built->levels.size(); ++k) {
    INFO("level " << k);
    const std::string& glb = built->levels[k].glb;
    const test::GlbFile file = test::parse_glb(glb);
    std::vector<std::string> keys;
    for (const auto& [key, value] : file.json.items()) keys.push_back(key);
    CHECK(keys == std::vector<std::string>{"accessors", "asset", "bufferViews", "buffers", "extensionsRequired",
                                           "extensionsUsed", "meshes", "nodes", "scene", "scenes"});
    CHECK(file.json.at("asset").at("extras").at("spherekit").size() == 2);
    // Every POSITION bound is written as the shortest decimal of its float (to_chars), and
    // (decode_and_check_draco) reads back as the decoded floats' bound exactly.
    const std::uint32_t json_bytes = static_cast<std::uint8_t>(glb[12]) | static_cast<std::uint8_t>(glb[13]) << 8 |
                                     static_cast<std::uint8_t>(glb[14]) << 16 |
                                     static_cast<std::uint32_t>(static_cast<std::uint8_t>(glb[15])) << 24;
    const std::string text = glb.substr(20, json_bytes);
    int bounds = 0;
    for (const char* key : {"\"max\":[", "\"min\":["}) {
      const std::size_t at = text.find(key);
      REQUIRE(at != std::string::npos);
      std::size_t p = at + std::string(key).size();
      const std::size_t end = text.find(']', p);
      while (p < end) {
        std::size_t q = text.find_first_of(",]", p);
        const std::string number = text.substr(p, q - p);
        float x = 0;
        std::from_chars(number.data(), number.data() + number.size(), x);
        char shortest[32];
        const auto r = std::to_chars(shortest, shortest + sizeof shortest, x);
        CHECK(number == std::string(shortest, r.ptr));
        ++bounds;
        p = q + 1;
      }
    }
    CHECK(bounds == 6);
    const auto decoded = test::decode_and_check_draco(file);
    CHECK(decoded.size() == 1);
    // This fixture's levels (POSITION, NORMAL, TEXCOORD_0) take 892-896 bytes of JSON; with
    // full-precision bounds and the provenance and quantization extras it was ~1.5 KB.
    INFO(text);
    CHECK(json_bytes < 960);
  }
}
