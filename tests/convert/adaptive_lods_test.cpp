// Tests of the adaptive levels of detail (convert/src/adaptive_lods.cpp, gltf_lods.cpp with
// LodMode::Adaptive): one connectivity for every member of a collection per level, error
// growing with the level, no face across the octahedral fold, determinism.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "gltf_test_support.h"
#include "spherekit/convert/adaptive_lods.h"
#include "spherekit/convert/gltf_lods.h"
#include "spherekit/convert/gltf_morph.h"
#include "test_meshes.h"

using namespace spherekit;
using namespace spherekit::convert;

namespace {

GltfLodOptions adaptive_options(int levels) {
  GltfLodOptions o = test::lod_test_options();
  o.mode = LodMode::Adaptive;
  o.levels = levels;
  return o;
}

}  // namespace

TEST_CASE("Adaptive LODs of a collection: every member has the same connectivity at every level", "[convert]") {
  const std::vector<GeometryImage> members{test::blob_geometry_image(33, 3, 7), test::blob_geometry_image(33, 3, 8),
                                           test::blob_geometry_image(33, 3, 9)};
  const std::vector<GltfLodOptions> options(3, adaptive_options(3));
  auto built = build_consistent_gltf_lods(members, options);
  REQUIRE(built.ok());
  REQUIRE(built->size() == 3);
  Eigen::Index previous_faces = 2 * 32 * 32 + 1;
  for (std::size_t k = 0; k < 3; ++k) {
    const GltfLodLevel& a = (*built)[0].levels[k];
    CHECK(a.mesh.F.rows() < previous_faces);  // coarser with the level
    previous_faces = a.mesh.F.rows();
    for (std::size_t m = 1; m < 3; ++m) {
      const GltfLodLevel& b = (*built)[m].levels[k];
      CHECK(a.mesh.F == b.mesh.F);
      CHECK(a.mesh.UV == b.mesh.UV);
      CHECK(a.mesh.position_index == b.mesh.position_index);
      CHECK(a.mesh.V != b.mesh.V);  // different shapes, one connectivity
      // Decoded index buffers (what a loader sees) are identical too.
      CHECK(a.primitive.decoded.mesh.F == b.primitive.decoded.mesh.F);
      CHECK(a.primitive.decoded.mesh.UV == b.primitive.decoded.mesh.UV);
    }
    // Each level's members still make one morph-target glTF.
    std::vector<GltfMesh> level;
    for (std::size_t m = 0; m < 3; ++m) level.push_back((*built)[m].levels[k].mesh);
    auto morph = build_gltf_morph_targets(level);
    CHECK(morph.ok());
  }
}

TEST_CASE("Adaptive LODs: error grows with the level, no face spans the fold, deterministic", "[convert]") {
  const GeometryImage gi = test::blob_geometry_image(65, 3, 7);
  const TriMesh reference = geometry_image_mesh(gi);
  auto built = build_gltf_lods(gi, adaptive_options(4));
  REQUIRE(built.ok());
  REQUIRE(built->levels.size() == 4);
  RemeshErrorOptions eo;
  eo.samples = 20000;
  double previous = std::numeric_limits<double>::infinity();
  for (const GltfLodLevel& level : built->levels) {
    const GltfMesh& d = level.primitive.decoded.mesh;
    const double psnr = remesh_psnr(reference, TriMesh{d.V, d.F}, eo);
    INFO("faces " << d.F.rows() << " PSNR " << psnr);
    CHECK(psnr < previous);
    previous = psnr;
    // Faces keep to one side of the fold: the levels' texture triangles then tile the square
    // of texel centres as a disc, so their signed areas add up to the square's area whatever
    // the flips (the boundary's enclosed area); a face reaching across the fold breaks the sum.
    double area = 0;
    for (Eigen::Index f = 0; f < level.mesh.F.rows(); ++f) {
      const Eigen::RowVector2d a = level.mesh.UV.row(level.mesh.F(f, 0)), b = level.mesh.UV.row(level.mesh.F(f, 1)),
                               c = level.mesh.UV.row(level.mesh.F(f, 2));
      area += 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
    }
    CHECK(std::abs(std::abs(area) - (64.0 / 65) * (64.0 / 65)) < 1e-9);
  }
  CHECK(built->levels[0].mesh.F.rows() < reference.F.rows() / 2);
  auto again = build_gltf_lods(gi, adaptive_options(4));
  REQUIRE(again.ok());
  CHECK(again->combined_glb == built->combined_glb);
  for (std::size_t k = 0; k < 4; ++k) CHECK(again->levels[k].glb == built->levels[k].glb);
}

