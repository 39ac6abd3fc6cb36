// Tests of the levels of detail simplified from the original mesh (convert/src/original_lods.cpp,
// gltf_lods.cpp with LodMode::Original): the cut along the octahedral fold, texture coordinates
// on the sphere map at every vertex, no face across the fold, sizes and errors along the levels,
// holes kept open, texture-coordinate bits, determinism.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <vector>

#include "gltf_test_support.h"
#include "spherekit/convert/gltf_lods.h"
#include "spherekit/convert/original_lods.h"
#include "spherekit/geometry_image.h"
#include "test_meshes.h"

using namespace spherekit;
using namespace spherekit::convert;

namespace {

struct OlBlob {
  TriMesh mesh;
  RowMat3d S;
};

// An icosphere-based blob with its radial map: many vertices and edges lie exactly on the planes
// x = 0 and y = 0 (the icosahedron's vertices do), the cut's degenerate cases.
OlBlob ol_blob(std::uint64_t seed = 7) {
  OlBlob b;
  b.mesh = test::random_blob(4, seed);
  b.S = b.mesh.V.rowwise().normalized();
  return b;
}

GltfLodOptions ol_options(int levels) {
  GltfLodOptions o;
  o.mode = LodMode::Original;
  o.levels = levels;
  o.normals = false;
  o.name = "blob";
  return o;
}

// Domain point (u, v) of a glTF texture coordinate of a T x T image (inverse of
// octahedral_to_texcoord).
Eigen::Vector2d ol_domain_of(const Eigen::RowVector2d& st, int T) {
  const double j = st.x() * T - 0.5, i = st.y() * T - 0.5;
  return {-1 + 2 * j / (T - 1), -1 + 2 * i / (T - 1)};
}

double ol_signed_uv_area_sum(const GltfMesh& m) {
  double area = 0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const Eigen::RowVector2d a = m.UV.row(m.F(f, 0)), b = m.UV.row(m.F(f, 1)), c = m.UV.row(m.F(f, 2));
    area += 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
  }
  return area;
}

double ol_surface_area(const RowMat3d& V, const RowMat3i& F) {
  double a = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    a += 0.5 * (V.row(F(f, 1)) - V.row(F(f, 0))).cross(V.row(F(f, 2)) - V.row(F(f, 0))).norm();
  return a;
}

}  // namespace

TEST_CASE("Original LODs: the cut along the fold is closed, keeps the original and no face crosses x = 0 or y = 0",
          "[convert]") {
  const OlBlob b = ol_blob();
  auto cut = cut_along_octahedral_fold(b.mesh, b.S);
  REQUIRE(cut.ok());
  const RowMat3d& S = cut->S;
  const RowMat3i& F = cut->mesh.F;
  REQUIRE(cut->original_vertices == b.mesh.V.rows());
  CHECK(cut->mesh.V.topRows(b.mesh.V.rows()) == b.mesh.V);
  CHECK(cut->mesh.V.rows() > b.mesh.V.rows());  // the cut added vertices
  std::set<std::array<int, 2>> edges;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int axis = 0; axis < 2; ++axis) {
      bool pos = false, neg = false;
      for (int k = 0; k < 3; ++k) {
        pos |= S(F(f, k), axis) > 0;
        neg |= S(F(f, k), axis) < 0;
      }
      INFO("face " << f << " axis " << axis);
      CHECK(!(pos && neg));
    }
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), c = F(f, (k + 1) % 3);
      edges.insert({std::min(a, c), std::max(a, c)});
    }
  }
  // Closed genus 0: V - E + F = 2.
  CHECK(cut->mesh.V.rows() - static_cast<Eigen::Index>(edges.size()) + F.rows() == 2);
  for (Eigen::Index v = 0; v < S.rows(); ++v) CHECK(std::abs(S.row(v).norm() - 1) < 1e-12);
  // The fold's ends and the poles are vertices.
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 0, 0),
                                   Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, -1, 0)}) {
    bool found = false;
    for (Eigen::Index v = 0; v < S.rows() && !found; ++v) found = (S.row(v).transpose() - p).norm() < 1e-12;
    INFO(p.transpose());
    CHECK(found);
  }
  // Domain points: four at the -z pole (the square's corners), two on the fold, one elsewhere
  // (the fold's ends included).
  CHECK(octahedral_copies(Eigen::Vector3d(0, 0, -1)).size() == 4);
  CHECK(octahedral_copies(Eigen::Vector3d(0, 0.5, -0.5).normalized()).size() == 2);
  CHECK(octahedral_copies(Eigen::Vector3d(0, 0.5, 0.5).normalized()).size() == 1);
  CHECK(octahedral_copies(Eigen::Vector3d(0, 1, 0)).size() == 1);
}

