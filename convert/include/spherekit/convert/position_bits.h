// Rate-distortion choice of a glTF level's Draco position bits.
//
// The error budget of QuantizationBudget keeps the quantization far below a surface's own
// error (step/2 <= 0.1 x error), at 3 bits per vertex per extra bit. For levels of detail the
// question is different: which bits give the smallest file at the level's error? A coarser
// grid saves bytes but adds error, which would have to be bought back with more vertices.
//
// Error model. Each coordinate moves by uniform noise of RMS step/sqrt(12); a surface-distance
// error sees the component along the normal, and inside a triangle the barycentric average of
// the three corners' independent noises, whose variance is sum(b_i^2) = 1/2 of it on average
// over the triangle. So the quantization adds surface RMS q = step / sqrt(24), in squares to
// the level's own error e (independent errors): total e * sqrt(1 + (q/e)^2).
//
// Rate model. Along a model's own levels, size grows as error^-gamma (gamma = log of the
// vertex ratio over log of the error ratio between its finest and coarsest level; 1 for a
// smooth surface, whose approximation error falls as 1/V). The extra error is worth
// (1 + (q/e)^2)^(gamma/2) in size, so the cost of b bits is
//     J(b) = bytes(b) * (1 + (q_b / e)^2)^(gamma / 2),
// and the chosen bits minimize J, bytes(b) measured by encoding. Measured on the bunny's
// adaptive levels (gltf-transform re-encodes at 9-14 bits, PSNR by eval-surface): the model's
// loss matches within 0.1-0.3 dB, and J's minimum is where the measured size at equal PSNR is.
#pragma once

#include "spherekit/convert/gltf_draco.h"

namespace spherekit::convert {

struct PositionBitsChoice {
  int bits = 0;               ///< the chosen position bits
  DracoPrimitive primitive;   ///< the level encoded with them
  double predicted_rms = 0;   ///< e * sqrt(1 + (q/e)^2): the level's predicted error after quantization
  int encodes = 0;            ///< how many bit counts were tried
};

/// Encodes `mesh` at the position bits minimizing J (above), from `options.quantization`'s
/// bits downward (J rises once the quantization error passes the level's own; the search
/// stops after two rises), never below `min_bits`. `level_error_rms` > 0 is the level's RMS
/// surface error without quantization; `gamma` in [0.5, 2]. The grid's origin and range stay
/// `options.quantization`'s. Deterministic. Errors: InvalidArgument (level_error_rms <= 0,
/// gamma outside [0.5, 2], min_bits outside 1..bits), and encode_draco_primitive's.
/// `fixed_bytes`: bytes of the file around the bitstream (GLB headers, JSON), added to bytes(b)
/// in J, since the file is what is downloaded; it tilts the choice towards more bits when the
/// bitstream is small.
[[nodiscard]] Result<PositionBitsChoice> choose_position_bits(const GltfMesh& mesh, const DracoEncodeOptions& options,
                                                              double level_error_rms, double gamma, int min_bits,
                                                              double fixed_bytes = 0);

/// gamma of the rate model from a model's finest and coarsest level: log(V0/V1) / log(e1/e0),
/// clamped to [0.5, 2]; 1 when the levels do not determine it (equal counts or errors).
double rate_exponent(double vertices_fine, double error_fine, double vertices_coarse, double error_coarse);

}  // namespace spherekit::convert
