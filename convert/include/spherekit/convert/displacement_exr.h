// Displacement maps as one OpenEXR atlas (the only other place SphereKit uses OpenEXR).
//
// Layout: the 6n^2 tiles of T x T samples (displacement.h) are packed row by row into a grid
// of C = ceil(sqrt(6n^2)) tile columns and R = ceil(6n^2 / C) tile rows, image size C*T x R*T.
// Pixel (x, y) = (col*T + c, row*T + r) holds sample (r, c) of quad f = row*C + col, i.e.
// (u, v) = (c/(T-1), r/(T-1)) on that quad; pixels of the unused tiles at the end are 0.
// Channels, 32-bit float: "D" for scalar displacement (signed distance along the limit
// normal), or "R", "G", "B" for vector displacement (object-space x, y, z); plus a UINT
// "in_hole" channel (1: the sample's sphere point fell in a hole of the mesh). ZIP
// compression. String header attributes: spherekit_version, format_version, layout
// ("cube-cage-atlas"), displacement ("scalar" | "vector"), cage_n, faces, tile, tile_columns,
// source_mesh, sphere_map, cage (the cage OBJ written beside it, if any).
#pragma once

#include <map>
#include <string>

#include "spherekit/convert/displacement.h"
#include "spherekit/status.h"

namespace spherekit::convert {

struct DisplacementProvenance {
  std::string source_mesh;
  std::string sphere_map;
  std::string cage;
};

/// Tile columns C of the atlas of `faces` tiles.
int displacement_atlas_columns(int faces);

/// Writes the atlas atomically. Errors: InvalidArgument (malformed map), IoError.
[[nodiscard]] Status write_displacement_exr(const std::string& path, const DisplacementMap& map,
                                            const DisplacementProvenance& provenance = {});

struct DisplacementFile {
  DisplacementMap map;
  std::map<std::string, std::string> attributes;
};

/// Reads an atlas written by write_displacement_exr. Errors: IoError, InvalidInput (not such
/// an atlas: attributes or channels missing, sizes inconsistent).
[[nodiscard]] Result<DisplacementFile> read_displacement_exr(const std::string& path);

}  // namespace spherekit::convert
