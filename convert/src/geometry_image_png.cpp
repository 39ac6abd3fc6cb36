#include "spherekit/convert/geometry_image_png.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

namespace spherekit::convert {
namespace {

std::uint8_t to_byte(double unit) {  // [0, 1] -> 0..255, clamped and rounded
  return static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(unit, 0.0, 1.0)));
}

}  // namespace

Result<Image8> geometry_image_preview(const GeometryImage& image, GeometryImagePreview kind) {
  const int n = image.size;
  const std::size_t texels = static_cast<std::size_t>(n > 0 ? n : 0) * static_cast<std::size_t>(n > 0 ? n : 0);
  const std::vector<float>& values = kind == GeometryImagePreview::Normals ? image.normals : image.positions;
  if (n < 2 || values.size() != 3 * texels || (!image.in_hole.empty() && image.in_hole.size() != texels))
    return Status(ErrorCode::InvalidArgument, "geometry image preview: malformed image (size " + std::to_string(n) + ")");
  for (float v : values)
    if (!std::isfinite(v)) return Status(ErrorCode::InvalidArgument, "geometry image preview: non-finite texel value");

  // Normals map [-1, 1] -> [0, 1]; positions map the bounding box, uniformly scaled by its
  // largest extent so shapes are not distorted, the smaller axes centred.
  std::array<double, 3> offset{0.5, 0.5, 0.5}, scale{0.5, 0.5, 0.5};
  if (kind == GeometryImagePreview::Positions) {
    std::array<double, 3> lo{values[0], values[1], values[2]}, hi = lo;
    for (std::size_t t = 0; t < texels; ++t)
      for (int c = 0; c < 3; ++c) {
        lo[c] = std::min(lo[c], static_cast<double>(values[3 * t + c]));
        hi[c] = std::max(hi[c], static_cast<double>(values[3 * t + c]));
      }
    double extent = 0;
    for (int c = 0; c < 3; ++c) extent = std::max(extent, hi[c] - lo[c]);
    if (!(extent > 0)) extent = 1;
    for (int c = 0; c < 3; ++c) {
      scale[c] = 1.0 / extent;
      offset[c] = 0.5 - 0.5 * (lo[c] + hi[c]) / extent;  // centre of the box -> 0.5
    }
  }
  Image8 out = Image8::filled(n, n, {0, 0, 0});
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const std::size_t t = static_cast<std::size_t>(i) * static_cast<std::size_t>(n) + static_cast<std::size_t>(j);
      const double dim = !image.in_hole.empty() && image.in_hole[t] ? 0.5 : 1.0;
      std::uint8_t* px = out.at(j, i);
      for (int c = 0; c < 3; ++c) px[c] = to_byte(dim * (offset[c] + scale[c] * values[3 * t + c]));
    }
  return out;
}

}  // namespace spherekit::convert
