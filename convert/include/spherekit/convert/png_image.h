// 8-bit images and their PNG encoding (stb_image_write, Debian's libstb): the normal maps of
// attribute transfer and the plots of `spherekit pca`. Pixel (x, y) is row y from the top,
// column x from the left, as PNG stores them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "spherekit/status.h"

namespace spherekit::convert {

/// An 8-bit image, rows top to bottom, channels interleaved.
struct Image8 {
  int width = 0, height = 0;
  int channels = 3;                 ///< 1 (grey), 3 (RGB) or 4 (RGBA)
  std::vector<std::uint8_t> pixels;  ///< width * height * channels bytes

  /// A width x height image filled with one value per channel (`fill` has `channels` entries).
  static Image8 filled(int width, int height, const std::vector<std::uint8_t>& fill);
  std::uint8_t* at(int x, int y) {
    return &pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) *
                   static_cast<std::size_t>(channels)];
  }
  const std::uint8_t* at(int x, int y) const { return const_cast<Image8*>(this)->at(x, y); }
};

/// The PNG file bytes of `image` (deterministic: the same pixels give the same bytes).
/// Errors: InvalidArgument (sizes <= 0, channels not 1/3/4, pixel count mismatch),
/// Internal (the encoder failed).
[[nodiscard]] Result<std::string> encode_png(const Image8& image);

}  // namespace spherekit::convert