TEST_CASE("Adaptive LODs: bad options", "[convert]") {
  AdaptiveLodOptions o;
  CHECK(adaptive_lod_meshes({}, o).status().code() == ErrorCode::InvalidArgument);
  o.lod0_vertex_fraction = 0;
  CHECK(adaptive_lod_meshes({test::blob_geometry_image(17)}, o).status().code() == ErrorCode::InvalidArgument);
  o.lod0_vertex_fraction = 0.25;
  CHECK(adaptive_lod_meshes({test::blob_geometry_image(17), test::blob_geometry_image(33)}, o).status().code() ==
        ErrorCode::InvalidArgument);
  CHECK(build_consistent_gltf_lods({test::blob_geometry_image(17)}, {}).status().code() == ErrorCode::InvalidArgument);
}

namespace {

double surface_area(const RowMat3d& V, const RowMat3i& F) {
  double a = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    a += 0.5 * (V.row(F(f, 1)) - V.row(F(f, 0))).cross(V.row(F(f, 2)) - V.row(F(f, 0))).norm();
  return a;
}

}  // namespace

TEST_CASE("Adaptive LODs of a mesh with holes: the holes stay their size at every level", "[convert]") {
  // The fitted image holds hole texels on the rim (zero-area faces). Before the rim was a
  // simplifier constraint and degenerate faces stopped vetoing collapses, the simplifier
  // stalled on them, forced fold-overs, and coarse faces half over a hole were dropped with
  // their surface (bunny's coarsest level: half its area, 22.7 dB).
  const test::HoledLodImages holed = test::holed_lod_images(65, 1);
  const GeometryImage& gi = holed.levels[0];
  REQUIRE(gi.texels_in_holes > 0);
  const TriMesh open = geometry_image_open_mesh(gi);
  const double open_area = surface_area(open.V, open.F);
  // Three levels: the fourth of a 65 x 65 image has ~16 vertices, too coarse for its area to
  // say anything about holes.
  GltfLodOptions o = adaptive_options(3);
  o.drop_hole_faces = true;
  auto built = build_gltf_lods(gi, o);
  REQUIRE(built.ok());
  for (const GltfLodLevel& level : built->levels) {
    const GltfMesh& d = level.primitive.decoded.mesh;
    INFO("faces " << d.F.rows() << " area ratio " << surface_area(d.V, d.F) / open_area);
    CHECK(std::abs(surface_area(d.V, d.F) / open_area - 1) < 0.05);
  }
}

TEST_CASE("Adaptive LODs: coarse levels' position bits from their own error; no normals on request", "[convert]") {
  const GeometryImage gi = test::blob_geometry_image(65, 3, 7);
  GltfLodOptions o = adaptive_options(4);
  o.normals = false;
  o.coarse_position_bits = 6;
  auto built = build_gltf_lods(gi, o);
  REQUIRE(built.ok());
  const int shared = built->quantization.quantization.position_bits;
  CHECK(built->levels[0].quantization.quantization.position_bits == shared);
  int previous = shared;
  for (std::size_t k = 0; k < built->levels.size(); ++k) {
    const GltfLodLevel& level = built->levels[k];
    const int bits = level.quantization.quantization.position_bits;
    INFO("level " << k << " bits " << bits);
    CHECK(bits <= previous);  // coarser levels have larger errors
    CHECK(bits >= 6);
    previous = bits;
    CHECK(level.primitive.decoded.mesh.N.rows() == 0);
    CHECK(level.primitive.decoded.mesh.V.rows() > 0);
    // The quantization error stays a small part of the level's error (budget fraction 0.1).
    if (k > 0) CHECK(level.quantization.position_max_error <= 0.1 * level.quantization.reference_rms_error + 1e-12);
  }
  CHECK(built->levels.back().quantization.quantization.position_bits < shared);
  const std::string json = built->levels.back().glb.substr(20, 4000);
  CHECK(json.find("\"NORMAL\"") == std::string::npos);
}

