// Geometry images as OpenEXR files (the only place SphereKit uses OpenEXR).
//
// Layout: one scanline image, size x size pixels, pixel (x = column j, y = row i) holds texel
// (i, j) of the octahedral layout (see spherekit/geometry_image.h; EXR's y grows downwards, so
// a viewer shows row 0, v = -1, at the top). Channels, all 32-bit:
//   R, G, B            FLOAT  surface position x, y, z
//   N.X, N.Y, N.Z      FLOAT  unit normal
//   face_id            UINT   face of the source mesh the texel fell in
//   in_hole            UINT   1: the texel's sphere point is in a hole of the mesh (nearest face used)
// ZIP compression. String header attributes: spherekit_version, format_version, layout
// ("octahedral"), resolution (e.g. "257"), source_mesh, sphere_map, texels_in_holes.
#pragma once

#include <map>
#include <string>

#include "spherekit/geometry_image.h"
#include "spherekit/status.h"

namespace spherekit::convert {

/// Where an image came from: recorded as string attributes in the EXR header.
struct GeometryImageProvenance {
  std::string source_mesh;  ///< path or name of the mesh
  std::string sphere_map;   ///< path or name of the sphere map
};

/// Writes `image` as a float EXR atomically (a temporary file in the target folder, renamed
/// over `path` only when complete). Errors: InvalidArgument (malformed image), IoError.
[[nodiscard]] Status write_geometry_image_exr(const std::string& path, const GeometryImage& image,
                                              const GeometryImageProvenance& provenance = {});

/// A geometry image read back, with every string attribute of the header.
struct GeometryImageFile {
  GeometryImage image;
  std::map<std::string, std::string> attributes;
};

/// Reads an EXR written by write_geometry_image_exr. Errors: IoError (cannot open/read),
/// InvalidInput (not square 2^k+1, R/G/B channels missing). Missing normal or face-id
/// channels read as zeros / -1.
[[nodiscard]] Result<GeometryImageFile> read_geometry_image_exr(const std::string& path);

}  // namespace spherekit::convert
