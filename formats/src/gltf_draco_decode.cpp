// KHR_draco_mesh_compression payloads through Draco's core decoder only (see gltf_compression.h).
#include <draco/compression/decode.h>
#include <draco/core/decoder_buffer.h>

#include "gltf_compression.h"

namespace spherekit::formats::detail {

Result<DracoPositions> decode_draco_positions(std::string_view bytes, std::uint32_t position_id) {
  draco::DecoderBuffer buffer;
  buffer.Init(bytes.data(), bytes.size());
  auto type = draco::Decoder::GetEncodedGeometryType(&buffer);
  if (!type.ok()) return Status(ErrorCode::ParseError, "not Draco data (" + type.status().error_msg_string() + ")");
  if (type.value() != draco::TRIANGULAR_MESH)
    return Status(ErrorCode::ParseError, "Draco data is a point cloud, not a triangle mesh");
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok())
    return Status(ErrorCode::ParseError, "Draco data is corrupt or truncated (" + decoded.status().error_msg_string() + ")");
  const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
  if (!mesh) return Status(ErrorCode::ParseError, "Draco data holds no mesh");
  const draco::PointAttribute* att = mesh->GetAttributeByUniqueId(position_id);
  if (!att)
    return Status(ErrorCode::ParseError, "Draco data has no attribute with unique id " + std::to_string(position_id) +
                                             " (the extension's POSITION)");
  if (att->num_components() != 3)
    return Status(ErrorCode::ParseError, "Draco POSITION has " + std::to_string(att->num_components()) +
                                             " components (need 3)");
  DracoPositions out;
  const std::uint32_t points = mesh->num_points();
  out.xyz.resize(3 * static_cast<std::size_t>(points));
  for (std::uint32_t p = 0; p < points; ++p) {
    if (!att->ConvertValue<float>(att->mapped_index(draco::PointIndex(p)), 3, out.xyz.data() + 3 * std::size_t{p}))
      return Status(ErrorCode::ParseError, "Draco POSITION of point " + std::to_string(p) + " is unreadable");
  }
  out.triangles.resize(3 * static_cast<std::size_t>(mesh->num_faces()));
  for (std::uint32_t f = 0; f < mesh->num_faces(); ++f) {
    const draco::Mesh::Face& face = mesh->face(draco::FaceIndex(f));
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t p = face[k].value();
      if (p >= points) return Status(ErrorCode::ParseError, "Draco face " + std::to_string(f) + " index out of range");
      out.triangles[3 * std::size_t{f} + static_cast<std::size_t>(k)] = p;
    }
  }
  return out;
}

}  // namespace spherekit::formats::detail
