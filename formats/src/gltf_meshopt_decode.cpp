// EXT_meshopt_compression / KHR_meshopt_compression bufferViews through libmeshoptimizer (see
// gltf_compression.h; bitstream: the extension's README, "Appendix A: Bitstream").
#include <meshoptimizer.h>

#include "gltf_compression.h"

namespace spherekit::formats::detail {

Status decode_meshopt(std::string_view bytes, std::uint64_t count, std::uint64_t stride, MeshoptMode mode,
                      MeshoptFilter filter, std::string& out) {
  const bool attributes = mode == MeshoptMode::Attributes;
  if (attributes ? (stride == 0 || stride % 4 != 0 || stride > 256) : (stride != 2 && stride != 4))
    return Status(ErrorCode::ParseError, "byteStride " + std::to_string(stride) + " is not allowed for mode " +
                                             (attributes ? "ATTRIBUTES (multiple of 4, at most 256)" : "TRIANGLES/INDICES (2 or 4)"));
  if (mode == MeshoptMode::Triangles && count % 3 != 0)
    return Status(ErrorCode::ParseError, "count " + std::to_string(count) + " is not a multiple of 3 for mode TRIANGLES");
  if (!attributes && filter != MeshoptFilter::None)
    return Status(ErrorCode::ParseError, "filters apply to mode ATTRIBUTES only");
  if ((filter == MeshoptFilter::Octahedral && stride != 4 && stride != 8) ||
      (filter == MeshoptFilter::Quaternion && stride != 8))
    return Status(ErrorCode::ParseError, "byteStride " + std::to_string(stride) + " does not fit the filter");
  // The vertex codec spends at least 2 header bits per 16 decoded bytes of a byte column
  // (1/64), the index codecs at least a byte per triangle or index: anything claiming more
  // than 64 decoded bytes per stored byte (plus a block's slack) is corrupt.
  const std::uint64_t limit = 64 * static_cast<std::uint64_t>(bytes.size()) + 65536;
  if (count > limit || count * stride > limit)
    return Status(ErrorCode::ParseError, std::to_string(count) + " elements of " + std::to_string(stride) +
                                             " bytes cannot come from " + std::to_string(bytes.size()) +
                                             " compressed bytes (corrupt count?)");
  // A stream's first byte is its codec and version: vertex 0xa0 + v, index 0xe0 + v, index
  // sequence 0xd0 + v. Debian's 0.18 decodes vertex version 0 and index versions 0-1 (gltfpack
  // 1.3 writes vertex version 1 for KHR_meshopt_compression, `-ce khr`): a newer version is
  // not corruption but a newer encoder, and gets its own message.
  if (!bytes.empty()) {
    const unsigned header = static_cast<unsigned char>(bytes[0]);
    const unsigned kind = header & 0xf0, version = header & 0x0f;
    const unsigned want = attributes ? 0xa0 : (mode == MeshoptMode::Triangles ? 0xe0 : 0xd0);
    const unsigned newest = attributes ? 0 : 1;
    if (kind == want && version > newest)
      return Status(ErrorCode::Unsupported,
                    std::string(attributes ? "vertex" : "index") + " codec version " + std::to_string(version) +
                        " (Debian's libmeshoptimizer " + std::to_string(MESHOPTIMIZER_VERSION / 100) + "." +
                        std::to_string(MESHOPTIMIZER_VERSION % 100) + " decodes up to version " +
                        std::to_string(newest) + "; re-encode with EXT_meshopt_compression, e.g. gltfpack -cc "
                                                 "without -ce khr)");
  }
  out.assign(static_cast<std::size_t>(count * stride), '\0');
  const auto* src = reinterpret_cast<const unsigned char*>(bytes.data());
  int rc = 0;
  switch (mode) {
    case MeshoptMode::Attributes: rc = meshopt_decodeVertexBuffer(out.data(), count, stride, src, bytes.size()); break;
    case MeshoptMode::Triangles: rc = meshopt_decodeIndexBuffer(out.data(), count, stride, src, bytes.size()); break;
    case MeshoptMode::Indices: rc = meshopt_decodeIndexSequence(out.data(), count, stride, src, bytes.size()); break;
  }
  if (rc != 0) {
    out.clear();
    return Status(ErrorCode::ParseError, "meshopt data is corrupt or truncated (decoder error " + std::to_string(rc) + ")");
  }
  switch (filter) {
    case MeshoptFilter::None: break;
    case MeshoptFilter::Octahedral: meshopt_decodeFilterOct(out.data(), count, stride); break;
    case MeshoptFilter::Quaternion: meshopt_decodeFilterQuat(out.data(), count, stride); break;
    case MeshoptFilter::Exponential: meshopt_decodeFilterExp(out.data(), count, stride); break;
  }
  return {};
}

}  // namespace spherekit::formats::detail
