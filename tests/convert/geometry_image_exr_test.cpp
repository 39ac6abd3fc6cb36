// Tests of the geometry-image EXR writer/reader (convert/src/geometry_image_exr.cpp).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <filesystem>
#include <string>

#include "spherekit/convert/geometry_image_exr.h"
#include "spherekit/convert/geometry_image_png.h"
#include "spherekit/geometry_image.h"
#include "spherekit/version.h"
#include "test_meshes.h"
#include "test_paths.h"

namespace fs = std::filesystem;
using namespace spherekit;

TEST_CASE("geometry image EXR: write/read round trip is bit-exact with provenance", "[convert]") {
  const TriMesh blob = test::random_blob(3, 9);
  auto r = sample_geometry_image(blob, blob.V.rowwise().normalized(), 33);
  REQUIRE(r.ok());
  const GeometryImage& gi = r.value();
  const std::string dir = test::temp_dir("gim_exr_roundtrip");
  const std::string path = dir + "/blob.exr";
  REQUIRE(convert::write_geometry_image_exr(path, gi, {"blob.obj", "blob.sphere.obj"}).ok());
  // Only the output: the temporary file was renamed.
  int files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
  CHECK(files == 1);

  auto back = convert::read_geometry_image_exr(path);
  REQUIRE(back.ok());
  const GeometryImage& g2 = back->image;
  REQUIRE(g2.size == 33);
  REQUIRE(g2.positions.size() == gi.positions.size());
  CHECK(std::memcmp(g2.positions.data(), gi.positions.data(), gi.positions.size() * sizeof(float)) == 0);
  CHECK(std::memcmp(g2.normals.data(), gi.normals.data(), gi.normals.size() * sizeof(float)) == 0);
  CHECK(g2.face_ids == gi.face_ids);
  CHECK(g2.in_hole == gi.in_hole);
  const auto& at = back->attributes;
  CHECK(at.at("spherekit_version") == kVersion);
  CHECK(at.at("source_mesh") == "blob.obj");
  CHECK(at.at("sphere_map") == "blob.sphere.obj");
  CHECK(at.at("resolution") == "33");
  CHECK(at.at("layout") == "octahedral");

  // The remesh of the read image equals the remesh of the original.
  const TriMesh a = geometry_image_mesh(gi), b = geometry_image_mesh(g2);
  CHECK(a.V == b.V);
  CHECK(a.F == b.F);
}

TEST_CASE("geometry image EXR: errors", "[convert]") {
  GeometryImage bad;
  bad.size = 4;
  const std::string dir = test::temp_dir("gim_exr_errors");
  Status s = convert::write_geometry_image_exr(dir + "/bad.exr", bad);
  CHECK(s.code() == ErrorCode::InvalidArgument);
  CHECK_FALSE(fs::exists(dir + "/bad.exr"));

  const TriMesh ico = test::icosphere(1);
  auto r = sample_geometry_image(ico, ico.V.rowwise().normalized(), 9);
  REQUIRE(r.ok());
  s = convert::write_geometry_image_exr(dir + "/no/such/folder/x.exr", r.value());
  CHECK(s.code() == ErrorCode::IoError);

  auto missing = convert::read_geometry_image_exr(dir + "/missing.exr");
  REQUIRE_FALSE(missing.ok());
  CHECK(missing.status().code() == ErrorCode::IoError);
  CHECK(missing.status().message().find("missing.exr") != std::string::npos);
}

TEST_CASE("geometry image previews: normals and positions as colours, holes dimmed", "[convert]") {
  const TriMesh blob = test::random_blob(3, 9);
  auto r = sample_geometry_image(blob, blob.V.rowwise().normalized(), 17);
  REQUIRE(r.ok());
  GeometryImage gi = r.value();
  auto normals = convert::geometry_image_preview(gi, convert::GeometryImagePreview::Normals);
  REQUIRE(normals.ok());
  REQUIRE(normals->width == 17);
  REQUIRE(normals->height == 17);
  REQUIRE(normals->channels == 3);
  // Pixel (x, y) is texel (i = y, j = x): each channel is the normal mapped [-1, 1] -> [0, 255].
  for (int i = 0; i < 17; i += 4)
    for (int j = 0; j < 17; j += 3) {
      const Eigen::Vector3f n = gi.normal(i, j);
      for (int c = 0; c < 3; ++c) CHECK(std::abs(normals->at(j, i)[c] - 127.5 * (n[c] + 1)) <= 0.5 + 1e-3);
    }
  // Positions: the bounding box's largest extent spans 0..255 (up to rounding) on some channel.
  auto pos = convert::geometry_image_preview(gi, convert::GeometryImagePreview::Positions);
  REQUIRE(pos.ok());
  int lo = 255, hi = 0;
  for (std::size_t k = 0; k < pos->pixels.size(); ++k) {
    lo = std::min<int>(lo, pos->pixels[k]);
    hi = std::max<int>(hi, pos->pixels[k]);
  }
  CHECK(lo <= 1);
  CHECK(hi >= 254);
  // A texel marked as lying in a hole is drawn at half brightness.
  gi.in_hole[5 * 17 + 7] = 1;
  auto dimmed = convert::geometry_image_preview(gi, convert::GeometryImagePreview::Normals);
  REQUIRE(dimmed.ok());
  for (int c = 0; c < 3; ++c) CHECK(std::abs(2 * dimmed->at(7, 5)[c] - normals->at(7, 5)[c]) <= 2);
  CHECK(dimmed->at(8, 5)[0] == normals->at(8, 5)[0]);
  // Deterministic bytes, and malformed images are refused.
  auto again = convert::geometry_image_preview(gi, convert::GeometryImagePreview::Normals);
  REQUIRE(again.ok());
  CHECK(again->pixels == dimmed->pixels);
  GeometryImage bad = gi;
  bad.normals.pop_back();
  CHECK(convert::geometry_image_preview(bad, convert::GeometryImagePreview::Normals).status().code() ==
        ErrorCode::InvalidArgument);
  bad = gi;
  bad.positions[4] = std::numeric_limits<float>::quiet_NaN();
  CHECK(convert::geometry_image_preview(bad, convert::GeometryImagePreview::Positions).status().code() ==
        ErrorCode::InvalidArgument);
}
