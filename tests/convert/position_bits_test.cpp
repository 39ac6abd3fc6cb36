// Tests of the rate-distortion position bits (convert/position_bits.h) and of levels of detail
// built with them: the chosen bits minimize the stated cost among their neighbours, follow the
// level's error, and cost little error for many fewer bytes than the error budget's bits.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include "gltf_test_support.h"
#include "spherekit/convert/gltf_lods.h"
#include "spherekit/convert/position_bits.h"
#include "spherekit/geometry_image.h"
#include "test_meshes.h"

using namespace spherekit;
using namespace spherekit::convert;

namespace {

// J(b) of position_bits.h, computed here from an independent encode at b bits.
double cost_at(const GltfMesh& mesh, DracoEncodeOptions o, int bits, double error, double gamma) {
  o.quantization.position_bits = bits;
  auto p = encode_draco_primitive(mesh, o);
  REQUIRE(p.ok());
  const double q = o.quantization.position_step() / std::sqrt(24.0);
  return static_cast<double>(p->bytes.size()) * std::pow(1 + (q / error) * (q / error), gamma / 2);
}

struct Encoded {
  GltfMesh mesh;
  DracoEncodeOptions options;
};

Encoded blob_level() {
  const GeometryImage gi = test::blob_geometry_image(65, 3, 7);
  auto mesh = gltf_mesh_from_geometry_image(gi);
  REQUIRE(mesh.ok());
  QuantizationBudget budget;
  budget.min_position_bits = 18;
  auto q = choose_draco_quantization(*mesh, 0, budget);
  REQUIRE(q.ok());
  DracoEncodeOptions o;
  o.quantization = q->quantization;
  return {std::move(mesh).value(), o};
}

}  // namespace

TEST_CASE("Rate-distortion position bits: a local minimum of the cost, more bits for a smaller error", "[convert]") {
  const Encoded e = blob_level();
  const double range = e.options.quantization.position_range;
  int previous = 0;
  // Errors from coarse to fine: the chosen bits never decrease.
  for (const double error : {range * 1e-2, range * 1e-3, range * 1e-4}) {
    auto c = choose_position_bits(e.mesh, e.options, error, 1.0, 4);
    REQUIRE(c.ok());
    INFO("error " << error << " bits " << c->bits);
    CHECK(c->bits >= previous);
    CHECK(c->bits < e.options.quantization.position_bits);  // 18 bits are far finer than any of these errors
    previous = c->bits;
    const double j = cost_at(e.mesh, e.options, c->bits, error, 1.0);
    CHECK(j <= cost_at(e.mesh, e.options, c->bits + 1, error, 1.0));
    CHECK(j <= cost_at(e.mesh, e.options, c->bits - 1, error, 1.0));
    CHECK(static_cast<int>(c->primitive.bytes.size()) > 0);
    REQUIRE(c->primitive.decoded.mesh.V.rows() > 0);
    CHECK(c->predicted_rms >= error);
    CHECK(c->predicted_rms <= error * 1.5);  // the cost keeps the added error a fraction of the level's
  }
  CHECK(previous >= 10);
  // Fixed bytes around the bitstream (a file's JSON) dilute what fewer bits save: never fewer
  // bits with them, and more once they dwarf the bitstream.
  const double error = range * 1e-2;
  auto plain = choose_position_bits(e.mesh, e.options, error, 1.0, 4);
  auto with_json = choose_position_bits(e.mesh, e.options, error, 1.0, 4, 800);
  auto huge = choose_position_bits(e.mesh, e.options, error, 1.0, 4, 1e7);
  REQUIRE(plain.ok());
  REQUIRE(with_json.ok());
  REQUIRE(huge.ok());
  CHECK(with_json->bits >= plain->bits);
  CHECK(huge->bits > plain->bits);
}

TEST_CASE("Rate-distortion position bits: errors as values", "[convert]") {
  const Encoded e = blob_level();
  CHECK(choose_position_bits(e.mesh, e.options, 0.0, 1.0, 4).status().code() == ErrorCode::InvalidArgument);
  CHECK(choose_position_bits(e.mesh, e.options, 1e-3, 3.0, 4).status().code() == ErrorCode::InvalidArgument);
  CHECK(choose_position_bits(e.mesh, e.options, 1e-3, 1.0, 0).status().code() == ErrorCode::InvalidArgument);
  CHECK(choose_position_bits(e.mesh, e.options, 1e-3, 1.0, 19).status().code() == ErrorCode::InvalidArgument);
  CHECK(rate_exponent(1000, 1e-3, 250, 4e-3) == Approx(1.0));
  CHECK(rate_exponent(1000, 1e-3, 1000, 4e-3) == 1.0);  // undetermined
  CHECK(rate_exponent(1000, 1e-3, 10, 1.1e-3) == 2.0);  // clamped
}

TEST_CASE("Adaptive LODs with rate-distortion bits: fewer bytes than the budget's bits, the error model holds", "[convert]") {
  const GeometryImage gi = test::blob_geometry_image(129, 3, 7);
  const TriMesh finest = geometry_image_mesh(gi);
  GltfLodOptions budget = test::lod_test_options();
  budget.mode = LodMode::Adaptive;
  budget.levels = 4;
  budget.normals = false;
  // The finest remesh's own error stands in for the error against an original surface.
  budget.reference_rms_error = 2e-4 * remesh_error(finest, finest).peak;
  GltfLodOptions rd = budget;
  rd.position_bits_rule = PositionBitsRule::RateDistortion;
  auto a = build_gltf_lods(gi, budget);
  auto b = build_gltf_lods(gi, rd);
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  RemeshErrorOptions eo;
  eo.samples = 50000;
  for (std::size_t k = 0; k < a->levels.size(); ++k) {
    const GltfLodLevel& x = a->levels[k];
    const GltfLodLevel& y = b->levels[k];
    CHECK(x.mesh.F == y.mesh.F);  // same simplification, only the grid differs
    CHECK(y.quantization.rate_distortion);
    CHECK(y.quantization.quantization.position_bits <= x.quantization.quantization.position_bits);
    const TriMesh dx{x.primitive.decoded.mesh.V, x.primitive.decoded.mesh.F};
    const TriMesh dy{y.primitive.decoded.mesh.V, y.primitive.decoded.mesh.F};
    const double ex = remesh_error(finest, dx, eo).rms, ey = remesh_error(finest, dy, eo).rms;
    const double total_x = std::hypot(budget.reference_rms_error, ex), total_y = std::hypot(budget.reference_rms_error, ey);
    const double loss_db = 20 * std::log10(total_y / total_x);
    INFO("level " << k << " bits " << x.quantization.quantization.position_bits << " -> "
                  << y.quantization.quantization.position_bits << " bytes " << x.primitive.bytes.size() << " -> "
                  << y.primitive.bytes.size() << " loss " << loss_db << " dB");
    // The error model (q = step / sqrt(24) in squares with the level's error) predicts the loss.
    const double e = y.quantization.reference_rms_error, q = y.quantization.quantization.position_step() / std::sqrt(24.0);
    const double predicted_db = 10 * std::log10(1 + (q / e) * (q / e));
    INFO("predicted loss " << predicted_db << " dB");
    CHECK(std::abs(loss_db - predicted_db) < 0.5);
    CHECK(y.primitive.bytes.size() < x.primitive.bytes.size());
    CHECK(loss_db < 2.0);
  }
  // The rule is recorded in the combined file's extras (a level's own file carries no quantization).
  CHECK(b->combined_glb.find("\"rate-distortion\"") != std::string::npos);
}
