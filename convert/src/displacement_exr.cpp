// Displacement textures <-> OpenEXR (layout in displacement_exr.h and cage_uv_atlas.h). Encoded
// in memory and written with formats::write_file_atomic, as geometry images are.
#include "spherekit/convert/displacement_exr.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

#include <exception>
#include <string>
#include <vector>

#include "exr_memory_stream.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/version.h"

namespace spherekit::convert {
namespace {

const char* const kScalarChannel = "Y";
const char* const kVectorChannels[3] = {"R", "G", "B"};
const char* const kTexelCentres =
    "texel (x, y) from the bottom-left has its value at UV ((x+0.5)/W, (y+0.5)/H); quad corners at the centres of "
    "their tile's corner texels";

const char* channel_name(int channels, int k) { return channels == 1 ? kScalarChannel : kVectorChannels[k]; }

bool parse_int(const std::map<std::string, std::string>& a, const char* key, int& out) {
  auto it = a.find(key);
  if (it == a.end()) return false;
  try {
    std::size_t used = 0;
    out = std::stoi(it->second, &used);
    return used == it->second.size();
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace

Status write_displacement_exr(const std::string& path, const DisplacementMap& map, const CageUvAtlas& atlas,
                              const DisplacementProvenance& provenance) {
  const int T = map.tile, nf = map.faces, ch = map.channels();
  const std::size_t samples = static_cast<std::size_t>(nf) * T * T;
  if (T < 2 || nf < 1 || map.values.size() != samples * ch)
    return Status(ErrorCode::InvalidArgument, path + ": malformed displacement map");
  auto expected = cage_uv_atlas(nf, T, atlas.gutter);
  if (!expected.ok() || expected->columns != atlas.columns || expected->rows != atlas.rows ||
      atlas.faces != nf || atlas.tile != T)
    return Status(ErrorCode::InvalidArgument, path + ": the UV atlas does not match the displacement map");
  const int width = atlas.width(), height = atlas.height();
  std::vector<float> planes = cage_atlas_image(atlas, map.values, ch);
  std::string bytes;
  try {
    Imf::Header header(width, height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (int k = 0; k < ch; ++k) header.channels().insert(channel_name(ch, k), Imf::Channel(Imf::FLOAT));
    auto put = [&](const char* key, const std::string& value) { header.insert(key, Imf::StringAttribute(value)); };
    put("spherekit_version", kVersion);
    put("format_version", std::to_string(kFormatVersion));
    put("layout", "cage-uv-atlas");
    put("displacement", ch == 1 ? "scalar" : "vector");
    put("normal", "limit");
    put("cage_n", std::to_string(map.cage_n));
    put("faces", std::to_string(nf));
    put("tile", std::to_string(T));
    put("gutter", std::to_string(atlas.gutter));
    put("tile_columns", std::to_string(atlas.columns));
    put("tile_rows", std::to_string(atlas.rows));
    put("texel_centres", kTexelCentres);
    put("samples_in_holes", std::to_string(map.samples_in_holes));
    put("source_mesh", provenance.source_mesh);
    put("sphere_map", provenance.sphere_map);
    put("cage", provenance.cage);
    Imf::FrameBuffer fb;
    const std::size_t xs = sizeof(float) * ch, ys = xs * width;
    for (int k = 0; k < ch; ++k)
      fb.insert(channel_name(ch, k), Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(planes.data() + k), xs, ys));
    detail::MemoryStream stream;
    {
      Imf::OutputFile file(stream, header, 1);
      file.setFrameBuffer(fb);
      file.writePixels(height);
    }
    bytes = std::move(stream.bytes());
  } catch (const std::exception& e) {
    return Status(ErrorCode::IoError, path + ": cannot encode EXR (" + e.what() + ")");
  }
  return formats::write_file_atomic(path, bytes);
}

Result<DisplacementFile> read_displacement_exr(const std::string& path) {
  DisplacementFile out;
  try {
    Imf::InputFile file(path.c_str(), 1);
    const Imf::Header& header = file.header();
    for (auto it = header.begin(); it != header.end(); ++it)
      if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
        out.attributes[it.name()] = s->value();
    DisplacementMap& map = out.map;
    int gutter = 0, columns = 0, rows = 0;
    if (out.attributes["layout"] != "cage-uv-atlas" || !parse_int(out.attributes, "cage_n", map.cage_n) ||
        !parse_int(out.attributes, "faces", map.faces) || !parse_int(out.attributes, "tile", map.tile) ||
        !parse_int(out.attributes, "gutter", gutter) || !parse_int(out.attributes, "tile_columns", columns) ||
        !parse_int(out.attributes, "tile_rows", rows))
      return Status(ErrorCode::InvalidInput, path + ": not a SphereKit displacement texture (header attributes missing)");
    const std::string kind = out.attributes["displacement"];
    if (kind != "scalar" && kind != "vector")
      return Status(ErrorCode::InvalidInput, path + ": unknown displacement kind '" + kind + "'");
    map.kind = kind == "scalar" ? DisplacementKind::Scalar : DisplacementKind::Vector;
    if (!parse_int(out.attributes, "samples_in_holes", map.samples_in_holes)) map.samples_in_holes = 0;
    const Imath::Box2i dw = header.dataWindow();
    const int width = dw.max.x - dw.min.x + 1, height = dw.max.y - dw.min.y + 1;
    auto atlas = cage_uv_atlas(map.faces, map.tile, gutter);
    if (!atlas.ok() || map.cage_n < 1 || map.faces != 6 * map.cage_n * map.cage_n || atlas->columns != columns ||
        atlas->rows != rows || width != atlas->width() || height != atlas->height())
      return Status(ErrorCode::InvalidInput, path + ": texture size does not match its atlas attributes");
    out.atlas = atlas.value();
    const int ch = map.channels();
    for (int k = 0; k < ch; ++k)
      if (!header.channels().findChannel(channel_name(ch, k)))
        return Status(ErrorCode::InvalidInput, path + ": channel " + channel_name(ch, k) + " is missing");
    std::vector<float> planes(static_cast<std::size_t>(width) * height * ch, 0.0f);
    const std::ptrdiff_t origin = static_cast<std::ptrdiff_t>(dw.min.y) * width + dw.min.x;
    const std::size_t xs = sizeof(float) * ch, ys = xs * width;
    Imf::FrameBuffer fb;
    for (int k = 0; k < ch; ++k)
      fb.insert(channel_name(ch, k),
                Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(planes.data() + k - ch * origin), xs, ys));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    map.values = cage_atlas_samples(out.atlas, planes, ch);
    map.in_hole.assign(static_cast<std::size_t>(map.faces) * map.tile * map.tile, 0);
  } catch (const std::exception& e) {
    return Status(ErrorCode::IoError, path + ": cannot read EXR (" + e.what() + ")");
  }
  return out;
}

}  // namespace spherekit::convert
