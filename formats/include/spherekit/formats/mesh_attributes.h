// Per-vertex colours, texture coordinates and normals of a mesh file, beside the geometry
// read_mesh() returns. TriMesh stays plain V/F (every stage of the library takes it); the
// attributes travel next to it for the commands that need them (`spherekit transfer`).
//
// What is read (other formats and statements are ignored, as by read_mesh):
//   OBJ  `v x y z r g b`   colours (r g b as written, usually 0..1) on every vertex or on none
//        `vt u v [w]`      texture coordinates; face corners `i/t` or `i/t/n` give FT
//        `mtllib a.mtl`    material libraries (names as written), `usemtl m` (the first one)
//   PLY  vertex properties red, green, blue (integers scaled by their type's maximum:
//        uchar / 255, ushort / 65535; floats as they are)
// What is written: OBJ `v x y z r g b`, `vt`, `vn`, `mtllib`/`usemtl` and corners `v/t/n`;
// PLY uchar red/green/blue (rounded, clamped to 0..255). Normals are written only.
//
// Texture coordinates use OBJ's convention: (0, 0) is the lower left corner of the image.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "spherekit/formats/mesh_io.h"
#include "spherekit/mesh.h"
#include "spherekit/status.h"

namespace spherekit::formats {

using RowMat2d = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;

/// Attributes of a mesh; every member is optional (empty).
struct MeshAttributes {
  RowMat3d colors;  ///< #V by 3 RGB (0..1 by convention), or empty
  RowMat2d UV;      ///< #T by 2 texture coordinates (OBJ convention), or empty
  /// #F by 3 indices into UV, one per face corner (triangulated like F), or empty. The reader
  /// sets UV and FT together, only when every face corner of the file has a texture
  /// coordinate (else both stay empty).
  RowMat3i FT;
  RowMat3d normals;  ///< #V by 3 per-vertex normals (written as OBJ `vn`, index = vertex), or empty
  std::vector<std::string> material_libraries;  ///< OBJ `mtllib` file names, as written
  std::string material;                         ///< OBJ `usemtl` name (the first one), or empty
};

/// A mesh with its attributes.
struct AttributedMesh {
  TriMesh mesh;
  MeshAttributes attributes;
};

/// Reads a mesh (as read_mesh) and its attributes. Errors: those of read_mesh, plus
/// ParseError (colours on some vertices only, a bad texture-coordinate line, a corner's
/// texture index out of range).
Result<AttributedMesh> read_mesh_with_attributes(const std::string& path, const ReadOptions& options = {},
                                                 ReadInfo* info = nullptr);

/// Checks that `attributes` fit `mesh`: colours and normals #V rows, FT #F rows with indices
/// into UV, all values finite. Errors: InvalidArgument naming the problem.
Status check_mesh_attributes(const TriMesh& mesh, const MeshAttributes& attributes);

/// The file bytes write_mesh_with_attributes would write to `path` (format by its extension),
/// for callers that stage several files themselves. Errors: as below, without IoError.
Result<std::string> format_mesh_with_attributes(const std::string& path, const TriMesh& mesh,
                                                const MeshAttributes& attributes, const WriteOptions& options = {});

/// Writes a mesh with its attributes (.obj, or .ply: colours only) atomically.
/// Errors: InvalidArgument (check_mesh_attributes; texture coordinates or normals to a PLY),
/// IoError, Unsupported (extension).
Status write_mesh_with_attributes(const std::string& path, const TriMesh& mesh, const MeshAttributes& attributes,
                                  const WriteOptions& options = {});

/// One material of an OBJ material library (.mtl): the statements SphereKit reads and writes.
struct ObjMaterial {
  std::string name;         ///< `newmtl name`
  std::string diffuse_map;  ///< `map_Kd FILE` (relative to the .mtl's folder), or empty
  /// `norm FILE`: a normal map, or empty. Written with `map_Bump -bm 1 FILE` too, which more
  /// readers know (three.js's MTLLoader reads both, as a tangent-space map by default).
  std::string normal_map;
};

/// Parses an .mtl file: `newmtl`, `map_Kd`, `norm`, `map_Bump`/`bump` (the last token is the
/// file; options before it are skipped). Errors: IoError, ParseError (a map before any
/// `newmtl`, a statement without a file).
Result<std::vector<ObjMaterial>> read_mtl(const std::string& path);

/// The text of an .mtl file with these materials (white diffuse colour, no specular).
std::string format_mtl(const std::vector<ObjMaterial>& materials);

}  // namespace spherekit::formats
