// Draco compression of one glTF primitive (KHR_draco_mesh_compression), the quantization grid
// chosen from an error budget, and decoding (the only place SphereKit calls Draco).
//
// Quantization (Draco bitstream spec v2.2, "Quantization"; draco AttributeQuantizationTransform):
// an attribute with b bits is stored as integers q in [0, 2^b - 1] on a grid
//     x = origin + q * step,   step = range / (2^b - 1),
// the same `range` on every axis. Each coordinate is rounded to the nearest grid value, so it
// moves by at most step/2; for positions spread evenly within their cells the RMS length of the
// 3D displacement is step/2 (3 * step^2/12, square-rooted) and its RMS component along the
// surface normal, the part a surface-distance error sees, step/sqrt(12). Normals use Draco's
// octahedral encoding with `normal_bits` per coordinate. ALGORITHM.md §5.3: 11-bit positions
// cap the PSNR at 72-77 dB, below a good 257 x 257 geometry image, hence >= 14 bits.
//
// The grids are explicit (not Draco's per-mesh default), for two reasons:
//  * positions: every level of detail of one model uses one grid (origin, range and bits of the
//    finest level), so a texel present in several levels decodes to the same position in each
//    (ALGORITHM.md §7, gotcha 9: "unify quantization across LODs");
//  * texture coordinates of a geometry image (GltfMesh::texture_size = T > 0) sit on texel
//    centres (j + 1/2)/T; the grid starts at 1/(2T) with step 1/(T*m), m a whole number, so
//    every texel centre is a grid value and decodes exactly (up to float rounding); they are
//    then predicted with Draco's parallelogram scheme, which is exact on a lattice.
//
// Draco may reorder and split points (edgebreaker: "may change the order and number of
// vertices", KHR_draco_mesh_compression README, implementation note). encode_draco_primitive
// therefore decodes what it encoded and returns the decoded primitive: glTF accessors must
// describe the decoded data (counts, POSITION min/max). Sequential encoding keeps the point and
// face order (used for morph targets, gltf_morph.h).
#pragma once

#include <array>
#include <string>
#include <string_view>

#include "spherekit/convert/gltf_mesh.h"
#include "spherekit/status.h"

namespace spherekit::convert {

/// The quantization of one Draco primitive: bits and explicit grids.
struct DracoQuantization {
  int position_bits = 14;                   ///< 1..30 (Draco's limit)
  std::array<float, 3> position_origin{};   ///< grid origin: the smallest corner of the grid's box
  float position_range = 1;                 ///< grid extent, same on every axis (> 0)
  int normal_bits = 10;                     ///< octahedral normal bits per coordinate, 1..30
  int texcoord_bits = 12;                   ///< 1..30
  std::array<float, 2> texcoord_origin{};   ///< texture-coordinate grid origin
  float texcoord_range = 1;                 ///< texture-coordinate grid extent (> 0)

