// PNG encoding through stb_image_write (Debian's libstb ships the implementation in
// libstb.so, so no STB_IMAGE_WRITE_IMPLEMENTATION here). stbi_write_png_to_func streams the
// file into a callback, which collects it in memory for an atomic write by the caller.
#include "spherekit/convert/png_image.h"

#include <stb/stb_image_write.h>

namespace spherekit::convert {

Image8 Image8::filled(int width, int height, const std::vector<std::uint8_t>& fill) {
  Image8 image;
  image.width = width;
  image.height = height;
  image.channels = static_cast<int>(fill.size());
  const std::size_t n = width > 0 && height > 0 ? static_cast<std::size_t>(width) * static_cast<std::size_t>(height) : 0;
  image.pixels.reserve(n * fill.size());
  for (std::size_t i = 0; i < n; ++i) image.pixels.insert(image.pixels.end(), fill.begin(), fill.end());
  return image;
}

Result<std::string> encode_png(const Image8& image) {
  if (image.width <= 0 || image.height <= 0)
    return Status(ErrorCode::InvalidArgument, "PNG image of " + std::to_string(image.width) + " x " +
                                                  std::to_string(image.height) + " pixels");
  if (image.channels != 1 && image.channels != 3 && image.channels != 4)
    return Status(ErrorCode::InvalidArgument, "PNG image with " + std::to_string(image.channels) + " channels");
  const std::size_t row = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.channels);
  if (image.pixels.size() != row * static_cast<std::size_t>(image.height))
    return Status(ErrorCode::InvalidArgument, "PNG pixel buffer has " + std::to_string(image.pixels.size()) +
                                                  " bytes, expected " + std::to_string(row * static_cast<std::size_t>(image.height)));
  std::string out;
  auto append = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data), static_cast<std::size_t>(size));
  };
  const int ok = stbi_write_png_to_func(append, &out, image.width, image.height, image.channels,
                                        image.pixels.data(), static_cast<int>(row));
  if (!ok || out.empty()) return Status(ErrorCode::Internal, "the PNG encoder failed");
  return out;
}

}  // namespace spherekit::convert
