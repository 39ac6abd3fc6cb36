// Tests of the glTF primitive builders (convert/src/gltf_mesh.cpp) and of Draco encoding with
// quantization from an error budget (convert/src/gltf_draco.cpp).
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <string>

#include "gltf_test_support.h"
#include "spherekit/convert/gltf_draco.h"
#include "spherekit/convert/gltf_mesh.h"
#include "spherekit/geometry_image.h"
#include "test_meshes.h"

using namespace spherekit;
using namespace spherekit::convert;

namespace {

// The texel (row, column) of a texel-centre texture coordinate of a T x T texture.
std::array<int, 2> texel_of(double s, double t, int T) {
  return {static_cast<int>(std::lround(t * T - 0.5)), static_cast<int>(std::lround(s * T - 0.5))};
}

// A face as the sorted triple of its corners' texels, rotated to start at the smallest (keeps
// the orientation): comparable across point orders.
using FaceKey = std::array<int, 3>;
FaceKey face_key(int a, int b, int c) {
  if (b < a && b < c) return {b, c, a};
  if (c < a && c < b) return {c, a, b};
  return {a, b, c};
}

}  // namespace

TEST_CASE("glTF primitive of a geometry image: texel points, geometry_image_mesh's faces", "[convert]") {
  const GeometryImage gi = test::blob_geometry_image(17);
  auto r = gltf_mesh_from_geometry_image(gi);
  REQUIRE(r.ok());
  const GltfMesh& m = r.value();
  REQUIRE(check_gltf_mesh(m).ok());
  CHECK(m.V.rows() == 17 * 17);
  CHECK(m.texture_size == 17);
  // Through position_index the faces are exactly geometry_image_mesh's, on its vertices.
  const TriMesh remesh = geometry_image_mesh(gi);
  REQUIRE(m.F.rows() == remesh.F.rows());
  RowMat3i welded = m.F;
  for (Eigen::Index f = 0; f < welded.rows(); ++f)
    for (int k = 0; k < 3; ++k) welded(f, k) = m.position_index[static_cast<std::size_t>(m.F(f, k))];
  CHECK(welded == remesh.F);
  for (Eigen::Index p = 0; p < m.V.rows(); ++p)
    REQUIRE(m.V.row(p) == remesh.V.row(m.position_index[static_cast<std::size_t>(p)]));
  // Texel centres: point (i, j) has ((j + 1/2)/T, (i + 1/2)/T).
  CHECK(m.UV(0, 0) == Approx(0.5 / 17));
  CHECK(m.UV(17 * 3 + 5, 0) == Approx(5.5 / 17));
  CHECK(m.UV(17 * 3 + 5, 1) == Approx(3.5 / 17));
  // Only folded border pairs share a vertex: (N-2)^2 + 2N - 1 vertices.
  const int vertices = *std::max_element(m.position_index.begin(), m.position_index.end()) + 1;
  CHECK(vertices == 15 * 15 + 2 * 17 - 1);
  for (Eigen::Index p = 0; p < m.N.rows(); ++p) REQUIRE(m.N.row(p).norm() == Approx(1.0).margin(1e-12));
}

TEST_CASE("subsampling a geometry image equals sampling at the smaller size", "[convert]") {
  const TriMesh blob = test::random_blob(3, 7);
  const RowMat3d S = blob.V.rowwise().normalized();
  auto big = sample_geometry_image(blob, S, 33);
  auto small = sample_geometry_image(blob, S, 17);
  REQUIRE(big.ok());
  REQUIRE(small.ok());
  auto sub = subsample_geometry_image(big.value(), 17);
  REQUIRE(sub.ok());
  CHECK(sub->positions == small->positions);
  CHECK(sub->normals == small->normals);
  CHECK(sub->face_ids == small->face_ids);
  CHECK(subsample_geometry_image(big.value(), 65).status().code() == ErrorCode::InvalidArgument);
  CHECK(subsample_geometry_image(big.value(), 16).status().code() == ErrorCode::InvalidArgument);
  // A coarse level keeps the full image's texture coordinates.
  auto coarse = gltf_mesh_from_geometry_image(sub.value(), 33);
  REQUIRE(coarse.ok());
  CHECK(coarse->UV(1, 0) == Approx(2.5 / 33));
  CHECK(gltf_mesh_from_geometry_image(sub.value(), 25).status().code() == ErrorCode::InvalidArgument);
}

