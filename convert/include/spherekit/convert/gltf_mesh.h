// The geometry of one glTF primitive (positions, normals, texture coordinates, triangles), and
// how it is made from an octahedral geometry image or a plain triangle mesh.
//
// glTF stores one value of every attribute per vertex (all accessors of a primitive have the
// same count, glTF 2.0 "Meshes"), so a surface vertex whose texture coordinate differs between
// two faces (a texture seam) is stored as two glTF vertices, here called *points*.
// `position_index` records which points are copies of the same surface vertex, so that the
// Draco encoder keeps the surface connected across the seam (Draco builds its connectivity on
// the position values and codes the seam as attribute connectivity; see gltf_draco.h).
//
// Texture coordinates of a geometry image (TEXCOORD_0). The geometry image of size T is the
// texture; texel (i, j) (row i, column j; geometry_image.h) is pixel (x = j, y = i) of the image
// as written by write_geometry_image_exr, and glTF puts (0, 0) at the first pixel's corner
// (glTF 2.0 "Images": "The origin of the texture coordinates (0, 0) corresponds to the upper
// left corner of a texture image"). A point
// sampling texel (i, j) therefore gets the texel centre
//
//     s = (j + 1/2) / T,   t = (i + 1/2) / T      <=>   j = s*T - 1/2,  i = t*T - 1/2
//
// and the octahedral domain point is u = -1 + 2j/(T-1), v = -1 + 2i/(T-1). Coarser levels of
// detail keep the same texture: texel (a, b) of an image subsampled with stride k is texel
// (a*k, b*k) of the full one. Within a triangle, bilinear texture filtering then interpolates
// exactly the texels between the triangle's corners.
//
//   full image (T = 9), points of the LOD with stride 2 marked o:
//     o . o . o . o . o      each o sits on a texel centre; the folded border pairs
//     . . . . . . . . .      ((0, s) == (0, T-1-s), ...) are separate points (different s)
//     o . o . o . o . o      that share a position_index (the welded vertex of
//     ...                    geometry_image_mesh)
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "spherekit/geometry_image.h"
#include "spherekit/mesh.h"
#include "spherekit/status.h"

namespace spherekit::convert {

using RowMat2d = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;

/// The geometry of one glTF triangle primitive. #P = number of points (glTF vertices).
struct GltfMesh {
  RowMat3d V;   ///< #P by 3 positions (POSITION)
  RowMat3d N;   ///< #P by 3 unit normals (NORMAL), or empty
  RowMat2d UV;  ///< #P by 2 texture coordinates (TEXCOORD_0, glTF convention above), or empty
  RowMat3i F;   ///< #F by 3 point indices, counter-clockwise seen from outside (glTF front face)
  /// #P: index of the surface vertex each point is a copy of (points split at a texture seam
  /// share it; same numbering as geometry_image_mesh's vertices), or empty: every point is its
  /// own vertex.
  std::vector<std::int32_t> position_index;
  /// > 0: UV are texel centres of a texture_size x texture_size image (the formula above),
  /// which lets the Draco grid for texture coordinates hit them exactly (gltf_draco.h).
  /// 0: arbitrary texture coordinates.
  int texture_size = 0;
};

/// Checks the shapes of `mesh`: #P > 0 and #F > 0, N and UV empty or #P rows, indices in
/// range, position_index empty or #P entries >= 0, all values finite. Errors: InvalidInput,
/// naming the first problem.
[[nodiscard]] Status check_gltf_mesh(const GltfMesh& mesh);

/// The image subsampled to `size` (texel (a, b) = texel (a*k, b*k), k = (image.size-1)/(size-1)).
/// The octahedral texel lattices nest (sizes 2^k+1), so this equals resampling the mesh at
/// `size` up to the bit-identical domain points, and folded border pairs stay bit-identical.
/// Errors: InvalidArgument (`size` not 2^k+1 or larger than the image, malformed image).
[[nodiscard]] Result<GeometryImage> subsample_geometry_image(const GeometryImage& image, int size);

/// The primitive of a geometry image: one point per texel (N*N points, row-major texel order),
/// positions and normals from the image, texture coordinates of a texture of size
/// `texture_size` (0: image.size; else (texture_size-1)/(image.size-1) must be a power of two,
/// the stride of `image` within that texture), faces exactly those of
/// geometry_image_mesh(image) but on points, and position_index = geometry_image_mesh's vertex
/// of each texel. The folded border pairs are the only points sharing a position_index.
/// Errors: InvalidArgument (malformed image or texture_size).
[[nodiscard]] Result<GltfMesh> gltf_mesh_from_geometry_image(const GeometryImage& image, int texture_size = 0);

/// Per face of `mesh`, a primitive made from `image` or from a subsampling of it (also after a
/// Draco round trip, which reorders points and faces): 1 if the texels of two or three of its
/// corners, found from the corners' texture coordinates, lie in a hole (the rule of
/// geometry_image_hole_faces).
/// Empty if image.in_hole is empty or the mesh has no texture coordinates.
std::vector<std::uint8_t> gltf_mesh_hole_faces(const GltfMesh& mesh, const GeometryImage& image);

/// `mesh` without the faces flagged 1 in `drop` (one flag per face, or empty: none) and
/// without the points no remaining face uses; the remaining points and faces keep their order
/// and attributes (position_index and texture_size too). A mesh check_gltf_mesh refuses, or
/// flags of the wrong count, give `mesh` unchanged.
GltfMesh gltf_mesh_without_faces(const GltfMesh& mesh, const std::vector<std::uint8_t>& drop);

/// The surface vertex of each point, numbered densely in order of first appearance (0, 1, ...
/// however position_index skips numbers), and their count in *vertices; empty (and *vertices
/// = #P) when position_index is empty: every point is its own vertex. position_index must hold
/// #P entries >= 0 (check_gltf_mesh).
std::vector<std::int32_t> gltf_point_vertices(const GltfMesh& mesh, std::int32_t* vertices);

/// `mesh` without texture coordinates: the points that share a position_index (copies of one
/// surface vertex at a texture seam) become one point, numbered in order of first appearance,
/// with the first copy's position and normal; faces re-indexed in their order;
/// position_index empty and texture_size 0. The copies then no longer split the surface, so
/// an encoder sees one vertex where there were two to four (the octahedral fold of `original`
/// levels). A mesh check_gltf_mesh refuses gives `mesh` unchanged.
GltfMesh gltf_mesh_without_texcoords(const GltfMesh& mesh);

/// A triangle mesh as a primitive without texture coordinates: points = vertices, normals =
/// area-weighted face normals summed per vertex and normalized (a vertex with no non-degenerate
/// face gets (0, 0, 1)). Errors: InvalidInput (empty mesh, index out of range, NaN/Inf).
[[nodiscard]] Result<GltfMesh> gltf_mesh_from_trimesh(const TriMesh& mesh);

}  // namespace spherekit::convert
