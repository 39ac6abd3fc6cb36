// Decoders for compressed glTF geometry, each in its own translation unit so the glTF reader
// needs neither Draco's nor meshoptimizer's headers:
//  * KHR_draco_mesh_compression through Draco's *core* decoder (draco::Decoder on the
//    bufferView's bytes). Never Draco's glTF reader: libdraco carries an older copy of tinygltf
//    whose symbols clash with Debian's libtinygltf (ECOSYSTEM.md sections 1.3-1.4).
//  * EXT_meshopt_compression / KHR_meshopt_compression bufferViews through libmeshoptimizer
//    (Debian 12: 0.18, which decodes version 0 of the vertex and index codecs and the
//    OCTAHEDRAL, QUATERNION and EXPONENTIAL filters).
// Messages name the problem only; the glTF reader prefixes file and element.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "spherekit/status.h"

namespace spherekit::formats::detail {

/// The positions and triangles of a Draco mesh.
struct DracoPositions {
  std::vector<float> xyz;                 ///< 3 per point
  std::vector<std::uint32_t> triangles;   ///< 3 per face, point indices (checked < points)
};

/// Decodes a Draco mesh bitstream and the attribute with unique id `position_id` (the
/// primitive's KHR_draco_mesh_compression "attributes"."POSITION"), dequantized to float.
/// Errors: ParseError (not a Draco mesh, corrupt or truncated data, no such attribute, not 3
/// components).
Result<DracoPositions> decode_draco_positions(std::string_view bytes, std::uint32_t position_id);

/// How a meshopt bufferView is encoded (EXT_meshopt_compression "mode" and "filter").
enum class MeshoptMode { Attributes, Triangles, Indices };
enum class MeshoptFilter { None, Octahedral, Quaternion, Exponential };

/// Decodes `count` elements of `stride` bytes (the extension's byteStride) into `out`.
/// Checks what the extension requires (ATTRIBUTES: stride a multiple of 4 up to 256;
/// TRIANGLES/INDICES: stride 2 or 4, TRIANGLES: count a multiple of 3; filters: their strides)
/// and refuses sizes no valid stream of `bytes.size()` bytes can decode to (both codecs store
/// at least one byte per 64 decoded), so a hostile count cannot force a huge allocation.
/// Errors: ParseError (corrupt data, bad stride or count), Unsupported (a codec version newer
/// than the library's).
Status decode_meshopt(std::string_view bytes, std::uint64_t count, std::uint64_t stride, MeshoptMode mode,
                      MeshoptFilter filter, std::string& out);

}  // namespace spherekit::formats::detail
