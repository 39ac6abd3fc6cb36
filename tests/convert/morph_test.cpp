// Morphing between consistent remeshes: exact endpoints, similarity alignment that keeps a
// rigidly moved shape rigid, and the similarity fit itself.
#include "spherekit/convert/morph.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>

#include <Eigen/Geometry>

#include "collection_fixture.h"
#include "gltf_test_support.h"
#include "spherekit/convert/consistent_remesh.h"
#include "spherekit/convert/gltf_morph.h"
#include "spherekit/convert/similarity_fit.h"

using namespace spherekit;
using namespace spherekit::convert;

namespace {

bool same_bits(const RowMat3d& a, const RowMat3d& b) {
  return a.rows() == b.rows() && std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())) == 0;
}

Similarity example_similarity() {
  Similarity s;
  s.centre = Eigen::Vector3d(0.1, -0.2, 0.3);
  s.offset = Eigen::Vector3d(1.5, 0.25, -0.75);
  s.scale = 1.7;
  s.R = Eigen::AngleAxisd(2.2, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
  return s;
}

}  // namespace

TEST_CASE("morph frames at t = 0 and t = 1 are the remeshes exactly", "[convert][morph]") {
  const auto& c = spherekit::test::mapped_sample_collection();
  auto ra = consistent_remesh(c.members[0].mesh, c.maps[0], 33);
  auto rb = consistent_remesh(c.members[1].mesh, c.maps[1], 33);
  REQUIRE(ra.ok());
  REQUIRE(rb.ok());
  REQUIRE(ra->mesh.F == rb->mesh.F);  // consistent remeshes share their connectivity
  for (bool align : {true, false}) {
    MorphOptions o;
    o.frames = 5;
    o.align = align;
    auto seq = morph_sequence(ra->mesh, rb->mesh, c.features[0], c.features[1], o);
    REQUIRE(seq.ok());
    CHECK(seq->aligned == align);
    REQUIRE(seq->frames.size() == 5);
    CHECK(seq->times.front() == 0.0);
    CHECK(seq->times.back() == 1.0);
    CHECK(same_bits(seq->frames.front().V, ra->mesh.V));
    CHECK(same_bits(seq->frames.back().V, rb->mesh.V));
    for (const TriMesh& f : seq->frames) CHECK(f.F == ra->mesh.F);
    // In between: neither end, and the evaluated formula approaches the ends continuously.
    const RowMat3d& mid = seq->frames[2].V;
    CHECK((mid - ra->mesh.V).norm() > 0);
    CHECK((mid - rb->mesh.V).norm() > 0);
    const double near_end = (morph_frame(ra->mesh, rb->mesh, 1 - 1e-9, seq->alignment).V - rb->mesh.V).cwiseAbs().maxCoeff();
    CHECK(near_end < 1e-6);
  }
}

TEST_CASE("aligned morph of a moved copy stays a similar copy, plain blending does not", "[convert][morph]") {
  const auto& c = spherekit::test::mapped_sample_collection();
  auto ra = consistent_remesh(c.members[0].mesh, c.maps[0], 17);
  REQUIRE(ra.ok());
  const TriMesh& A = ra->mesh;
  const Similarity H = example_similarity();
  const TriMesh B{H.apply(A.V), A.F};
  const RowMat3d fa = c.features[0], fb = H.apply(fa);
  MorphOptions o;
  o.frames = 3;
  auto seq = morph_sequence(A, B, fa, fb, o);
  REQUIRE(seq.ok());
  CHECK(seq->alignment.scale == Approx(H.scale));
  CHECK(seq->alignment_rms < 1e-9);
  // frame(1/2) = H_{1/2}((A + H^-1(B)) / 2) = H_{1/2}(A): the shape moved half way, intact.
  const RowMat3d expected = seq->alignment.interpolated(0.5).apply(A.V);
  CHECK((seq->frames[1].V - expected).cwiseAbs().maxCoeff() < 1e-9);
  // Edge lengths scaled by sqrt(1.7) uniformly.
  const double ratio = (seq->frames[1].V.row(A.F(0, 0)) - seq->frames[1].V.row(A.F(0, 1))).norm() /
                       (A.V.row(A.F(0, 0)) - A.V.row(A.F(0, 1))).norm();
  CHECK(ratio == Approx(std::sqrt(H.scale)).epsilon(1e-9));
  // The plain blend of a shape and its turned copy is not a similar copy (it shrinks).
  o.align = false;
  auto plain = morph_sequence(A, B, fa, fb, o);
  REQUIRE(plain.ok());
  auto fit = fit_similarity(A.V, plain->frames[1].V);
  REQUIRE(fit.ok());
  CHECK((fit->apply(A.V) - plain->frames[1].V).cwiseAbs().maxCoeff() > 1e-3);
}

