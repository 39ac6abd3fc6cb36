// Geometry images <-> OpenEXR (layout and attributes in geometry_image_exr.h). The file is
// encoded in memory and handed to formats::write_file_atomic (temporary file in the target
// folder + fsync + rename; removed on signals), so no partial EXR is ever visible.
#include "spherekit/convert/geometry_image_exr.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

#include <cstdint>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "exr_memory_stream.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/version.h"

namespace spherekit::convert {
namespace {

const char* const kPositionChannels[3] = {"R", "G", "B"};
const char* const kNormalChannels[3] = {"N.X", "N.Y", "N.Z"};
const char* const kFaceChannel = "face_id";
const char* const kHoleChannel = "in_hole";

}  // namespace

Status write_geometry_image_exr(const std::string& path, const GeometryImage& image,
                                const GeometryImageProvenance& provenance) {
  const int n = image.size;
  const auto texels = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  if (!is_geometry_image_size(n) || image.positions.size() != texels * 3 || image.normals.size() != texels * 3 ||
      image.face_ids.size() != texels || (!image.in_hole.empty() && image.in_hole.size() != texels))
    return Status(ErrorCode::InvalidArgument, path + ": malformed geometry image (size " + std::to_string(n) + ")");
  std::string bytes;
  try {
    Imf::Header header(n, n);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const char* c : kPositionChannels) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    for (const char* c : kNormalChannels) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    header.channels().insert(kFaceChannel, Imf::Channel(Imf::UINT));
    header.channels().insert(kHoleChannel, Imf::Channel(Imf::UINT));
    header.insert("spherekit_version", Imf::StringAttribute(kVersion));
    header.insert("format_version", Imf::StringAttribute(std::to_string(kFormatVersion)));
    header.insert("layout", Imf::StringAttribute("octahedral"));
    header.insert("resolution", Imf::StringAttribute(std::to_string(n)));
    header.insert("source_mesh", Imf::StringAttribute(provenance.source_mesh));
    header.insert("sphere_map", Imf::StringAttribute(provenance.sphere_map));
    header.insert("texels_in_holes", Imf::StringAttribute(std::to_string(image.texels_in_holes)));

    // EXR wants non-const pointers; the writer only reads through them.
    auto* positions = const_cast<float*>(image.positions.data());
    auto* normals = const_cast<float*>(image.normals.data());
    std::vector<std::uint32_t> faces(texels);
    std::vector<std::uint32_t> holes(texels, 0);
    for (std::size_t t = 0; t < texels; ++t) {
      faces[t] = static_cast<std::uint32_t>(image.face_ids[t]);
      if (!image.in_hole.empty()) holes[t] = image.in_hole[t];
    }

    Imf::FrameBuffer fb;
    const std::size_t xs = 3 * sizeof(float), ys = xs * static_cast<std::size_t>(n);
    for (int k = 0; k < 3; ++k) {
      fb.insert(kPositionChannels[k], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(positions + k), xs, ys));
      fb.insert(kNormalChannels[k], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(normals + k), xs, ys));
    }
    fb.insert(kFaceChannel, Imf::Slice(Imf::UINT, reinterpret_cast<char*>(faces.data()), sizeof(std::uint32_t),
                                       sizeof(std::uint32_t) * static_cast<std::size_t>(n)));
    fb.insert(kHoleChannel, Imf::Slice(Imf::UINT, reinterpret_cast<char*>(holes.data()), sizeof(std::uint32_t),
                                       sizeof(std::uint32_t) * static_cast<std::size_t>(n)));
    detail::MemoryStream stream;
    {
      Imf::OutputFile file(stream, header, 1);
      file.setFrameBuffer(fb);
      file.writePixels(n);
    }
    bytes = std::move(stream.bytes());
  } catch (const std::exception& e) {
    return Status(ErrorCode::IoError, path + ": cannot encode EXR (" + e.what() + ")");
  }
  return formats::write_file_atomic(path, bytes);
}

Result<GeometryImageFile> read_geometry_image_exr(const std::string& path) {
  GeometryImageFile out;
  try {
    Imf::InputFile file(path.c_str(), 1);
    const Imf::Header& header = file.header();
    const Imath::Box2i dw = header.dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    if (w != h || !is_geometry_image_size(w))
      return Status(ErrorCode::InvalidInput, path + ": image is " + std::to_string(w) + " x " + std::to_string(h) +
                                                 ", not a square of size 2^k+1");
    for (const char* c : kPositionChannels)
      if (!header.channels().findChannel(c))
        return Status(ErrorCode::InvalidInput, path + ": channel " + c + " is missing");
    for (auto it = header.begin(); it != header.end(); ++it)
      if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
        out.attributes[it.name()] = s->value();

    const int n = w;
    const auto texels = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
    GeometryImage& image = out.image;
    image.size = n;
    image.positions.assign(texels * 3, 0.0f);
    image.normals.assign(texels * 3, 0.0f);
    std::vector<std::uint32_t> faces(texels, 0xffffffffu), holes(texels, 0);
    // Slices are addressed relative to the data window's origin.
    const std::ptrdiff_t origin = static_cast<std::ptrdiff_t>(dw.min.y) * n + dw.min.x;
    const std::size_t xs = 3 * sizeof(float), ys = xs * static_cast<std::size_t>(n);
    Imf::FrameBuffer fb;
    for (int k = 0; k < 3; ++k) {
      fb.insert(kPositionChannels[k],
                Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(image.positions.data() + k - 3 * origin), xs, ys));
      fb.insert(kNormalChannels[k],
                Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(image.normals.data() + k - 3 * origin), xs, ys, 1, 1,
                           0.0));
    }
    fb.insert(kFaceChannel, Imf::Slice(Imf::UINT, reinterpret_cast<char*>(faces.data() - origin),
                                       sizeof(std::uint32_t), sizeof(std::uint32_t) * static_cast<std::size_t>(n), 1,
                                       1, static_cast<double>(0xffffffffu)));
    fb.insert(kHoleChannel, Imf::Slice(Imf::UINT, reinterpret_cast<char*>(holes.data() - origin),
                                       sizeof(std::uint32_t), sizeof(std::uint32_t) * static_cast<std::size_t>(n), 1,
                                       1, 0.0));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    image.face_ids.resize(texels);
    image.in_hole.resize(texels);
    for (std::size_t t = 0; t < texels; ++t) {
      image.face_ids[t] = static_cast<std::int32_t>(faces[t]);
      image.in_hole[t] = holes[t] != 0 ? 1 : 0;
    }
    if (auto it = out.attributes.find("texels_in_holes"); it != out.attributes.end()) {
      try {
        image.texels_in_holes = std::stoi(it->second);
      } catch (const std::exception&) {
        image.texels_in_holes = 0;
      }
    }
  } catch (const std::exception& e) {
    return Status(ErrorCode::IoError, path + ": cannot read EXR (" + e.what() + ")");
  }
  return out;
}

}  // namespace spherekit::convert
