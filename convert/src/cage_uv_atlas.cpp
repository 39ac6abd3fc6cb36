// The cage quads' UV atlas (layout, texel-centre convention and gutters in cage_uv_atlas.h).
#include "spherekit/convert/cage_uv_atlas.h"

#include <cmath>
#include <cstddef>

namespace spherekit::convert {

Eigen::Vector2d CageUvAtlas::uv(int f, double u, double v) const {
  const double x = texel_x(f, 0) + u * (tile - 1) + 0.5, y = texel_y(f, 0) + v * (tile - 1) + 0.5;
  return {x / width(), y / height()};
}

Result<CageUvAtlas> cage_uv_atlas(int faces, int tile, int gutter) {
  if (faces < 1 || tile < 2 || gutter < 0 || gutter > 64)
    return Status(ErrorCode::InvalidArgument, "cage UV atlas: need faces >= 1, tile >= 2, gutter 0..64");
  CageUvAtlas a;
  a.faces = faces;
  a.tile = tile;
  a.gutter = gutter;
  // The smallest square-ish grid: C = ceil(sqrt(faces)) columns.
  a.columns = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(faces))));
  while (a.columns > 1 && (a.columns - 1) * (a.columns - 1) >= faces) --a.columns;
  while (a.columns * a.columns < faces) ++a.columns;
  a.rows = (faces + a.columns - 1) / a.columns;
  if (static_cast<long long>(a.columns) * a.pitch() > 65536 || static_cast<long long>(a.rows) * a.pitch() > 65536)
    return Status(ErrorCode::InvalidArgument, "cage UV atlas: the image would be wider than 65536 texels");
  return a;
}

std::vector<float> cage_atlas_image(const CageUvAtlas& a, const std::vector<float>& values, int channels) {
  const int T = a.tile, g = a.gutter, P = a.pitch(), W = a.width(), H = a.height();
  std::vector<float> image(static_cast<std::size_t>(W) * H * channels, 0.0f);
  std::vector<double> block(static_cast<std::size_t>(P) * P);
  for (int f = 0; f < a.faces; ++f)
    for (int ch = 0; ch < channels; ++ch) {
      // block[(r + g) * P + (c + g)] for r, c in -g .. T-1+g.
      auto at = [&](int r, int c) -> double& { return block[static_cast<std::size_t>(r + g) * P + (c + g)]; };
      for (int r = 0; r < T; ++r)
        for (int c = 0; c < T; ++c)
          at(r, c) = values[((static_cast<std::size_t>(f) * T + r) * T + c) * channels + ch];
      // Linear extrapolation across the border: rows first, then whole columns (which then
      // include the row gutters), so gutter corners continue the corner cell bilinearly.
      for (int r = 0; r < T; ++r)
        for (int k = 1; k <= g; ++k) {
          at(r, -k) = at(r, 0) + k * (at(r, 0) - at(r, 1));
          at(r, T - 1 + k) = at(r, T - 1) + k * (at(r, T - 1) - at(r, T - 2));
        }
      for (int c = -g; c < T + g; ++c)
        for (int k = 1; k <= g; ++k) {
          at(-k, c) = at(0, c) + k * (at(0, c) - at(1, c));
          at(T - 1 + k, c) = at(T - 1, c) + k * (at(T - 1, c) - at(T - 2, c));
        }
      for (int r = -g; r < T + g; ++r)
        for (int c = -g; c < T + g; ++c) {
          const int x = a.texel_x(f, c), y = a.texel_y(f, r);
          image[(static_cast<std::size_t>(H - 1 - y) * W + x) * channels + ch] = static_cast<float>(at(r, c));
        }
    }
  return image;
}

std::vector<float> cage_atlas_samples(const CageUvAtlas& a, const std::vector<float>& image, int channels) {
  const int T = a.tile, W = a.width(), H = a.height();
  std::vector<float> values(static_cast<std::size_t>(a.faces) * T * T * channels);
  for (int f = 0; f < a.faces; ++f)
    for (int r = 0; r < T; ++r)
      for (int c = 0; c < T; ++c)
        for (int ch = 0; ch < channels; ++ch)
          values[((static_cast<std::size_t>(f) * T + r) * T + c) * channels + ch] =
              image[(static_cast<std::size_t>(H - 1 - a.texel_y(f, r)) * W + a.texel_x(f, c)) * channels + ch];
  return values;
}

}  // namespace spherekit::convert