TEST_CASE("Draco quantization from an error budget", "[convert]") {
  auto m = gltf_mesh_from_geometry_image(test::blob_geometry_image(33));
  REQUIRE(m.ok());
  QuantizationBudget budget;

  SECTION("no reference error: the floor decides") {
    auto q = choose_draco_quantization(m.value(), 0, budget);
    REQUIRE(q.ok());
    CHECK(q->quantization.position_bits == 14);
    CHECK(q->quantization.normal_bits == 10);
    // A 33 x 33 texel lattice: the fewest bits holding it, one grid step per texel.
    CHECK(q->quantization.texcoord_bits == 6);
    CHECK(q->quantization.texcoord_step() == Approx(1.0 / 33));
    CHECK(q->position_max_error == Approx(q->quantization.position_step() / 2));
    // The grid is the bounding box as a cube of its largest extent.
    const double extent = (m->V.colwise().maxCoeff() - m->V.colwise().minCoeff()).maxCoeff();
    CHECK(q->quantization.position_range == Approx(extent));
    for (int c = 0; c < 3; ++c) CHECK(q->quantization.position_origin[static_cast<std::size_t>(c)] == Approx(m->V.col(c).minCoeff()));
  }
  SECTION("the fewest bits meeting the budget") {
    for (double reference : {1e-3, 1e-4, 1e-5, 1e-6}) {
      auto q = choose_draco_quantization(m.value(), reference, budget);
      REQUIRE(q.ok());
      const DracoQuantization& d = q->quantization;
      INFO("reference " << reference << " bits " << d.position_bits);
      if (d.position_bits < budget.max_position_bits)
        CHECK(d.position_step() / 2 <= budget.position_error_fraction * reference);
      if (d.position_bits > budget.min_position_bits) {
        DracoQuantization fewer = d;
        --fewer.position_bits;
        CHECK(fewer.position_step() / 2 > budget.position_error_fraction * reference);
      }
      CHECK(q->reference_rms_error == reference);
    }
    auto tight = choose_draco_quantization(m.value(), 1e-12, budget);
    REQUIRE(tight.ok());
    CHECK(tight->quantization.position_bits == budget.max_position_bits);
  }
  SECTION("texture coordinates: every texel centre is a grid value") {
    auto q = choose_draco_quantization(m.value(), 0, budget);
    REQUIRE(q.ok());
    const DracoQuantization& d = q->quantization;
    for (int j = 0; j < 33; ++j) {
      const double k = ((j + 0.5) / 33 - d.texcoord_origin[0]) / d.texcoord_step();
      REQUIRE(std::abs(k - std::round(k)) < 1e-3);
      REQUIRE(std::round(k) <= std::ldexp(1.0, d.texcoord_bits) - 1);
    }
    // A large texture needs more bits: 2^bits - 1 >= T - 1.
    GltfMesh big = m.value();
    big.texture_size = 8193;
    big.UV *= 33.0 / 8193;
    auto qb = choose_draco_quantization(big, 0, budget);
    REQUIRE(qb.ok());
    CHECK(qb->quantization.texcoord_bits == 14);
  }
  SECTION("invalid budgets") {
    QuantizationBudget bad = budget;
    bad.min_position_bits = 31;
    CHECK(choose_draco_quantization(m.value(), 0, bad).status().code() == ErrorCode::InvalidArgument);
    bad = budget;
    bad.min_position_bits = 20;
    bad.max_position_bits = 16;
    CHECK(choose_draco_quantization(m.value(), 0, bad).status().code() == ErrorCode::InvalidArgument);
    bad = budget;
    bad.position_error_fraction = 0;
    CHECK(choose_draco_quantization(m.value(), 0, bad).status().code() == ErrorCode::InvalidArgument);
    CHECK(choose_draco_quantization(GltfMesh{}, 0, budget).status().code() == ErrorCode::InvalidInput);
  }
}

