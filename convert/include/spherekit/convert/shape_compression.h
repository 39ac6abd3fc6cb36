// The compression experiment of a collection: storing n consistent remeshes as a PCA model
// (mean + k components + n x k coefficients, shape_pca.h) versus Draco-compressing every
// remesh alone (gltf_draco.h), as bytes per shape against reconstruction error.
//
// Both sides store the same surfaces (the members' consistent remeshes, the same vertices),
// and the error is measured the same way: RMS distance between corresponding vertices of the
// member's remesh and its decoded version, PSNR against the remesh's bounding-box diagonal.
// Connectivity: the PCA model needs none (a remesh's faces follow from its grid size,
// geometry_image_mesh), whereas Draco codes it (edgebreaker) in every file; that is the
// advantage a consistent parameterization buys, so it is left in.
//
// PCA storage at b bits (b = 0: float32, 4 bytes a value): the mean, each component and the
// coefficient matrix are quantized uniformly on their own [min, max] (2^b - 1 steps, each
// array's min and max kept as two float32), packed into whole bytes (b <= 8: 1 byte, <= 16:
// 2, else 4 bytes a value); `bytes` counts that payload, `bytes_deflated` the same bytes after
// zlib deflate (zlib, best level) as a plain entropy coder would give. Bytes per shape
// divide the whole model by n, so the mean and components are shared by the collection: PCA
// pays off once the collection is large relative to the components kept.
// Draco at b position bits: edgebreaker encoding of positions and faces (compression level
// as given), grid from the remesh's bounding box (choose_draco_quantization); the decoded
// positions are those of a sequential encode on the same grid (same values, point order kept).
#pragma once

#include <string>
#include <vector>

#include "spherekit/convert/shape_pca.h"
#include "spherekit/mesh.h"
#include "spherekit/progress.h"
#include "spherekit/status.h"

namespace spherekit::convert {

struct CompressionOptions {
  std::vector<int> pca_bits = {0, 16, 12};        ///< PCA value encodings (0: float32; else 1..24)
  std::vector<int> draco_bits = {8, 10, 12, 14, 16};  ///< Draco position bits (1..30)
  int draco_compression_level = 7;                ///< 0..10 as draco_encoder's -cl
};

/// One point of the bytes-versus-error curve.
struct CompressionPoint {
  std::string method;            ///< "pca" or "draco"
  int components = 0;            ///< pca: k components (0: the mean alone); draco: 0
  int bits = 0;                  ///< 0: float32; else bits per value (pca) / position (draco)
  double bytes_per_shape = 0;    ///< payload / n (pca) or mean Draco bitstream size (draco)
  double deflated_bytes_per_shape = 0;  ///< pca: after deflate; draco: equal to bytes_per_shape
  double mean_rms = 0;           ///< mean over members of the RMS vertex error (absolute units)
  double max_rms = 0;            ///< largest member RMS error
  double mean_psnr = 0;          ///< mean over members of 20 log10(diagonal / rms), dB (+inf if exact)
};

/// Runs the experiment: for every k = 0..r and every pca_bits, then for every draco_bits.
/// `shapes` are the remeshes `pca` was computed from (stage "compress", one event per
/// configuration). Errors: InvalidArgument (bits out of range, no shapes), InvalidInput
/// (shapes differ from the PCA's vertex count), Internal (Draco failed), Cancelled.
[[nodiscard]] Result<std::vector<CompressionPoint>> compression_experiment(const ShapePca& pca,
                                                                           const std::vector<TriMesh>& shapes,
                                                                           const CompressionOptions& options = {},
                                                                           const ProgressFn& progress = {});

}  // namespace spherekit::convert
