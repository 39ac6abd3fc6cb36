// Compressed glTF read back: meshopt-compressed, quantized GLBs (built with libmeshoptimizer's
// own encoders, compressed_glb.h) equal their source within the quantization, and corrupt
// streams give one-line errors naming the file. The Draco round trips need the writer, in
// convert_tests (gltf_read_draco_test.cpp).
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "compressed_glb.h"
#include "spherekit/formats/mesh_io.h"
#include "test_meshes.h"
#include "test_paths.h"

namespace {

using namespace spherekit;
using spherekit::test::MeshoptGlb;

std::string write_bytes(const std::string& dir, const std::string& name, const std::string& bytes) {
  const std::string path = dir + "/" + name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

/// Same triangles in the same order; the index codec may rotate a triangle's corners (keeping
/// its orientation). Returns the largest coordinate difference over matched corners.
double corner_error(const TriMesh& read, const TriMesh& source) {
  REQUIRE(read.F.rows() == source.F.rows());
  double worst = 0;
  for (Eigen::Index t = 0; t < source.F.rows(); ++t) {
    double best = 1e300;
    for (int r = 0; r < 3; ++r) {
      double e = 0;
      for (int k = 0; k < 3; ++k)
        e = std::max(e, (read.V.row(read.F(t, (k + r) % 3)) - source.V.row(source.F(t, k))).cwiseAbs().maxCoeff());
      best = std::min(best, e);
    }
    worst = std::max(worst, best);
  }
  return worst;
}

}  // namespace

TEST_CASE("glTF reader: meshopt-compressed and quantized GLBs read back within the quantization", "[formats]") {
  const std::string dir = test::temp_dir("formats_gltf_meshopt");
  TriMesh source = test::random_blob(2, 5);
  source.V.array() += 3.0;  // away from the origin: the dequantization offset matters
  for (const auto kind : {MeshoptGlb::QuantizedTriangles, MeshoptGlb::QuantizedTrianglesKhr, MeshoptGlb::ExponentialIndices}) {
    INFO("kind " << static_cast<int>(kind));
    const std::string path = write_bytes(dir, "blob.glb", test::meshopt_glb(source, kind));
    formats::ReadInfo info;
    Result<TriMesh> r = formats::read_mesh(path, {}, &info);
    INFO(r.status().message());
    REQUIRE(r.ok());
    CHECK(r->V.rows() == source.V.rows());
    const double err = corner_error(r.value(), source);
    CHECK(err <= test::meshopt_glb_tolerance(source, kind));
    CHECK(err > 0);  // really quantized: the test would see a reader ignoring the transform
    CHECK(info.face_polygon.size() == static_cast<std::size_t>(source.F.rows()));
  }
}

TEST_CASE("glTF reader: KHR_mesh_quantization normalized shorts through the node transform", "[formats]") {
  const std::string dir = test::temp_dir("formats_gltf_quantized");
  TriMesh source = test::random_blob(2, 9);
  source.V.col(0).array() -= 7.0;
  double tolerance = 0;
  const std::string path = write_bytes(dir, "normalized.glb", test::normalized_short_glb(source, tolerance));
  Result<TriMesh> r = formats::read_mesh(path);
  INFO(r.status().message());
  REQUIRE(r.ok());
  REQUIRE(r->F.rows() == source.F.rows());
  double err = 0;
  for (Eigen::Index t = 0; t < source.F.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      err = std::max(err, (r->V.row(r->F(t, k)) - source.V.row(source.F(t, k))).cwiseAbs().maxCoeff());
  CHECK(err <= tolerance);
  CHECK(err > 0);
}

TEST_CASE("glTF reader: corrupt meshopt streams are refused in one line", "[formats]") {
  const std::string dir = test::temp_dir("formats_gltf_meshopt_bad");
  const TriMesh source = test::random_blob(2, 5);
  const test::GlbParts good = test::glb_parts(test::meshopt_glb(source, MeshoptGlb::QuantizedTriangles));
  const std::string ext = "EXT_meshopt_compression";
  struct Case {
    const char* name;
    ErrorCode code;
    const char* phrase;
    std::function<void(test::GlbParts&)> spoil;
  };
  const std::vector<Case> cases = {
      {"bad_header.glb", ErrorCode::ParseError, "bufferView 0 EXT_meshopt_compression: meshopt data is corrupt",
       [&](test::GlbParts& g) {
         const std::size_t at = g.json["bufferViews"][0]["extensions"][ext]["byteOffset"].get<std::size_t>();
         g.bin[at] = 0x13;
       }},
      {"newer_codec.glb", ErrorCode::Unsupported, "vertex codec version 1",
       [&](test::GlbParts& g) {
         const std::size_t at = g.json["bufferViews"][0]["extensions"][ext]["byteOffset"].get<std::size_t>();
         g.bin[at] = static_cast<char>(0xa1);
       }},
      {"truncated.glb", ErrorCode::ParseError, "meshopt data is corrupt or truncated",
       [&](test::GlbParts& g) {
         auto& e = g.json["bufferViews"][1]["extensions"][ext];
         e["byteLength"] = e["byteLength"].get<std::size_t>() / 2;
       }},
      {"count_too_high.glb", ErrorCode::ParseError, "meshopt data is corrupt",
       [&](test::GlbParts& g) { g.json["bufferViews"][0]["extensions"][ext]["count"] = source.V.rows() + 100; }},
      {"huge_count.glb", ErrorCode::ParseError, "cannot come from",
       [&](test::GlbParts& g) { g.json["bufferViews"][0]["extensions"][ext]["count"] = 4000000000ull; }},
      {"bad_stride.glb", ErrorCode::ParseError, "byteStride 6 is not allowed",
       [&](test::GlbParts& g) { g.json["bufferViews"][0]["extensions"][ext]["byteStride"] = 6; }},
      {"bad_mode.glb", ErrorCode::ParseError, "unknown mode 'STRIPS'",
       [&](test::GlbParts& g) { g.json["bufferViews"][1]["extensions"][ext]["mode"] = "STRIPS"; }},
      {"outside_buffer.glb", ErrorCode::ParseError, "lies outside buffer 0",
       [&](test::GlbParts& g) { g.json["bufferViews"][1]["extensions"][ext]["byteOffset"] = 1u << 30; }},
      {"short_decode.glb", ErrorCode::ParseError, "byteLength says",
       [&](test::GlbParts& g) { g.json["bufferViews"][0]["byteLength"] = 8 * source.V.rows() + 64; }},
  };
  for (const Case& c : cases) {
    INFO("case " << c.name);
    test::GlbParts g = good;
    c.spoil(g);
    const std::string path = write_bytes(dir, c.name, test::glb_bytes(g));
    test::require_read_error(formats::read_mesh(path).status(), c.code, path, c.phrase);
  }
}
