// The PCA-versus-Draco compression experiment (see shape_compression.h for what is counted).
#include "spherekit/convert/shape_compression.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "spherekit/convert/gltf_draco.h"

namespace spherekit::convert {
namespace {

/// One array of values, quantized (or rounded to float32) as the model would store it.
struct Stored {
  std::vector<double> values;  ///< dequantized
  std::string bytes;           ///< packed payload (incl. the float32 min/max of a quantized array)
};

void append_raw(std::string& out, const void* p, std::size_t n) { out.append(static_cast<const char*>(p), n); }

Stored store(const double* x, std::size_t n, int bits) {
  Stored s;
  s.values.resize(n);
  if (bits == 0) {
    for (std::size_t i = 0; i < n; ++i) {
      const auto f = static_cast<float>(x[i]);
      s.values[i] = f;
      append_raw(s.bytes, &f, 4);
    }
    return s;
  }
  float lo = n ? static_cast<float>(*std::min_element(x, x + n)) : 0.0f;
  float hi = n ? static_cast<float>(*std::max_element(x, x + n)) : 0.0f;
  // The float bounds must still enclose the doubles, or rounding could push a value one step
  // outside the grid.
  if (n && lo > *std::min_element(x, x + n)) lo = std::nextafter(lo, -std::numeric_limits<float>::infinity());
  if (n && hi < *std::max_element(x, x + n)) hi = std::nextafter(hi, std::numeric_limits<float>::infinity());
  append_raw(s.bytes, &lo, 4);
  append_raw(s.bytes, &hi, 4);
  const double levels = std::ldexp(1.0, bits) - 1;
  const double step = hi > lo ? (static_cast<double>(hi) - lo) / levels : 0.0;
  const int width = bits <= 8 ? 1 : bits <= 16 ? 2 : 4;
  for (std::size_t i = 0; i < n; ++i) {
    const double q = step > 0 ? std::clamp(std::round((x[i] - lo) / step), 0.0, levels) : 0.0;
    s.values[i] = lo + q * step;
    const auto u = static_cast<std::uint32_t>(q);
    for (int b = 0; b < width; ++b) s.bytes.push_back(static_cast<char>((u >> (8 * b)) & 0xff));
  }
  return s;
}

// zlib at its best level: what a plain entropy coder gets from the payload. Should zlib fail
// (it cannot, short of memory), the payload counts uncompressed.
std::size_t deflated_size(const std::string& bytes) {
  if (bytes.empty()) return 0;
  uLongf len = compressBound(static_cast<uLong>(bytes.size()));
  std::vector<Bytef> z(len);
  if (compress2(z.data(), &len, reinterpret_cast<const Bytef*>(bytes.data()), static_cast<uLong>(bytes.size()),
                Z_BEST_COMPRESSION) != Z_OK)
    return bytes.size();
  return static_cast<std::size_t>(len);
}

double bbox_diagonal(const RowMat3d& V) { return (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm(); }

/// Fills the error fields of `p` from per-member reconstructions.
void measure(CompressionPoint& p, const std::vector<TriMesh>& shapes, const std::vector<RowMat3d>& decoded) {
  double sum_rms = 0, sum_psnr = 0;
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    const double rms = std::sqrt((decoded[i] - shapes[i].V).squaredNorm() / static_cast<double>(shapes[i].V.rows()));
    sum_rms += rms;
    p.max_rms = std::max(p.max_rms, rms);
    sum_psnr += rms > 0 ? 20 * std::log10(bbox_diagonal(shapes[i].V) / rms) : std::numeric_limits<double>::infinity();
  }
  p.mean_rms = sum_rms / static_cast<double>(shapes.size());
  p.mean_psnr = sum_psnr / static_cast<double>(shapes.size());
}

}  // namespace

Result<std::vector<CompressionPoint>> compression_experiment(const ShapePca& pca, const std::vector<TriMesh>& shapes,
                                                             const CompressionOptions& options,
                                                             const ProgressFn& progress) {
  if (shapes.empty()) return Status(ErrorCode::InvalidArgument, "no shapes to compress");
  for (int b : options.pca_bits)
    if (b < 0 || b > 24) return Status(ErrorCode::InvalidArgument, "PCA bits " + std::to_string(b) + " outside 0..24");
  for (int b : options.draco_bits)
    if (b < 1 || b > 30) return Status(ErrorCode::InvalidArgument, "Draco bits " + std::to_string(b) + " outside 1..30");
  for (std::size_t i = 0; i < shapes.size(); ++i)
    if (shapes[i].V.rows() != pca.mean.rows() || shapes[i].V.rows() == 0)
      return Status(ErrorCode::InvalidInput, "shape " + std::to_string(i) + " does not match the PCA's " +
                                                 std::to_string(pca.mean.rows()) + " vertices");
  const auto r = static_cast<int>(pca.components.size());
  const auto n = static_cast<Eigen::Index>(shapes.size());
  if (pca.coefficients.rows() != n)
    return Status(ErrorCode::InvalidInput, "the PCA has " + std::to_string(pca.coefficients.rows()) +
                                               " members' coefficients for " + std::to_string(n) + " shapes");
  const std::size_t vals = 3 * static_cast<std::size_t>(pca.mean.rows());
  const int configurations = static_cast<int>(options.pca_bits.size()) * (r + 1) + static_cast<int>(options.draco_bits.size());
  int done = 0;
  auto tick = [&]() {
    const bool go = report_progress(progress, "compress", done, static_cast<double>(done) / configurations);
    ++done;
    return go;
  };
  std::vector<CompressionPoint> out;

  for (int bits : options.pca_bits) {
    const Stored mean = store(pca.mean.data(), vals, bits);
    std::vector<Stored> comps;
    for (int j = 0; j < r; ++j) comps.push_back(store(pca.components[static_cast<std::size_t>(j)].data(), vals, bits));
    for (int k = 0; k <= r; ++k) {
      if (!tick()) return Status(ErrorCode::Cancelled, "cancelled");
      // Coefficients n x k, row-major (member by member).
      std::vector<double> c(static_cast<std::size_t>(n) * static_cast<std::size_t>(k));
      for (Eigen::Index i = 0; i < n; ++i)
        for (int j = 0; j < k; ++j) c[static_cast<std::size_t>(i * k + j)] = pca.coefficients(i, j);
      const Stored coef = store(c.data(), c.size(), bits);
      std::string payload = mean.bytes;
      for (int j = 0; j < k; ++j) payload += comps[static_cast<std::size_t>(j)].bytes;
      payload += coef.bytes;
      std::vector<RowMat3d> decoded;
      for (Eigen::Index i = 0; i < n; ++i) {
        RowMat3d V = Eigen::Map<const RowMat3d>(mean.values.data(), pca.mean.rows(), 3);
        for (int j = 0; j < k; ++j)
          V += coef.values[static_cast<std::size_t>(i * k + j)] *
               Eigen::Map<const RowMat3d>(comps[static_cast<std::size_t>(j)].values.data(), pca.mean.rows(), 3);
        decoded.push_back(std::move(V));
      }
      CompressionPoint p;
      p.method = "pca";
      p.components = k;
      p.bits = bits;
      p.bytes_per_shape = static_cast<double>(payload.size()) / static_cast<double>(n);
      p.deflated_bytes_per_shape = static_cast<double>(deflated_size(payload)) / static_cast<double>(n);
      measure(p, shapes, decoded);
      out.push_back(p);
    }
  }

  for (int bits : options.draco_bits) {
    if (!tick()) return Status(ErrorCode::Cancelled, "cancelled");
    double bytes = 0;
    std::vector<RowMat3d> decoded;
    for (std::size_t i = 0; i < shapes.size(); ++i) {
      GltfMesh g;
      g.V = shapes[i].V;
      g.F = shapes[i].F;
      QuantizationBudget budget;
      budget.min_position_bits = bits;
      budget.max_position_bits = std::max(bits, 24);
      SPHEREKIT_ASSIGN_OR_RETURN(QuantizationChoice q, choose_draco_quantization(g, 0, budget));
      DracoEncodeOptions enc;
      enc.quantization = q.quantization;
      enc.compression_level = options.draco_compression_level;
      SPHEREKIT_ASSIGN_OR_RETURN(DracoPrimitive packed, encode_draco_primitive(g, enc));
      bytes += static_cast<double>(packed.bytes.size());
      enc.sequential = true;
      SPHEREKIT_ASSIGN_OR_RETURN(DracoPrimitive ordered, encode_draco_primitive(g, enc));
      if (ordered.decoded.mesh.V.rows() != g.V.rows())
        return Status(ErrorCode::Internal, "Draco sequential decoding changed the vertex count");
      decoded.push_back(ordered.decoded.mesh.V);
    }
    CompressionPoint p;
    p.method = "draco";
    p.bits = bits;
    p.bytes_per_shape = bytes / static_cast<double>(n);
    p.deflated_bytes_per_shape = p.bytes_per_shape;
    measure(p, shapes, decoded);
    out.push_back(p);
  }
  if (!report_progress(progress, "compress", done, 1.0)) return Status(ErrorCode::Cancelled, "cancelled");
  return out;
}

}  // namespace spherekit::convert
