// glTF binaries with compressed geometry for the reader tests, built here with
// libmeshoptimizer's own encoders (no npm tool, no network): what gltfpack writes, in miniature.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "spherekit/mesh.h"
#include "spherekit/status.h"

namespace spherekit::test {

/// A .glb split into its JSON and BIN chunks, and put back together.
struct GlbParts {
  nlohmann::json json;
  std::string bin;
};
/// REQUIRE-s a well-formed GLB header and chunk layout.
GlbParts glb_parts(const std::string& glb);
std::string glb_bytes(const GlbParts& parts);

enum class MeshoptGlb {
  /// gltfpack's layout: positions quantized to 14-bit unsigned shorts (KHR_mesh_quantization,
  /// stride 8), dequantized by the node's matrix; vertex codec ATTRIBUTES, index codec
  /// TRIANGLES (u32); EXT_meshopt_compression with a fallback buffer.
  QuantizedTriangles,
  /// The same under the extension's Khronos name, KHR_meshopt_compression, and the node's
  /// translation/scale instead of a matrix.
  QuantizedTrianglesKhr,
  /// Float positions through the EXPONENTIAL filter (15-bit mantissas, stride 12) and the
  /// INDICES codec (u16 index sequence).
  ExponentialIndices,
};

/// `mesh` as a .glb of the given kind (one primitive).
std::string meshopt_glb(const TriMesh& mesh, MeshoptGlb kind);

/// `mesh` as a .glb with KHR_mesh_quantization only (no compression): positions as normalized
/// signed shorts in [-1, 1] about the bounding box's centre, the node's scale and translation
/// mapping them back. Returns the largest coordinate error the quantization allows in `tolerance`.
std::string normalized_short_glb(const TriMesh& mesh, double& tolerance);

/// A reader's refusal: `code`, one line starting "PATH: " and containing `phrase`.
void require_read_error(const Status& status, ErrorCode code, const std::string& path, const std::string& phrase);

/// The largest position error the kind's quantization allows for `mesh` (per coordinate).
double meshopt_glb_tolerance(const TriMesh& mesh, MeshoptGlb kind);

}  // namespace spherekit::test
