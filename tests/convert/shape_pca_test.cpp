// PCA of a collection's consistent remeshes (paper Fig. 1): exact reconstruction with all
// components, a monotone error table, a known low-rank case, the compression experiment, and
// the plot/PNG writers its command uses.
#include "spherekit/convert/shape_pca.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "collection_fixture.h"
#include "spherekit/convert/consistent_remesh.h"
#include "spherekit/convert/line_plot.h"
#include "spherekit/convert/png_image.h"
#include "spherekit/convert/shape_compression.h"
#include "test_meshes.h"

using namespace spherekit;
using namespace spherekit::convert;

namespace {

std::vector<TriMesh> sample_remeshes(int size) {
  const auto& c = spherekit::test::mapped_sample_collection();
  std::vector<TriMesh> meshes;
  for (const auto& m : c.members) meshes.push_back(m.mesh);
  auto r = consistent_remeshes(meshes, c.maps, size);
  REQUIRE(r.ok());
  std::vector<TriMesh> out;
  for (auto& rm : r.value()) out.push_back(std::move(rm.mesh));
  return out;
}

}  // namespace

TEST_CASE("PCA of the sample collection: all components reconstruct every member, the table is monotone",
          "[convert][pca]") {
  const std::vector<TriMesh> shapes = sample_remeshes(33);
  auto pca = compute_shape_pca(shapes);
  REQUIRE(pca.ok());
  const std::size_t n = shapes.size();
  // n centred shapes span at most n - 1 directions; different animals span all of them.
  REQUIRE(pca->components.size() == n - 1);
  for (std::size_t j = 0; j < pca->components.size(); ++j) {
    CHECK(pca->components[j].norm() == Approx(1.0).epsilon(1e-12));
    for (std::size_t k = 0; k < j; ++k) CHECK(std::abs(pca->components[j].cwiseProduct(pca->components[k]).sum()) < 1e-12);
    if (j > 0) CHECK(pca->singular_values[j] <= pca->singular_values[j - 1]);
  }
  double total = 0;
  for (double f : pca->variance_fraction) total += f;
  CHECK(total == Approx(1.0));
  // The mean is the mean.
  RowMat3d sum = RowMat3d::Zero(shapes[0].V.rows(), 3);
  for (const TriMesh& s : shapes) sum += s.V;
  CHECK((sum / static_cast<double>(n) - pca->mean).cwiseAbs().maxCoeff() < 1e-12);

  auto table = pca_error_table(pca.value(), shapes);
  REQUIRE(table.ok());
  const auto r = static_cast<Eigen::Index>(pca->components.size());
  REQUIRE(table->rms.rows() == r + 1);
  for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(n); ++i) {
    const double peak = table->peak[static_cast<std::size_t>(i)];
    INFO("member " << i);
    CHECK(table->rms(0, i) > 1e-3 * peak);  // the mean alone is not the member
    // With every component: the member itself up to rounding, far below float precision
    // (float32 has 2^-24 = 6e-8 relative precision).
    CHECK(table->rms(r, i) < 1e-7 * peak);
    CHECK(table->psnr(r, i) > 140);
    // Monotone non-increasing: each row is an orthogonal projection onto a larger subspace;
    // only rounding (1e-15 relative) could reverse two equal values.
    for (Eigen::Index k = 1; k <= r; ++k) CHECK(table->rms(k, i) <= table->rms(k - 1, i) + 1e-12 * peak);
    // Reconstructing from the stored coefficients gives the same numbers.
    const RowMat3d rec = reconstruct_shape(pca.value(), pca->coefficients.row(i).transpose());
    CHECK((rec - shapes[static_cast<std::size_t>(i)].V).cwiseAbs().maxCoeff() < 1e-9 * peak);
  }
  for (std::size_t k = 1; k < table->mean_rms.size(); ++k) CHECK(table->mean_rms[k] <= table->mean_rms[k - 1] + 1e-12);
}

TEST_CASE("PCA finds the rank of a known two-parameter family", "[convert][pca]") {
  const TriMesh base = spherekit::test::icosphere(2);
  RowMat3d d1 = base.V, d2 = base.V;
  d1.col(2) *= 0.5;  // stretch along z
  for (Eigen::Index v = 0; v < base.V.rows(); ++v) d2(v, 0) = std::sin(3 * base.V(v, 1));
  std::vector<TriMesh> shapes;
  const double a[] = {0, 1, -0.5, 2, 0.3}, b[] = {0.2, -1, 0.7, 0, 1.1};
  for (int i = 0; i < 5; ++i) shapes.push_back(TriMesh{base.V + a[i] * d1 + b[i] * d2, base.F});
  auto pca = compute_shape_pca(shapes);
  REQUIRE(pca.ok());
  CHECK(pca->components.size() == 2);
  auto table = pca_error_table(pca.value(), shapes);
  REQUIRE(table.ok());
  CHECK(table->max_rms[2] < 1e-12);
  CHECK(table->max_rms[1] > 1e-3);

  CHECK(compute_shape_pca({}).status().code() == ErrorCode::InvalidArgument);
  std::vector<TriMesh> mixed{base, spherekit::test::icosphere(1)};
  CHECK(compute_shape_pca(mixed).status().code() == ErrorCode::InvalidInput);
}