TEST_CASE("morph refuses bad arguments", "[convert][morph]") {
  const auto& c = spherekit::test::mapped_sample_collection();
  auto ra = consistent_remesh(c.members[0].mesh, c.maps[0], 17);
  auto rb = consistent_remesh(c.members[0].mesh, c.maps[0], 9);
  REQUIRE(ra.ok());
  REQUIRE(rb.ok());
  MorphOptions o;
  o.frames = 1;
  CHECK(morph_sequence(ra->mesh, ra->mesh, {}, {}, o).status().code() == ErrorCode::InvalidArgument);
  o.frames = 3;
  CHECK(morph_sequence(ra->mesh, rb->mesh, {}, {}, o).status().code() == ErrorCode::InvalidInput);
  CHECK(morph_sequence(ra->mesh, ra->mesh, c.features[0], c.features[0].topRows(4), o).status().code() ==
        ErrorCode::InvalidArgument);
  // Without features the blend is linear.
  auto lin = morph_sequence(ra->mesh, ra->mesh, {}, {}, o);
  REQUIRE(lin.ok());
  CHECK_FALSE(lin->aligned);
}

TEST_CASE("fit_similarity recovers a known similarity and refuses collinear points", "[convert][morph]") {
  const Similarity H = example_similarity();
  RowMat3d P(5, 3);
  P << 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 3, 1, 1, 1;
  auto fit = fit_similarity(P, H.apply(P));
  REQUIRE(fit.ok());
  CHECK((fit->apply(P) - H.apply(P)).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(fit->scale == Approx(H.scale));
  CHECK((fit->R - H.R).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((fit->inverse().apply(H.apply(P)) - P).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(fit->interpolated(0).is_identity());
  CHECK((fit->interpolated(0).apply(P) - P).cwiseAbs().maxCoeff() < 1e-15);
  CHECK((fit->interpolated(1).apply(P) - H.apply(P)).cwiseAbs().maxCoeff() < 1e-12);
  auto rigid = fit_similarity(P, H.apply(P), false);
  REQUIRE(rigid.ok());
  CHECK(rigid->scale == 1.0);
  RowMat3d line(4, 3);
  line << 0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3;
  CHECK(fit_similarity(line, line).status().code() == ErrorCode::InvalidInput);
  CHECK(fit_similarity(P.topRows(2), P.topRows(2)).status().code() == ErrorCode::InvalidArgument);
}

TEST_CASE("a morph sequence as glTF: one target per frame and an animation through them", "[convert][morph]") {
  const auto& c = spherekit::test::mapped_sample_collection();
  auto ra = consistent_remesh(c.members[0].mesh, c.maps[0], 9);
  auto rb = consistent_remesh(c.members[2].mesh, c.maps[2], 9);
  REQUIRE(ra.ok());
  REQUIRE(rb.ok());
  MorphOptions o;
  o.frames = 4;
  auto seq = morph_sequence(ra->mesh, rb->mesh, c.features[0], c.features[2], o);
  REQUIRE(seq.ok());
  GltfMorphOptions g;
  g.animation_seconds = 2;
  auto glb = build_gltf_morph_targets(seq->frames, g);
  REQUIRE(glb.ok());
  const auto file = spherekit::test::parse_glb(glb->glb);
  const auto& j = file.json;
  REQUIRE(j["meshes"][0]["primitives"][0]["targets"].size() == 3);
  REQUIRE(j["animations"].size() == 1);
  const auto& anim = j["animations"][0];
  CHECK(anim["channels"][0]["target"]["path"] == "weights");
  CHECK(anim["channels"][0]["target"]["node"] == 0);
  const auto& times = j["accessors"][anim["samplers"][0]["input"].get<int>()];
  const auto& weights = j["accessors"][anim["samplers"][0]["output"].get<int>()];
  CHECK(times["count"] == 4);
  CHECK(times["max"][0] == 2.0);
  CHECK(weights["count"] == 12);  // 4 keys x 3 targets
  // Key k shows frame k: weight 1 on target k-1 only.
  const std::string w = spherekit::test::buffer_view_bytes(file, weights["bufferView"].get<int>());
  REQUIRE(w.size() == 12 * sizeof(float));
  std::vector<float> values(12);
  std::memcpy(values.data(), w.data(), w.size());
  for (int k = 0; k < 4; ++k)
    for (int t = 0; t < 3; ++t) CHECK(values[static_cast<std::size_t>(3 * k + t)] == (k > 0 && t == k - 1 ? 1.0f : 0.0f));
  // Without the option: no animation.
  auto plain = build_gltf_morph_targets(seq->frames, GltfMorphOptions{});
  REQUIRE(plain.ok());
  CHECK_FALSE(spherekit::test::parse_glb(plain->glb).json.contains("animations"));
}