TEST_CASE("Draco edgebreaker round trip: same surface, positions within half a grid step", "[convert]") {
  const GeometryImage gi = test::blob_geometry_image(33);
  auto m = gltf_mesh_from_geometry_image(gi);
  REQUIRE(m.ok());
  auto q = choose_draco_quantization(m.value(), 0);
  REQUIRE(q.ok());
  DracoEncodeOptions options;
  options.quantization = q->quantization;
  auto enc = encode_draco_primitive(m.value(), options);
  REQUIRE(enc.ok());
  const GltfMesh& d = enc->decoded.mesh;
  CHECK(enc->decoded.position_id >= 0);
  CHECK(enc->decoded.normal_id >= 0);
  CHECK(enc->decoded.texcoord_id >= 0);
  REQUIRE(d.N.rows() == d.V.rows());
  REQUIRE(d.UV.rows() == d.V.rows());
  CHECK(d.F.rows() == m->F.rows());
  // The library's decode is the independent decoder's (draco::Decoder by unique id, in
  // gltf_test_support) on the same bytes.
  auto again = decode_draco_primitive(enc->bytes);
  REQUIRE(again.ok());
  CHECK(again->mesh.V == d.V);

  // Each decoded point is a texel (its texture coordinate is a texel centre, exactly up to
  // float rounding), its position within half a grid step per coordinate, its normal within
  // the octahedral quantization's error.
  const double half_step = q->quantization.position_step() / 2;
  const double float_slack = 4 * 1.2e-7 * (q->quantization.position_range + 2);
  double worst_position = 0, worst_normal = 0, worst_uv = 0;
  std::vector<int> texel_of_point(static_cast<std::size_t>(d.V.rows()));
  std::set<int> texels;
  for (Eigen::Index p = 0; p < d.V.rows(); ++p) {
    const auto [i, j] = texel_of(d.UV(p, 0), d.UV(p, 1), 33);
    REQUIRE(i >= 0);
    REQUIRE(i < 33);
    REQUIRE(j >= 0);
    REQUIRE(j < 33);
    worst_uv = std::max({worst_uv, std::abs(d.UV(p, 0) - (j + 0.5) / 33), std::abs(d.UV(p, 1) - (i + 0.5) / 33)});
    worst_position =
        std::max(worst_position, (d.V.row(p) - gi.position(i, j).cast<double>().transpose()).cwiseAbs().maxCoeff());
    worst_normal = std::max(worst_normal, (d.N.row(p) - gi.normal(i, j).cast<double>().transpose()).norm());
    texel_of_point[static_cast<std::size_t>(p)] = i * 33 + j;
    texels.insert(i * 33 + j);
  }
  CHECK(worst_position <= half_step + float_slack);
  CHECK(worst_uv < 1e-6);
  // 10-bit octahedral normals (Draco OctahedronToolBox): grid step 2/(2^10 - 2) on the square,
  // rounding moves a point by at most sqrt(2)/(2^10 - 2) there; square -> octahedron stretches
  // lengths by at most sqrt(3) and the central projection onto the sphere (|q| >= 1/sqrt(3)) by
  // at most sqrt(3) more.
  CHECK(worst_normal <= 3 * std::sqrt(2.0) / (1024 - 2) + 1e-6);
  // Every texel survives as a point, and the faces are the same triangles over texels.
  CHECK(texels.size() == 33u * 33u);
  std::set<FaceKey> original, decoded;
  for (Eigen::Index f = 0; f < m->F.rows(); ++f) original.insert(face_key(m->F(f, 0), m->F(f, 1), m->F(f, 2)));
  for (Eigen::Index f = 0; f < d.F.rows(); ++f)
    decoded.insert(face_key(texel_of_point[static_cast<std::size_t>(d.F(f, 0))],
                            texel_of_point[static_cast<std::size_t>(d.F(f, 1))],
                            texel_of_point[static_cast<std::size_t>(d.F(f, 2))]));
  CHECK(decoded == original);
  // glTF front faces are counter-clockwise: every decoded triangle's winding agrees with the
  // NORMALs at its corners (the blob is smooth, so no face is near the silhouette of its own
  // normals).
  int disagreeing = 0;
  for (Eigen::Index f = 0; f < d.F.rows(); ++f) {
    const Eigen::RowVector3d a = d.V.row(d.F(f, 0)), b = d.V.row(d.F(f, 1)), c = d.V.row(d.F(f, 2));
    const Eigen::RowVector3d n = d.N.row(d.F(f, 0)) + d.N.row(d.F(f, 1)) + d.N.row(d.F(f, 2));
    disagreeing += (b - a).cross(c - a).dot(n) <= 0;
  }
  CHECK(disagreeing == 0);
}

