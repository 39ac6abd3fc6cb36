// Readers and writers for meshes. Formats by file extension (case-insensitive):
// read .obj .ply (ascii, binary little/big endian) .off .stl (ascii, binary) .gltf .glb;
// write .obj .ply. Every error message names the file and the problem in one line.
#pragma once

#include <string>
#include <vector>

#include "spherekit/mesh.h"
#include "spherekit/status.h"

namespace spherekit::formats {

/// What to do with faces of more than three corners.
enum class PolygonPolicy {
  TriangulateUniform,  ///< default: fan-triangulate when all faces have the same corner count
                       ///< (pure quad meshes...); refuse a mix of triangles and polygons
  Triangulate,         ///< always fan-triangulate polygons
  Reject,              ///< refuse any face with more than three corners
};

struct ReadOptions {
  PolygonPolicy polygons = PolygonPolicy::TriangulateUniform;
};

/// Extra information about what the reader saw.
struct ReadInfo {
  std::string format;        ///< "obj", "ply-ascii", "ply-binary-le", "off", "stl-binary", "glb", ...
  int polygons_triangulated = 0;
};

/// Reads a triangle mesh. Errors: IoError (cannot open), ParseError (malformed, truncated,
/// wrong counts), InvalidInput (index out of range, NaN/Inf coordinate, no faces),
/// Unsupported (unknown extension, Draco-compressed glTF, ...).
Result<TriMesh> read_mesh(const std::string& path, const ReadOptions& options = {}, ReadInfo* info = nullptr);

struct WriteOptions {
  bool binary = true;  ///< PLY: binary little endian (doubles) or ascii
  int precision = 17;  ///< significant digits for text formats (17 = exact round trip)
};

/// Writes a mesh (.obj or .ply by extension) atomically: a temporary file in the target
/// folder, renamed over the target only when complete. Errors: IoError, Unsupported.
Status write_mesh(const std::string& path, const TriMesh& mesh, const WriteOptions& options = {});

/// Lower-case extension without the dot ("obj"), or "" if none.
std::string file_extension(const std::string& path);

}  // namespace spherekit::formats