TEST_CASE("Original LODs: texture coordinates are the sphere map's at every vertex and no face spans the fold",
          "[convert]") {
  const OlBlob b = ol_blob();
  auto cut = cut_along_octahedral_fold(b.mesh, b.S);
  REQUIRE(cut.ok());
  std::map<std::array<double, 3>, Eigen::Vector3d> sphere_of;
  for (Eigen::Index v = 0; v < cut->mesh.V.rows(); ++v)
    sphere_of[{cut->mesh.V(v, 0), cut->mesh.V(v, 1), cut->mesh.V(v, 2)}] = cut->S.row(v).transpose();
  OriginalLodOptions o;
  o.levels = 4;
  o.texture_size = 65;
  auto levels = original_lod_meshes(b.mesh, b.S, o);
  REQUIRE(levels.ok());
  REQUIRE(levels->size() == 4);
  Eigen::Index previous = std::numeric_limits<Eigen::Index>::max();
  for (std::size_t k = 0; k < levels->size(); ++k) {
    const GltfMesh& m = (*levels)[k];
    INFO("level " << k << " points " << m.V.rows() << " faces " << m.F.rows());
    CHECK(m.F.rows() < previous);
    previous = m.F.rows();
    double worst = 0;
    for (Eigen::Index p = 0; p < m.V.rows(); ++p) {
      const auto it = sphere_of.find({m.V(p, 0), m.V(p, 1), m.V(p, 2)});
      REQUIRE(it != sphere_of.end());  // every point is a vertex of the cut mesh
      const Eigen::Vector2d uv = ol_domain_of(m.UV.row(p), 65);
      worst = std::max(worst, (octahedral_to_sphere(uv.x(), uv.y()) - it->second).norm());
    }
    CHECK(worst < 1e-9);
    // The texture triangles tile the square of texel centres as one disc (the fold is its
    // boundary), so their signed areas sum to the square's whatever the flips; a face whose
    // corners take copies across the fold breaks the sum.
    CHECK(std::abs(ol_signed_uv_area_sum(m) - (64.0 / 65) * (64.0 / 65)) < 1e-9);
    // One glTF vertex per (vertex, copy): points of one vertex differ in texture coordinate.
    std::set<std::pair<int, std::array<double, 2>>> seen;
    for (Eigen::Index p = 0; p < m.V.rows(); ++p)
      CHECK(seen.insert({m.position_index[static_cast<std::size_t>(p)], {m.UV(p, 0), m.UV(p, 1)}}).second);
  }
  // Level 0 has the original's vertex count (the cut's extra vertices collapsed again, up to
  // the fold's kept vertices), level k a quarter of the previous one's.
  auto vertices = [](const GltfMesh& m) {
    return 1 + *std::max_element(m.position_index.begin(), m.position_index.end());
  };
  CHECK(vertices((*levels)[0]) == b.mesh.V.rows());
  CHECK(std::abs(vertices((*levels)[2]) - b.mesh.V.rows() / 16.0) <= 2);
}