  /// Position grid step range / (2^bits - 1); no coordinate moves by more than half of it.
  double position_step() const;
  /// Texture-coordinate grid step.
  double texcoord_step() const;
};

/// How the quantization is chosen.
struct QuantizationBudget {
  int min_position_bits = 14;  ///< floor on position bits (ALGORITHM.md §5.3)
  /// Ceiling on position bits: a float carries 24 significant bits, more is noise.
  int max_position_bits = 24;
  /// Positions get the fewest bits (>= min_position_bits) for which the RMS displacement the
  /// quantization adds, step/2, is at most this fraction of the surface's own RMS error
  /// (`reference_rms_error` below). Independent errors add in squares, so 0.1 costs at most
  /// 10 log10(1 + 0.1^2) = 0.043 dB of PSNR.
  double position_error_fraction = 0.1;
  int normal_bits = 10;        ///< octahedral normal bits (draco_encoder's and glTF-Transform's default)
  /// Texture-coordinate bits of arbitrary coordinates (texture_size 0). A texel-centre
  /// lattice (texture_size T > 0) takes the fewest bits that hold it with one grid step per
  /// texel (2^bits - 1 >= T - 1: 9 at T = 257), whatever this says: a finer grid leaves every
  /// coordinate exact too, but its prediction residuals are multiples of the step ratio, which
  /// Draco's entropy coder pays for (12 bits at 257: 0.2% to 6% larger adaptive levels).
  int min_texcoord_bits = 12;
};

/// What choose_draco_quantization decided, with the numbers behind it (recorded in glTF extras).
struct QuantizationChoice {
  DracoQuantization quantization;
  /// RMS surface error the budget was taken from (absolute units); 0 when none was given and
  /// the floor min_position_bits decided.
  double reference_rms_error = 0;
  double position_error_fraction = 0;  ///< the fraction used
  /// Largest per-coordinate position error step/2 and the RMS 3D displacement (also step/2).
  double position_max_error = 0;
  /// The bits were chosen by rate and distortion (position_bits.h), not by the budget; then
  /// reference_rms_error is the level's own error the choice was made against.
  bool rate_distortion = false;
};

/// Chooses the grids for a primitive (or for several levels of detail of one model: pass the
/// finest, whose points contain every coarser level's). Position grid: the bounding box of
/// `finest.V`, as a cube of its largest extent anchored at the box's minimum (Draco's own
/// convention), bits as in QuantizationBudget from `reference_rms_error` (the RMS surface
/// error of `finest` against the original surface; <= 0 or not finite: the floor decides).
/// Texture coordinates: the texel-centre grid when finest.texture_size > 0, else the bounding
/// box of UV. Errors: InvalidInput (check_gltf_mesh), InvalidArgument (bits outside 1..30 or
/// min > max, fraction <= 0).
[[nodiscard]] Result<QuantizationChoice> choose_draco_quantization(const GltfMesh& finest, double reference_rms_error,
                                                                   const QuantizationBudget& budget = {});

/// Encoder settings for one primitive.
struct DracoEncodeOptions {
  DracoQuantization quantization;  ///< grids (from choose_draco_quantization); points must lie in them
  /// false: edgebreaker (best compression; reorders points). true: sequential encoding, which
  /// keeps the order of points and faces (gotcha 9; glTF-Pipeline's "compression level 0").
  bool sequential = false;
  /// 0..10 as draco_encoder's -cl: Draco encoding speed = decoding speed = 10 - level (its
  /// default, 7, is draco_encoder's).
  int compression_level = 7;
  /// Arbitrary texture coordinates (texture_size 0, not sequential): also encode them with
  /// parallelogram prediction and keep the smaller bitstream (Draco's default predictor, from
  /// the 3D triangle shapes, wins on coarse meshes, parallelogram on fine ones: bunny's
  /// original-mesh levels, 5% smaller level 0, 2-3% larger coarse levels). Twice the encoding
  /// time; deterministic.
  bool smallest_texcoord_prediction = false;
};

/// A decoded Draco primitive and the unique ids of its attributes.
struct DecodedDraco {
  GltfMesh mesh;          ///< points and faces in the decoder's order; N/UV empty if absent
  int position_id = -1;   ///< Draco unique id of POSITION (-1: absent)
  int normal_id = -1;     ///< of NORMAL
  int texcoord_id = -1;   ///< of TEXCOORD_0
};

/// A Draco-compressed primitive: the bitstream and what a decoder gets back from it.
struct DracoPrimitive {
  std::string bytes;      ///< Draco bitstream, the KHR_draco_mesh_compression bufferView
  DecodedDraco decoded;   ///< decode of `bytes` (accessors are written from this)
};

/// Encodes `mesh` (positions, and normals/texture coordinates when present) and decodes the
/// result. Connectivity is built on mesh.position_index (points of one vertex stay one Draco
/// vertex; texture seams become attribute seams). Deterministic. Errors: InvalidInput
/// (check_gltf_mesh; a point outside the position or texture grid), InvalidArgument
/// (compression_level outside 0..10, bad bits or range), Internal (Draco failed to encode or to
/// decode its own output, or sequential encoding changed the point order).
[[nodiscard]] Result<DracoPrimitive> encode_draco_primitive(const GltfMesh& mesh, const DracoEncodeOptions& options);

/// Decodes a Draco mesh bitstream: POSITION (required), NORMAL and TEX_COORD (first of each).
/// Errors: ParseError (not a Draco mesh, corrupt), Unsupported (no 3-component position).
[[nodiscard]] Result<DecodedDraco> decode_draco_primitive(std::string_view bytes);

}  // namespace spherekit::convert