TEST_CASE("Draco sequential encoding keeps the point and face order", "[convert]") {
  auto m = gltf_mesh_from_geometry_image(test::blob_geometry_image(17));
  REQUIRE(m.ok());
  auto q = choose_draco_quantization(m.value(), 0);
  REQUIRE(q.ok());
  DracoEncodeOptions options;
  options.quantization = q->quantization;
  options.sequential = true;
  auto enc = encode_draco_primitive(m.value(), options);
  REQUIRE(enc.ok());
  const GltfMesh& d = enc->decoded.mesh;
  REQUIRE(d.V.rows() == m->V.rows());
  CHECK(d.F == m->F);
  CHECK((d.V - m->V).cwiseAbs().maxCoeff() <= q->quantization.position_step() / 2 + 1e-6);
  CHECK((d.UV - m->UV).cwiseAbs().maxCoeff() < 1e-6);
}

TEST_CASE("Draco encoding is deterministic", "[convert]") {
  auto m = gltf_mesh_from_geometry_image(test::blob_geometry_image(17));
  REQUIRE(m.ok());
  auto q = choose_draco_quantization(m.value(), 0);
  REQUIRE(q.ok());
  DracoEncodeOptions options;
  options.quantization = q->quantization;
  auto a = encode_draco_primitive(m.value(), options), b = encode_draco_primitive(m.value(), options);
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  CHECK(a->bytes == b->bytes);
  // Vertex numbers are only labels: gaps in position_index change nothing.
  GltfMesh sparse = m.value();
  for (std::int32_t& v : sparse.position_index) v *= 3;
  auto c = encode_draco_primitive(sparse, options);
  REQUIRE(c.ok());
  CHECK(c->bytes == a->bytes);
}