TEST_CASE("Original LODs: sizes and errors along the levels, texture-coordinate bits, deterministic", "[convert]") {
  const OlBlob b = ol_blob();
  auto built = build_original_gltf_lods(b.mesh, b.S, 257, ol_options(4));
  REQUIRE(built.ok());
  REQUIRE(built->levels.size() == 4);
  RemeshErrorOptions eo;
  eo.samples = 20000;
  double previous_psnr = std::numeric_limits<double>::infinity();
  std::size_t previous_bytes = std::numeric_limits<std::size_t>::max();
  for (std::size_t k = 0; k < built->levels.size(); ++k) {
    const GltfLodLevel& level = built->levels[k];
    const GltfMesh& d = level.primitive.decoded.mesh;
    const double psnr = remesh_psnr(b.mesh, TriMesh{d.V, d.F}, eo);
    INFO("level " << k << " bytes " << level.glb.size() << " PSNR " << psnr << " bits "
                  << level.quantization.quantization.position_bits);
    CHECK(psnr < previous_psnr);
    CHECK(level.glb.size() < previous_bytes);
    previous_psnr = psnr;
    previous_bytes = level.glb.size();
    // Half a texel of the 257 x 257 image at level 0: 8 bits on the coordinates' box; a bit
    // fewer per level (edges twice as long, shown at half the size).
    CHECK(level.quantization.quantization.texcoord_bits == 8 - static_cast<int>(k));
    CHECK(level.primitive.decoded.mesh.UV.rows() > 0);
    CHECK(level.primitive.decoded.mesh.N.rows() == 0);
  }
  // Each level's bitstream is the smaller of Draco's two texture-coordinate predictors.
  for (const GltfLodLevel& level : built->levels) {
    DracoEncodeOptions e;
    e.quantization = level.quantization.quantization;
    e.compression_level = 7;
    auto plain = encode_draco_primitive(level.mesh, e);
    e.smallest_texcoord_prediction = true;
    auto smallest = encode_draco_primitive(level.mesh, e);
    REQUIRE(plain.ok());
    REQUIRE(smallest.ok());
    CHECK(smallest->bytes.size() <= plain->bytes.size());
    CHECK(smallest->decoded.mesh.UV.rows() == plain->decoded.mesh.UV.rows());
  }
  // Level 0 is the original up to the cut: the 14-bit grid's error alone.
  CHECK(remesh_psnr(b.mesh, TriMesh{built->levels[0].primitive.decoded.mesh.V, built->levels[0].primitive.decoded.mesh.F},
                    eo) > 80);
  // The mode is recorded in the combined file; a level's own file carries no quantization.
  CHECK(built->combined_glb.find("\"lod_mode\":\"original\"") != std::string::npos);
  CHECK(built->levels[0].glb.find("lod_mode") == std::string::npos);
  auto again = build_original_gltf_lods(b.mesh, b.S, 257, ol_options(4));
  REQUIRE(again.ok());
  CHECK(again->combined_glb == built->combined_glb);
  for (std::size_t k = 0; k < 4; ++k) CHECK(again->levels[k].glb == built->levels[k].glb);
}

TEST_CASE("Original LODs without texture coordinates: the same surfaces, one point per vertex, smaller files",
          "[convert]") {
  const OlBlob b = ol_blob();
  auto with = build_original_gltf_lods(b.mesh, b.S, 257, ol_options(3));
  GltfLodOptions o = ol_options(3);
  o.texcoords = false;
  auto without = build_original_gltf_lods(b.mesh, b.S, 257, o);
  REQUIRE(with.ok());
  REQUIRE(without.ok());
  for (std::size_t k = 0; k < 3; ++k) {
    const GltfLodLevel& a = with->levels[k];
    const GltfLodLevel& g = without->levels[k];
    INFO("level " << k << ": " << a.glb.size() << " -> " << g.glb.size() << " bytes");
    // The same triangles: the fold's copies of a vertex (two, four at the pole) are one point.
    CHECK(g.mesh.F.rows() == a.mesh.F.rows());
    CHECK(g.mesh.UV.rows() == 0);
    CHECK(g.primitive.decoded.mesh.UV.rows() == 0);
    const std::set<std::int32_t> vertices(a.mesh.position_index.begin(), a.mesh.position_index.end());
    CHECK(g.mesh.V.rows() == static_cast<Eigen::Index>(vertices.size()));
    CHECK(g.mesh.V.rows() < a.mesh.V.rows());
    CHECK(g.primitive.decoded.mesh.V.rows() == g.mesh.V.rows());
    for (Eigen::Index f = 0; f < a.mesh.F.rows(); ++f)
      for (int c = 0; c < 3; ++c) REQUIRE(g.mesh.V.row(g.mesh.F(f, c)) == a.mesh.V.row(a.mesh.F(f, c)));
    CHECK(g.glb.size() < a.glb.size());
    // The level file names the texture's side only when it has texture coordinates.
    CHECK(a.glb.find("texture_size") != std::string::npos);
    CHECK(g.glb.find("texture_size") == std::string::npos);
  }
}

