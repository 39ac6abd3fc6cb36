// Draco-compressed glTF written by convert's own writers read back by formats::read_mesh (its
// Draco core decoder, gltf_compression.h): the levels of detail equal the Draco decode exactly,
// a plain mesh equals its source within half a quantization step; corrupt Draco data and wrong
// accessor counts are refused in one line naming the file.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <array>
#include <algorithm>
#include <string>

#include "cli_runner.h"
#include "compressed_glb.h"
#include "gltf_test_support.h"
#include "spherekit/convert/gltf_lods.h"
#include "spherekit/convert/gltf_morph.h"
#include "spherekit/formats/mesh_io.h"
#include "test_meshes.h"
#include "test_paths.h"
#include "test_skip.h"

namespace {

using namespace spherekit;

std::string write_bytes(const std::string& dir, const std::string& name, const std::string& bytes) {
  const std::string path = dir + "/" + name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

/// A blob as one Draco primitive (sequential encoding: points and faces keep their order), as
/// `convert --collection` writes collection_morph.glb.
convert::GltfMorph draco_blob(const TriMesh& blob) {
  convert::GltfMorphOptions options;
  options.encoding = convert::MorphEncoding::DracoSequential;
  auto morph = convert::build_gltf_morph_targets(std::vector<TriMesh>{blob}, options);
  INFO(morph.status().message());
  REQUIRE(morph.ok());
  return std::move(morph).value();
}

}  // namespace

TEST_CASE("glTF reader: convert's Draco levels of detail read back as decoded", "[convert]") {
  const std::string dir = test::temp_dir("convert_read_draco_lods");
  auto lods = convert::build_gltf_lods(test::blob_geometry_image(33), [] {
    convert::GltfLodOptions o;
    o.levels = 2;
    return o;
  }());
  INFO(lods.status().message());
  REQUIRE(lods.ok());
  for (std::size_t level = 0; level < lods->levels.size(); ++level) {
    INFO("level " << level);
    const convert::GltfMesh& decoded = lods->levels[level].primitive.decoded.mesh;
    const std::string path = write_bytes(dir, "lod" + std::to_string(level) + ".glb", lods->levels[level].glb);
    Result<TriMesh> r = formats::read_mesh(path);
    INFO(r.status().message());
    REQUIRE(r.ok());
    // Triangle for triangle the decoder's positions (points at one position are welded).
    REQUIRE(r->F.rows() == decoded.F.rows());
    int differing = 0;
    for (Eigen::Index t = 0; t < decoded.F.rows(); ++t)
      for (int k = 0; k < 3; ++k) differing += r->V.row(r->F(t, k)) != decoded.V.row(decoded.F(t, k));
    CHECK(differing == 0);
    CHECK(r->V.rows() < decoded.V.rows());  // the folded border's copies were welded
  }
  // The combined file (MSFT_lod) holds every level in its nodes; the reader takes the scene's
  // (level 0).
  Result<TriMesh> combined = formats::read_mesh(write_bytes(dir, "lods.glb", lods->combined_glb));
  REQUIRE(combined.ok());
  CHECK(combined->F.rows() == lods->levels[0].primitive.decoded.mesh.F.rows());
}

TEST_CASE("glTF reader: a Draco mesh equals its source within half a quantization step", "[convert]") {
  const std::string dir = test::temp_dir("convert_read_draco_mesh");
  TriMesh blob = test::random_blob(2, 11);
  blob.V.array() -= 5.0;
  const convert::GltfMorph morph = draco_blob(blob);
  Result<TriMesh> r = formats::read_mesh(write_bytes(dir, "blob.glb", morph.glb));
  INFO(r.status().message());
  REQUIRE(r.ok());
  REQUIRE(r->V.rows() == blob.V.rows());
  // Sequential Draco keeps the face order (the reader numbers vertices by first use).
  REQUIRE(r->F.rows() == blob.F.rows());
  const auto& q = morph.quantization.quantization;
  const double range = q.position_range + std::abs(q.position_origin[0]) + std::abs(q.position_origin[1]) +
                       std::abs(q.position_origin[2]);
  const double tolerance = q.position_step() / 2 + 4 * 1.2e-7 * range;
  double err = 0;
  for (Eigen::Index t = 0; t < blob.F.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      err = std::max(err, (r->V.row(r->F(t, k)) - blob.V.row(blob.F(t, k))).cwiseAbs().maxCoeff());
  CHECK(err <= tolerance);
  CHECK(err > 0);  // quantized, not a float copy
}

TEST_CASE("glTF reader: corrupt Draco data and wrong counts are refused in one line", "[convert]") {
  const std::string dir = test::temp_dir("convert_read_draco_bad");
  const TriMesh blob = test::random_blob(2, 11);
  const test::GlbParts good = test::glb_parts(draco_blob(blob).glb);
  const nlohmann::json& draco = good.json["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"];
  const int view = draco["bufferView"].get<int>();
  struct Case {
    const char* name;
    const char* phrase;
    std::function<void(test::GlbParts&)> spoil;
  };
  const std::vector<Case> cases = {
      {"truncated.glb", "Draco data is corrupt or truncated",
       [&](test::GlbParts& g) {
         auto& bv = g.json["bufferViews"][view];
         bv["byteLength"] = bv["byteLength"].get<std::size_t>() / 2;
       }},
      {"not_draco.glb", "not Draco data",
       [&](test::GlbParts& g) {
         const std::size_t at = g.json["bufferViews"][view].value("byteOffset", std::size_t{0});
         g.bin.replace(at, 5, "XRACO");
       }},
      {"position_count.glb", "POSITION accessor count",
       [&](test::GlbParts& g) {
         const int acc = g.json["meshes"][0]["primitives"][0]["attributes"]["POSITION"].get<int>();
         g.json["accessors"][acc]["count"] = blob.V.rows() + 1;
       }},
      {"index_count.glb", "indices accessor count",
       [&](test::GlbParts& g) {
         const int acc = g.json["meshes"][0]["primitives"][0]["indices"].get<int>();
         g.json["accessors"][acc]["count"] = 3;
       }},
      {"unique_id.glb", "no attribute with unique id 7",
       [&](test::GlbParts& g) {
         g.json["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["attributes"]["POSITION"] = 7;
       }},
  };
  for (const Case& c : cases) {
    INFO("case " << c.name);
    test::GlbParts g = good;
    c.spoil(g);
    const std::string path = write_bytes(dir, c.name, test::glb_bytes(g));
    test::require_read_error(formats::read_mesh(path).status(), ErrorCode::ParseError, path, c.phrase);
  }
}

TEST_CASE("glTF reader: gltfpack -cc output (meshopt, quantized) equals its source within 14 bits", "[convert][npm]") {
  const test::NpmTools& tools = test::npm_tools();
  const std::string gltfpack = tools.node_dir + "/node_modules/.bin/gltfpack";
  if (!tools.available || !std::filesystem::exists(gltfpack)) {
    SPHEREKIT_SKIP("gltfpack is unavailable (scripts/setup_npm_tools.sh said: " << tools.why << ")");
    return;
  }
  const std::string dir = test::temp_dir("convert_read_gltfpack");
  TriMesh blob = test::random_blob(2, 13);
  blob.V.array() += 2.0;
  const std::string obj = dir + "/blob.obj";
  REQUIRE(formats::write_mesh(obj, blob).ok());
  const double extent = (blob.V.colwise().maxCoeff() - blob.V.colwise().minCoeff()).maxCoeff();
  for (const std::string flags : {"-cc", "-cc -ce khr"}) {
    INFO("gltfpack " << flags);
    const std::string glb = dir + "/blob_gltfpack.glb";
    std::filesystem::remove(glb);
    REQUIRE(test::run_shell("NO_COLOR=1 " + test::shell_quote(gltfpack) + " -i " + test::shell_quote(obj) + " -o " +
                                test::shell_quote(glb) + " " + flags,
                            dir + "/gltfpack.out", dir + "/gltfpack.err") == 0);
    Result<TriMesh> r = formats::read_mesh(glb);
    if (flags != "-cc") {
      // KHR_meshopt_compression from gltfpack 1.3 uses vertex codec version 1, newer than
      // Debian's libmeshoptimizer 0.18 decodes: refused with a message that says so.
      REQUIRE_FALSE(r.ok());
      CHECK(r.status().code() == ErrorCode::Unsupported);
      CHECK(r.status().message().find("vertex codec version 1") != std::string::npos);
      continue;
    }
    INFO(r.status().message());
    REQUIRE(r.ok());
    // gltfpack reorders vertices and triangles: match each read vertex to its nearest source
    // vertex; the match must be a bijection within half of gltfpack's 14-bit grid step, and
    // carry the triangles onto the source's.
    REQUIRE(r->V.rows() == blob.V.rows());
    REQUIRE(r->F.rows() == blob.F.rows());
    // gltfpack reads the OBJ in float and dequantizes in float: their rounding on top.
    const double tolerance = 0.5 * extent / ((1 << 14) - 1) + 4 * 1.2e-7 * blob.V.cwiseAbs().maxCoeff();
    std::vector<int> match(static_cast<std::size_t>(r->V.rows()), -1);
    std::vector<char> used(static_cast<std::size_t>(blob.V.rows()), 0);
    double worst = 0;
    for (Eigen::Index v = 0; v < r->V.rows(); ++v) {
      Eigen::Index best = 0;
      (blob.V.rowwise() - r->V.row(v)).rowwise().squaredNorm().minCoeff(&best);
      worst = std::max(worst, (blob.V.row(best) - r->V.row(v)).cwiseAbs().maxCoeff());
      match[static_cast<std::size_t>(v)] = static_cast<int>(best);
      used[static_cast<std::size_t>(best)] = 1;
    }
    CHECK(worst <= tolerance);
    CHECK(std::count(used.begin(), used.end(), 1) == blob.V.rows());
    std::set<std::array<int, 3>> source, read;
    auto key = [](int a, int b, int c) {  // rotation-invariant, orientation-keeping
      if (b < a && b < c) return std::array<int, 3>{b, c, a};
      if (c < a && c < b) return std::array<int, 3>{c, a, b};
      return std::array<int, 3>{a, b, c};
    };
    for (Eigen::Index t = 0; t < blob.F.rows(); ++t) source.insert(key(blob.F(t, 0), blob.F(t, 1), blob.F(t, 2)));
    for (Eigen::Index t = 0; t < r->F.rows(); ++t)
      read.insert(key(match[static_cast<std::size_t>(r->F(t, 0))], match[static_cast<std::size_t>(r->F(t, 1))],
                      match[static_cast<std::size_t>(r->F(t, 2))]));
    CHECK(read == source);
  }
}
