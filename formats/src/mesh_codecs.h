// Internal entry points of the per-format readers and writers. read_mesh() picks one by
// extension; read_sphere_map() parses bytes it has already read (to also see the header).
// Readers get the whole file in memory and the path only for messages.
#pragma once

#include <string>
#include <string_view>

#include "spherekit/formats/mesh_attributes.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/sphere_map.h"

namespace spherekit::formats::detail {

/// `attributes` (optional): also collect what mesh_attributes.h describes.
Result<TriMesh> read_obj(const std::string& path, std::string_view bytes, const ReadOptions& options, ReadInfo& info,
                         MeshAttributes* attributes = nullptr);
Result<TriMesh> read_ply(const std::string& path, std::string_view bytes, const ReadOptions& options, ReadInfo& info,
                         MeshAttributes* attributes = nullptr);
Result<TriMesh> read_off(const std::string& path, std::string_view bytes, const ReadOptions& options, ReadInfo& info);
Result<TriMesh> read_stl(const std::string& path, std::string_view bytes, const ReadOptions& options, ReadInfo& info);
/// `glb`: binary container (.glb) rather than JSON text (.gltf). External buffers are
/// resolved relative to the folder of `path`.
Result<TriMesh> read_gltf(const std::string& path, std::string_view bytes, bool glb, const ReadOptions& options,
                          ReadInfo& info);

/// Parses a mesh file already in memory, choosing the reader by the extension of `path`.
Result<TriMesh> parse_mesh(const std::string& path, std::string_view bytes, const ReadOptions& options,
                           ReadInfo* info);

/// Parses a sphere map already in memory (read_sphere_map without the file read).
Result<SphereMap> parse_sphere_map(const std::string& path, std::string_view bytes, const TriMesh& mesh);

/// OBJ text: `header` (already '#'-commented lines) first, then `v` lines and 1-based `f` lines.
/// `attributes` (optional, already checked): colours, `vt`, `vn`, mtllib/usemtl.
std::string format_obj(const TriMesh& mesh, int precision, const std::string& header,
                       const MeshAttributes* attributes = nullptr);
/// PLY: binary little endian with double coordinates and int indices, or ascii; with
/// `attributes` colours as uchar red, green, blue.
std::string format_ply(const TriMesh& mesh, bool binary, int precision, const MeshAttributes* attributes = nullptr);

}  // namespace spherekit::formats::detail
