// Rate-distortion position bits (position_bits.h).
#include "spherekit/convert/position_bits.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace spherekit::convert {

double rate_exponent(double vertices_fine, double error_fine, double vertices_coarse, double error_coarse) {
  if (!(vertices_fine > 0 && vertices_coarse > 0 && error_fine > 0 && error_coarse > 0)) return 1.0;
  const double de = std::log(error_coarse / error_fine), dv = std::log(vertices_fine / vertices_coarse);
  if (!(std::abs(de) > 1e-9) || !(dv > 1e-9) || !std::isfinite(de) || !std::isfinite(dv)) return 1.0;
  return std::clamp(dv / de, 0.5, 2.0);
}

Result<PositionBitsChoice> choose_position_bits(const GltfMesh& mesh, const DracoEncodeOptions& options,
                                                double level_error_rms, double gamma, int min_bits,
                                                double fixed_bytes) {
  const int top = options.quantization.position_bits;
  if (!(level_error_rms > 0) || !std::isfinite(level_error_rms))
    return Status(ErrorCode::InvalidArgument, "position bits: the level's error must be > 0");
  if (!(gamma >= 0.5 && gamma <= 2.0)) return Status(ErrorCode::InvalidArgument, "position bits: gamma must be in [0.5, 2]");
  if (min_bits < 1 || min_bits > top)
    return Status(ErrorCode::InvalidArgument, "position bits: min_bits must be in 1.." + std::to_string(top));

  PositionBitsChoice best;
  double best_cost = std::numeric_limits<double>::infinity();
  int rises = 0;
  double last_cost = std::numeric_limits<double>::infinity();
  for (int b = top; b >= min_bits && rises < 2; --b) {
    DracoEncodeOptions o = options;
    o.quantization.position_bits = b;
    SPHEREKIT_ASSIGN_OR_RETURN(DracoPrimitive p, encode_draco_primitive(mesh, o));
    ++best.encodes;
    const double q = o.quantization.position_step() / std::sqrt(24.0);
    const double ratio2 = (q / level_error_rms) * (q / level_error_rms);
    const double cost = (static_cast<double>(p.bytes.size()) + fixed_bytes) * std::pow(1.0 + ratio2, gamma / 2);
    rises = cost > last_cost ? rises + 1 : 0;
    last_cost = cost;
    // Ties keep the finer grid (the first one met).
    if (cost < best_cost) {
      best_cost = cost;
      best.bits = b;
      best.primitive = std::move(p);
      best.predicted_rms = level_error_rms * std::sqrt(1.0 + ratio2);
    }
  }
  return best;
}

}  // namespace spherekit::convert