TEST_CASE("compression experiment: bytes and errors behave as their definitions say", "[convert][pca]") {
  const std::vector<TriMesh> shapes = sample_remeshes(17);
  auto pca = compute_shape_pca(shapes);
  REQUIRE(pca.ok());
  CompressionOptions o;
  o.pca_bits = {0, 12};
  o.draco_bits = {8, 12, 16};
  int events = 0;
  auto points = compression_experiment(pca.value(), shapes, o, [&](const ProgressEvent&) { return ++events > 0; });
  REQUIRE(points.ok());
  const auto r = static_cast<int>(pca->components.size());
  REQUIRE(points->size() == static_cast<std::size_t>(2 * (r + 1) + 3));
  CHECK(events >= static_cast<int>(points->size()));
  const double V3 = 3.0 * static_cast<double>(shapes[0].V.rows()), n = static_cast<double>(shapes.size());
  for (const CompressionPoint& p : points.value()) {
    INFO(p.method << " k=" << p.components << " bits=" << p.bits);
    CHECK(p.deflated_bytes_per_shape > 0);
    if (p.method == "pca" && p.bits == 0) {
      // float32: 4 bytes for every value of the mean, the k components and the n x k coefficients.
      CHECK(p.bytes_per_shape == Approx(4 * (V3 * (p.components + 1) + n * p.components) / n));
      if (p.components == r) CHECK(p.mean_psnr > 100);  // float rounding only
    }
    if (p.method == "pca" && p.bits == 12) {
      // 2 bytes a value plus min/max (8 bytes) per stored array.
      CHECK(p.bytes_per_shape == Approx((2 * (V3 * (p.components + 1) + n * p.components) + 8 * (p.components + 2)) / n));
    }
  }
  // More Draco bits: more bytes, less error.
  std::vector<CompressionPoint> draco;
  for (const auto& p : points.value())
    if (p.method == "draco") draco.push_back(p);
  REQUIRE(draco.size() == 3);
  for (std::size_t k = 1; k < draco.size(); ++k) {
    CHECK(draco[k].bytes_per_shape > draco[k - 1].bytes_per_shape);
    CHECK(draco[k].mean_rms < draco[k - 1].mean_rms);
  }
  // Quantization error of b bits: at most half a step per coordinate, step = extent / (2^b - 1).
  const double extent = (shapes[0].V.colwise().maxCoeff() - shapes[0].V.colwise().minCoeff()).maxCoeff();
  CHECK(draco[0].mean_rms > 0);
  CHECK(draco[1].max_rms <= std::sqrt(3.0) * 0.5 * 1.5 * extent / 4095);  // 1.5: members differ in extent

  o.pca_bits = {40};
  CHECK(compression_experiment(pca.value(), shapes, o).status().code() == ErrorCode::InvalidArgument);
  o.pca_bits = {0};
  CHECK(compression_experiment(pca.value(), shapes, o, [](const ProgressEvent&) { return false; }).status().code() ==
        ErrorCode::Cancelled);
}

TEST_CASE("line plots render to PNG", "[convert][pca]") {
  LinePlot plot;
  plot.title = "test";
  plot.x_label = "x";
  plot.y_label = "y";
  plot.series.push_back(PlotSeries{"a", {1, 2, 3}, {3, 1, 2}, {255, 0, 0}, 2, true});
  plot.series.push_back(PlotSeries{"b", {1, 2, 3}, {0, std::nan(""), 1}, {0, 0, 255}, 1, false});
  auto image = render_line_plot(plot);
  REQUIRE(image.ok());
  CHECK(image->width == 800);
  int red = 0, blue = 0;
  for (int y = 0; y < image->height; ++y)
    for (int x = 0; x < image->width; ++x) {
      const std::uint8_t* p = image->at(x, y);
      red += p[0] == 255 && p[1] == 0 && p[2] == 0;
      blue += p[0] == 0 && p[1] == 0 && p[2] == 255;
    }
  CHECK(red > 500);   // two segments 2 px wide and three markers
  CHECK(blue > 10);   // the legend swatch (the series has no drawable segment)
  auto png = encode_png(image.value());
  REQUIRE(png.ok());
  CHECK(png->substr(0, 8) == std::string("\x89PNG\r\n\x1a\n", 8));
  auto again = encode_png(image.value());
  REQUIRE(again.ok());
  CHECK(again.value() == png.value());

  plot.series[0].y.pop_back();
  CHECK(render_line_plot(plot).status().code() == ErrorCode::InvalidArgument);
  LinePlot empty;
  CHECK(render_line_plot(empty).status().code() == ErrorCode::InvalidArgument);
  Image8 bad;
  CHECK(encode_png(bad).status().code() == ErrorCode::InvalidArgument);
}
