// Displacement maps as ONE float OpenEXR texture over the cage's UV atlas (issue 22), the
// texture a DCC tool or renderer applies through the texture coordinates of the cage OBJ
// (write_cage_obj with the same CageUvAtlas).
//
// Image: the atlas of cage_uv_atlas.h (C x R blocks of T + 2g texels, quad f's sample (r, c) at
// texel (col·P + g + c, row·P + g + r) from the bottom, texel centres at ((x+0.5)/W, (y+0.5)/H),
// gutters extrapolated linearly), 32-bit float, ZIP. Values in object units:
//   scalar: one channel "Y" = signed distance along the limit normal (a one-channel float map,
//           what renderers take for scalar displacement; tools that read colour see grey, and
//           Blender's Displace, which averages R, G and B, sees the value itself);
//   vector: "R", "G", "B" = object-space x, y, z offset from the limit point.
// Displaced point = limit(f,u,v) + D·n(f,u,v) (scalar) or + D (vector), i.e. "displacement
// along the normal, mid level 0, scale 1" / "vector displacement, object space".
// No alpha or other channel: a fourth channel would be taken for alpha by tools that read
// RGBA. Which samples fell in a hole of the mesh is therefore not stored (only their count).
// String header attributes: spherekit_version, format_version, layout ("cage-uv-atlas"),
// displacement ("scalar" | "vector"), normal ("limit"), cage_n, faces, tile, gutter,
// tile_columns, tile_rows, texel_centres (the convention in words), samples_in_holes,
// source_mesh, sphere_map, cage (the cage OBJ written beside it, if any).
#pragma once

#include <map>
#include <string>

#include "spherekit/convert/cage_uv_atlas.h"
#include "spherekit/convert/displacement.h"
#include "spherekit/status.h"

namespace spherekit::convert {

struct DisplacementProvenance {
  std::string source_mesh;
  std::string sphere_map;
  std::string cage;
};

/// Gutter texels per tile side written by default: two, so that bilinear filtering and the
/// first mip level still see continued values across every tile border.
inline constexpr int kDefaultDisplacementGutter = 2;

/// Writes the map as the atlas texture `atlas` (which must be cage_uv_atlas(map.faces,
/// map.tile, g) for some g), atomically. Errors: InvalidArgument (malformed map, atlas of
/// another layout), IoError.
[[nodiscard]] Status write_displacement_exr(const std::string& path, const DisplacementMap& map,
                                            const CageUvAtlas& atlas, const DisplacementProvenance& provenance = {});

struct DisplacementFile {
  DisplacementMap map;  ///< in_hole all 0 (not stored); samples_in_holes from the header
  CageUvAtlas atlas;
  std::map<std::string, std::string> attributes;
};

/// Reads a texture written by write_displacement_exr: the per-quad samples (gutters dropped).
/// Errors: IoError, InvalidInput (not such a texture: attributes or channels missing, sizes
/// inconsistent).
[[nodiscard]] Result<DisplacementFile> read_displacement_exr(const std::string& path);

}  // namespace spherekit::convert