TEST_CASE("Original LODs: the decoded texture coordinates stay within about half a texel", "[convert]") {
  const OlBlob b = ol_blob(8);
  for (int T : {65, 257}) {
    auto built = build_original_gltf_lods(b.mesh, b.S, T, ol_options(2));
    REQUIRE(built.ok());
    for (const GltfLodLevel& level : built->levels) {
      // Half a grid step: (T - 1) / (2^b - 1) texels on the coordinates' box at most (0.502
      // texel at level 0, T = 257; twice as much per coarser level, one bit fewer).
      const int bits = level.quantization.quantization.texcoord_bits;
      const double half_step_texels = 0.5 * (T - 1) / (std::ldexp(1.0, bits) - 1);
      // Edgebreaker may reorder the points: each decoded point against the source points at
      // its position (within the position grid's half step), the nearest texture coordinate.
      const GltfMesh& d = level.primitive.decoded.mesh;
      const double half_step = level.quantization.quantization.position_step() / 2 * 1.01;  // Draco rounds in float
      double worst = 0, worst_position = 0;
      for (Eigen::Index p = 0; p < d.UV.rows(); ++p) {
        double best = std::numeric_limits<double>::infinity(), nearest = best;
        for (Eigen::Index q = 0; q < level.mesh.V.rows(); ++q)
          nearest = std::min(nearest, (d.V.row(p) - level.mesh.V.row(q)).cwiseAbs().maxCoeff());
        worst_position = std::max(worst_position, nearest / half_step);
        for (Eigen::Index q = 0; q < level.mesh.UV.rows(); ++q)
          if ((d.V.row(p) - level.mesh.V.row(q)).cwiseAbs().maxCoeff() <= half_step)
            best = std::min(best, (d.UV.row(p) - level.mesh.UV.row(q)).cwiseAbs().maxCoeff());
        worst = std::max(worst, best);
      }
      INFO("T " << T << " worst " << worst * T << " texels; position " << worst_position << " half steps");
      CHECK(worst * T <= half_step_texels * 1.01);
      if (&level == &built->levels[0]) CHECK(half_step_texels <= 0.51);
    }
  }
}

TEST_CASE("Original LODs of a mesh with holes: the holes stay open and the surface keeps its area", "[convert]") {
  const test::HoledLodImages holed = test::holed_lod_images(33, 1);
  const double area = ol_surface_area(holed.mesh.V, holed.mesh.F);
  auto built = build_original_gltf_lods(holed.mesh, holed.S, 33, ol_options(2));
  REQUIRE(built.ok());
  for (const GltfLodLevel& level : built->levels) {
    const GltfMesh& d = level.primitive.decoded.mesh;
    INFO("faces " << d.F.rows() << " area ratio " << ol_surface_area(d.V, d.F) / area);
    CHECK(std::abs(ol_surface_area(d.V, d.F) / area - 1) < 0.08);  // level 1: 0.953
  }
}

TEST_CASE("Original LODs: bad input", "[convert]") {
  const OlBlob b = ol_blob();
  OriginalLodOptions o;
  o.levels = 0;
  CHECK(original_lod_meshes(b.mesh, b.S, o).status().code() == ErrorCode::InvalidArgument);
  o.levels = 2;
  o.texture_size = 64;
  CHECK(original_lod_meshes(b.mesh, b.S, o).status().code() == ErrorCode::InvalidArgument);
  o.texture_size = 65;
  CHECK(original_lod_meshes(b.mesh, b.S.topRows(10), o).status().code() == ErrorCode::InvalidInput);
  RowMat3d zero = b.S;
  zero.row(3).setZero();
  CHECK(original_lod_meshes(b.mesh, zero, o).status().code() == ErrorCode::InvalidInput);
  GltfLodOptions g = ol_options(2);
  g.texcoord_max_error_texels = 0;
  CHECK(build_original_gltf_lods(b.mesh, b.S, 65, g).status().code() == ErrorCode::InvalidArgument);
}
