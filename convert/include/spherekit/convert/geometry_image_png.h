// 8-bit PNG previews of an octahedral geometry image, for people: the EXR holds the data, the
// preview shows at a glance whether the image is sane (a smooth unfolding of the surface, no
// tears, where the holes fell). Pixel (x, y) = texel (i = y, j = x), the EXR's own layout, so
// preview and EXR overlay exactly.
#pragma once

#include "spherekit/convert/png_image.h"
#include "spherekit/geometry_image.h"
#include "spherekit/status.h"

namespace spherekit::convert {

enum class GeometryImagePreview {
  /// Unit normals as colours, (r, g, b) = 255 * (n + 1) / 2: the usual object-space normal
  /// map look; reveals the surface's detail and any fold of the sampling.
  Normals,
  /// Positions scaled uniformly into the bounding box's largest extent (centred on the
  /// others), (r, g, b) = (x, y, z): the classic geometry image picture.
  Positions,
};

/// The preview of `image` (size x size, RGB). Texels in holes of the mesh (in_hole) are drawn
/// at half brightness, so holes show where they fell. Deterministic (rounding, no threads).
/// Errors: InvalidArgument (malformed image: sizes disagree, non-finite values).
[[nodiscard]] Result<Image8> geometry_image_preview(const GeometryImage& image, GeometryImagePreview kind);

}  // namespace spherekit::convert
