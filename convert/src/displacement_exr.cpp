// Displacement atlases <-> OpenEXR (layout in displacement_exr.h). Encoded in memory and
// written with formats::write_file_atomic, as geometry images are.
#include "spherekit/convert/displacement_exr.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

#include <cmath>
#include <cstdint>
#include <exception>
#include <string>
#include <vector>

#include "exr_memory_stream.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/version.h"

namespace spherekit::convert {
namespace {

const char* const kScalarChannel = "D";
const char* const kVectorChannels[3] = {"R", "G", "B"};
const char* const kHoleChannel = "in_hole";

// Atlas pixel index of sample (r, c) of quad f.
std::size_t atlas_index(int f, int r, int c, int tile, int columns) {
  const int width = columns * tile;
  const int x = (f % columns) * tile + c, y = (f / columns) * tile + r;
  return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
}

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

int displacement_atlas_columns(int faces) {
  int c = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(faces))));
  while (c > 1 && (c - 1) * (c - 1) >= faces) --c;
  while (c * c < faces) ++c;
  return std::max(c, 1);
}

Status write_displacement_exr(const std::string& path, const DisplacementMap& map,
                              const DisplacementProvenance& provenance) {
  const int T = map.tile, nf = map.faces, ch = map.channels();
  const std::size_t samples = static_cast<std::size_t>(nf) * T * T;
  if (T < 2 || nf < 1 || map.values.size() != samples * ch || map.in_hole.size() != samples)
    return Status(ErrorCode::InvalidArgument, path + ": malformed displacement map");
  const int columns = displacement_atlas_columns(nf);
  const int rows = (nf + columns - 1) / columns;
  const int width = columns * T, height = rows * T;
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  std::vector<float> planes(pixels * ch, 0.0f);
  std::vector<std::uint32_t> holes(pixels, 0);
  for (int f = 0; f < nf; ++f)
    for (int r = 0; r < T; ++r)
      for (int c = 0; c < T; ++c) {
        const std::size_t s = (static_cast<std::size_t>(f) * T + r) * T + c, p = atlas_index(f, r, c, T, columns);
        for (int k = 0; k < ch; ++k) planes[p * ch + k] = map.values[s * ch + k];
        holes[p] = map.in_hole[s];
      }
  std::string bytes;
  try {
    Imf::Header header(width, height);
    header.compression() = Imf::ZIP_COMPRESSION;
    const bool scalar = map.kind == DisplacementKind::Scalar;
    if (scalar)
      header.channels().insert(kScalarChannel, Imf::Channel(Imf::FLOAT));
    else
      for (const char* c : kVectorChannels) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    header.channels().insert(kHoleChannel, Imf::Channel(Imf::UINT));
    header.insert("spherekit_version", Imf::StringAttribute(kVersion));
    header.insert("format_version", Imf::StringAttribute(std::to_string(kFormatVersion)));
    header.insert("layout", Imf::StringAttribute("cube-cage-atlas"));
    header.insert("displacement", Imf::StringAttribute(scalar ? "scalar" : "vector"));
    header.insert("cage_n", Imf::StringAttribute(std::to_string(map.cage_n)));
    header.insert("faces", Imf::StringAttribute(std::to_string(nf)));
    header.insert("tile", Imf::StringAttribute(std::to_string(T)));
    header.insert("tile_columns", Imf::StringAttribute(std::to_string(columns)));
    header.insert("source_mesh", Imf::StringAttribute(provenance.source_mesh));
    header.insert("sphere_map", Imf::StringAttribute(provenance.sphere_map));
    header.insert("cage", Imf::StringAttribute(provenance.cage));
    Imf::FrameBuffer fb;
    const std::size_t xs = sizeof(float) * ch, ys = xs * width;
    if (scalar)
      fb.insert(kScalarChannel, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(planes.data()), xs, ys));
    else
      for (int k = 0; k < 3; ++k)
        fb.insert(kVectorChannels[k], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(planes.data() + k), xs, ys));
    fb.insert(kHoleChannel, Imf::Slice(Imf::UINT, reinterpret_cast<char*>(holes.data()), sizeof(std::uint32_t),
                                       sizeof(std::uint32_t) * width));
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
    int columns = 0;
    if (out.attributes["layout"] != "cube-cage-atlas" || !parse_int(out.attributes, "cage_n", map.cage_n) ||
        !parse_int(out.attributes, "faces", map.faces) || !parse_int(out.attributes, "tile", map.tile) ||
        !parse_int(out.attributes, "tile_columns", columns))
      return Status(ErrorCode::InvalidInput, path + ": not a SphereKit displacement atlas (header attributes missing)");
    const std::string kind = out.attributes["displacement"];
    if (kind != "scalar" && kind != "vector")
      return Status(ErrorCode::InvalidInput, path + ": unknown displacement kind '" + kind + "'");
    map.kind = kind == "scalar" ? DisplacementKind::Scalar : DisplacementKind::Vector;
    const Imath::Box2i dw = header.dataWindow();
    const int width = dw.max.x - dw.min.x + 1, height = dw.max.y - dw.min.y + 1;
    const int T = map.tile, nf = map.faces;
    if (T < 2 || nf < 1 || map.cage_n < 1 || nf != 6 * map.cage_n * map.cage_n ||
        columns != displacement_atlas_columns(nf) || width != columns * T ||
        height != ((nf + columns - 1) / columns) * T)
      return Status(ErrorCode::InvalidInput, path + ": atlas size does not match its tile attributes");
    const int ch = map.channels();
    for (int k = 0; k < ch; ++k) {
      const char* name = ch == 1 ? kScalarChannel : kVectorChannels[k];
      if (!header.channels().findChannel(name))
        return Status(ErrorCode::InvalidInput, path + ": channel " + name + " is missing");
    }
    const std::size_t pixels = static_cast<std::size_t>(width) * height;
    std::vector<float> planes(pixels * ch, 0.0f);
    std::vector<std::uint32_t> holes(pixels, 0);
    const std::ptrdiff_t origin = static_cast<std::ptrdiff_t>(dw.min.y) * width + dw.min.x;
    const std::size_t xs = sizeof(float) * ch, ys = xs * width;
    Imf::FrameBuffer fb;
    for (int k = 0; k < ch; ++k)
      fb.insert(ch == 1 ? kScalarChannel : kVectorChannels[k],
                Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(planes.data() + k - ch * origin), xs, ys));
    fb.insert(kHoleChannel, Imf::Slice(Imf::UINT, reinterpret_cast<char*>(holes.data() - origin), sizeof(std::uint32_t),
                                       sizeof(std::uint32_t) * width, 1, 1, 0.0));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    const std::size_t samples = static_cast<std::size_t>(nf) * T * T;
    map.values.assign(samples * ch, 0.0f);
    map.in_hole.assign(samples, 0);
    for (int f = 0; f < nf; ++f)
      for (int r = 0; r < T; ++r)
        for (int c = 0; c < T; ++c) {
          const std::size_t s = (static_cast<std::size_t>(f) * T + r) * T + c, p = atlas_index(f, r, c, T, columns);
          for (int k = 0; k < ch; ++k) map.values[s * ch + k] = planes[p * ch + k];
          map.in_hole[s] = holes[p] ? 1 : 0;
          map.samples_in_holes += map.in_hole[s];
        }
  } catch (const std::exception& e) {
    return Status(ErrorCode::IoError, path + ": cannot read EXR (" + e.what() + ")");
  }
  return out;
}

}  // namespace spherekit::convert