TEST_CASE("Adaptive LODs: level 0 has no more vertices than the cap (the original mesh's count)", "[convert]") {
  const GeometryImage gi = test::blob_geometry_image(65, 3, 7);
  AdaptiveLodOptions a;
  a.levels = 3;
  auto free_levels = adaptive_lod_meshes({gi}, a);
  a.lod0_max_vertices = 300;
  auto capped = adaptive_lod_meshes({gi}, a);
  REQUIRE(free_levels.ok());
  REQUIRE(capped.ok());
  auto vertices = [](const GltfMesh& m) {
    return 1 + *std::max_element(m.position_index.begin(), m.position_index.end());
  };
  const int free0 = vertices((*free_levels)[0][0]);
  CHECK(free0 > 300);  // the cap binds
  for (std::size_t k = 0; k < 3; ++k) {
    INFO("level " << k);
    const int v = vertices((*capped)[k][0]);
    CHECK(v <= static_cast<int>(std::lround(300 / std::pow(4.0, static_cast<double>(k)))) + 8);  // + fold/corner keeps
    CHECK(v >= 6);
  }
  a.lod0_max_vertices = -1;
  CHECK(adaptive_lod_meshes({gi}, a).status().code() == ErrorCode::InvalidArgument);
}

TEST_CASE("Adaptive LODs: vertices at their clusters' quadric minima fit the surface better than texel samples",
          "[convert]") {
  const GeometryImage gi = test::blob_geometry_image(65, 3, 7);
  const TriMesh fine = geometry_image_mesh(gi);
  AdaptiveLodOptions fit, samples;
  fit.levels = samples.levels = 3;
  samples.fit_positions = false;
  auto a = adaptive_lod_meshes({gi}, fit);
  auto b = adaptive_lod_meshes({gi}, samples);
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  RemeshErrorOptions eo;
  eo.samples = 20000;
  for (std::size_t k = 0; k < 3; ++k) {
    INFO("level " << k);
    const GltfMesh& fa = (*a)[k][0];
    const GltfMesh& sb = (*b)[k][0];
    // Same faces, points and texture coordinates: only positions move.
    REQUIRE(fa.F == sb.F);
    CHECK(fa.UV == sb.UV);
    CHECK(fa.position_index == sb.position_index);
    // Points of one vertex (the fold's copies) keep one position.
    for (std::size_t p = 0; p < fa.position_index.size(); ++p)
      for (std::size_t q = p + 1; q < fa.position_index.size(); ++q)
        if (fa.position_index[p] == fa.position_index[q])
          CHECK(fa.V.row(static_cast<Eigen::Index>(p)) == fa.V.row(static_cast<Eigen::Index>(q)));
    TriMesh ma, mb;
    ma.V = fa.V;
    ma.F = fa.F;
    mb.V = sb.V;
    mb.F = sb.F;
    const RemeshError ea = remesh_error(fine, ma, eo), eb = remesh_error(fine, mb, eo);
    if (k > 0) {  // the coarse levels, where samples cut through the curved surface
      CHECK(ea.rms_forward < eb.rms_forward);
      CHECK(ea.rms < eb.rms);
    } else {
      CHECK(ea.rms <= 1.05 * eb.rms);
    }
  }
}
