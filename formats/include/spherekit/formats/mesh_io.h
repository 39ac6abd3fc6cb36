// Readers and writers for meshes. Formats by file extension (case-insensitive):
// read .obj .ply (ascii, binary little/big endian) .off .stl (ascii, binary) .gltf .glb;
// write .obj .ply. Every error message names the file and the problem in one line.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "spherekit/mesh.h"
#include "spherekit/status.h"

namespace spherekit::formats {

/// What to do with faces of more than three corners. Polygons are triangulated by
/// triangulate_polygon (polygon_triangulation.h: quads along the diagonal that keeps both
/// triangles unfolded, larger polygons by ear clipping in their best-fit plane; no fans).
enum class PolygonPolicy {
  Triangulate,         ///< default: triangulate every polygon (triangles, quads and n-gons may mix)
  TriangulateUniform,  ///< triangulate only when all faces have the same corner count; refuse a mix
  Reject,              ///< refuse any face with more than three corners
};

struct ReadOptions {
  PolygonPolicy polygons = PolygonPolicy::Triangulate;
};

/// The faces of the file by corner count, before triangulation.
struct FaceCounts {
  std::int64_t faces = 0;      ///< faces (polygons) in the file
  std::int64_t triangles = 0;  ///< faces with 3 corners
  std::int64_t quads = 0;      ///< faces with 4 corners
  std::int64_t ngons = 0;      ///< faces with 5 or more corners
};

/// Extra information about what the reader saw.
struct ReadInfo {
  std::string format;        ///< "obj", "ply-ascii", "ply-binary-le", "off", "stl-binary", "glb", ...
  int polygons_triangulated = 0;  ///< faces.quads + faces.ngons
  FaceCounts faces;
  /// For every triangle of the mesh (row of F), the 0-based number of the file's face it was
  /// cut from, in the order of the file (glTF: of its triangles, in the order read; STL: the
  /// identity). Non-decreasing; its size is F's row count.
  std::vector<std::int32_t> face_polygon;
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