TEST_CASE("Draco encoding and decoding errors", "[convert]") {
  auto m = gltf_mesh_from_geometry_image(test::blob_geometry_image(9));
  REQUIRE(m.ok());
  auto q = choose_draco_quantization(m.value(), 0);
  REQUIRE(q.ok());
  DracoEncodeOptions options;
  options.quantization = q->quantization;

  DracoEncodeOptions bad = options;
  bad.compression_level = 11;
  CHECK(encode_draco_primitive(m.value(), bad).status().code() == ErrorCode::InvalidArgument);
  bad = options;
  bad.quantization.position_range = 0;
  CHECK(encode_draco_primitive(m.value(), bad).status().code() == ErrorCode::InvalidArgument);
  // A point outside the grid.
  bad = options;
  bad.quantization.position_range *= 0.5f;
  CHECK(encode_draco_primitive(m.value(), bad).status().code() == ErrorCode::InvalidInput);
  // Points of one vertex with different positions.
  GltfMesh split = m.value();
  split.V(0, 0) += 1e-3;
  auto qs = choose_draco_quantization(split, 0);
  REQUIRE(qs.ok());
  DracoEncodeOptions split_options;
  split_options.quantization = qs->quantization;
  auto split_result = encode_draco_primitive(split, split_options);
  CHECK(split_result.status().code() == ErrorCode::InvalidInput);
  CHECK(split_result.status().message().find("position_index") != std::string::npos);
  // Malformed primitives.
  GltfMesh broken = m.value();
  broken.F(0, 0) = static_cast<std::int32_t>(broken.V.rows());
  CHECK(check_gltf_mesh(broken).code() == ErrorCode::InvalidInput);
  broken = m.value();
  broken.N.conservativeResize(3, 3);
  CHECK(encode_draco_primitive(broken, options).status().code() == ErrorCode::InvalidInput);
  broken = m.value();
  broken.V(2, 1) = std::nan("");
  CHECK(check_gltf_mesh(broken).code() == ErrorCode::InvalidInput);
  // Garbage is not a Draco mesh.
  CHECK(decode_draco_primitive("not a draco bitstream").status().code() == ErrorCode::ParseError);
}

TEST_CASE("glTF primitive of a triangle mesh: area-weighted unit normals", "[convert]") {
  const TriMesh ico = test::icosphere(2);
  auto m = gltf_mesh_from_trimesh(ico);
  REQUIRE(m.ok());
  CHECK(m->V == ico.V);
  CHECK(m->F == ico.F);
  CHECK(m->UV.rows() == 0);
  CHECK(m->position_index.empty());
  // On a sphere centred at the origin the normals point outwards along the positions.
  for (Eigen::Index v = 0; v < ico.V.rows(); ++v) REQUIRE(m->N.row(v).dot(ico.V.row(v).normalized()) > 0.99);
  CHECK(gltf_mesh_from_trimesh(TriMesh{}).status().code() == ErrorCode::InvalidInput);
}

TEST_CASE("hole faces of a glTF primitive are found through its texture coordinates", "[convert]") {
  const TriMesh holed = test::sphere_with_holes(3, 2);
  auto gi = sample_geometry_image(holed, holed.V.rowwise().normalized(), 33);
  REQUIRE(gi.ok());
  REQUIRE(gi->texels_in_holes > 0);
  auto m = gltf_mesh_from_geometry_image(gi.value());
  REQUIRE(m.ok());
  // Before encoding the faces are geometry_image_mesh's, in its order.
  const std::vector<std::uint8_t> expected = geometry_image_hole_faces(gi.value());
  CHECK(gltf_mesh_hole_faces(m.value(), gi.value()) == expected);
  // After a Draco round trip (points and faces reordered) the same number of faces.
  auto q = choose_draco_quantization(m.value(), 0);
  REQUIRE(q.ok());
  DracoEncodeOptions options;
  options.quantization = q->quantization;
  auto enc = encode_draco_primitive(m.value(), options);
  REQUIRE(enc.ok());
  const std::vector<std::uint8_t> decoded = gltf_mesh_hole_faces(enc->decoded.mesh, gi.value());
  CHECK(std::count(decoded.begin(), decoded.end(), 1) == std::count(expected.begin(), expected.end(), 1));
  // A primitive without texture coordinates has no texels to ask about.
  CHECK(gltf_mesh_hole_faces(gltf_mesh_from_trimesh(holed).value(), gi.value()).empty());
}

