// libFuzzer harness: the compressed-geometry decoders on raw bytes (gltf_compression.h), which
// the .glb harness reaches only through a well-formed glTF document. The first byte picks the
// decoder (Draco, or meshopt ATTRIBUTES/TRIANGLES/INDICES with a filter), the next ones the
// Draco attribute id or the meshopt stride and count. Contract: a decode either fails with a
// one-line message or returns exactly what was asked for (Draco: triangle indices in range).
#include "fuzz_common.h"
#include "gltf_compression.h"

using namespace spherekit;
using namespace spherekit::formats::detail;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 4) return 0;
  const std::uint8_t pick = data[0];
  const std::string_view payload = fuzz::bytes_of(data + 4, size - 4);
  if (pick % 4 == 0) {
    Result<DracoPositions> d = decode_draco_positions(payload, data[1] % 4);
    if (!d.ok()) {
      fuzz::require(!d.status().message().empty() && d.status().message().find('\n') == std::string::npos);
      return 0;
    }
    fuzz::require(d->xyz.size() % 3 == 0 && d->triangles.size() % 3 == 0);
    for (const std::uint32_t i : d->triangles) fuzz::require(i < d->xyz.size() / 3);
    return 0;
  }
  const auto mode = static_cast<MeshoptMode>(pick % 4 - 1);
  const auto filter = mode == MeshoptMode::Attributes ? static_cast<MeshoptFilter>((pick / 4) % 4) : MeshoptFilter::None;
  const std::uint64_t stride = mode == MeshoptMode::Attributes ? 4u * (1u + data[1] % 64) : (data[1] % 2 ? 4u : 2u);
  const std::uint64_t count = (std::uint64_t{data[2]} << 8 | data[3]) * (mode == MeshoptMode::Triangles ? 3u : 1u);
  std::string out;
  Status s = decode_meshopt(payload, count, stride, mode, filter, out);
  if (!s.ok()) {
    fuzz::require(!s.message().empty() && s.message().find('\n') == std::string::npos);
    return 0;
  }
  fuzz::require(out.size() == count * stride);
  return 0;
}