TEST_CASE("a primitive without some faces keeps the rest in order and drops unused points", "[convert]") {
  const GeometryImage gi = test::blob_geometry_image(9);
  auto full = gltf_mesh_from_geometry_image(gi);
  REQUIRE(full.ok());
  const GltfMesh& m = full.value();
  // Drop every face touching point 40 (the image's centre texel, (4, 4), an octahedron
  // vertex): that point goes, no other does (each neighbour keeps a face elsewhere).
  std::vector<std::uint8_t> drop(static_cast<std::size_t>(m.F.rows()), 0);
  int dropped = 0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    if (m.F(f, 0) == 40 || m.F(f, 1) == 40 || m.F(f, 2) == 40) drop[static_cast<std::size_t>(f)] = 1, ++dropped;
  REQUIRE(dropped == 4);  // the octahedron's vertices have valence 4
  const GltfMesh out = gltf_mesh_without_faces(m, drop);
  REQUIRE(out.V.rows() == m.V.rows() - 1);
  REQUIRE(out.F.rows() == m.F.rows() - dropped);
  CHECK(out.N.rows() == out.V.rows());
  CHECK(out.UV.rows() == out.V.rows());
  CHECK(out.position_index.size() == static_cast<std::size_t>(out.V.rows()));
  CHECK(out.texture_size == m.texture_size);
  CHECK(check_gltf_mesh(out).ok());
  // Points after 40 move down by one; faces keep their order and their corners' data.
  Eigen::Index row = 0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    if (drop[static_cast<std::size_t>(f)]) continue;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Index p = m.F(f, k), q = out.F(row, k);
      REQUIRE(q == (p < 40 ? p : p - 1));
      REQUIRE(out.V.row(q) == m.V.row(p));
      REQUIRE(out.UV.row(q) == m.UV.row(p));
      REQUIRE(out.position_index[static_cast<std::size_t>(q)] == m.position_index[static_cast<std::size_t>(p)]);
    }
    ++row;
  }
  // No flags, or flags of the wrong count: unchanged.
  CHECK(gltf_mesh_without_faces(m, {}).F == m.F);
  CHECK(gltf_mesh_without_faces(m, std::vector<std::uint8_t>(3, 1)).V == m.V);
}

TEST_CASE("a primitive without texture coordinates: the copies of a vertex become one point", "[convert]") {
  const GeometryImage gi = test::blob_geometry_image(9);
  auto full = gltf_mesh_from_geometry_image(gi);
  REQUIRE(full.ok());
  const GltfMesh& m = full.value();
  const std::set<std::int32_t> vertices(m.position_index.begin(), m.position_index.end());
  REQUIRE(vertices.size() < static_cast<std::size_t>(m.V.rows()));  // the folded border pairs
  const GltfMesh out = gltf_mesh_without_texcoords(m);
  CHECK(check_gltf_mesh(out).ok());
  CHECK(out.V.rows() == static_cast<Eigen::Index>(vertices.size()));
  CHECK(out.UV.rows() == 0);
  CHECK(out.N.rows() == out.V.rows());
  CHECK(out.position_index.empty());
  CHECK(out.texture_size == 0);
  // Same faces in the same order, each corner at the same position; copies now one point.
  REQUIRE(out.F.rows() == m.F.rows());
  std::map<std::int32_t, Eigen::Index> point_of_vertex;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      REQUIRE(out.V.row(out.F(f, k)) == m.V.row(m.F(f, k)));
      const auto [it, fresh] = point_of_vertex.emplace(m.position_index[static_cast<std::size_t>(m.F(f, k))], out.F(f, k));
      REQUIRE(it->second == out.F(f, k));
    }
  // Encoded, the surface has no seam left: Draco decodes one point per vertex.
  DracoEncodeOptions e;
  auto q = choose_draco_quantization(out, 0.0, QuantizationBudget{});
  REQUIRE(q.ok());
  e.quantization = q->quantization;
  auto p = encode_draco_primitive(out, e);
  REQUIRE(p.ok());
  CHECK(p->decoded.mesh.V.rows() == out.V.rows());
  CHECK(p->decoded.mesh.UV.rows() == 0);
  // A mesh the check refuses: unchanged.
  GltfMesh bad = m;
  bad.position_index.pop_back();
  CHECK(gltf_mesh_without_texcoords(bad).UV.rows() == bad.UV.rows());
}
