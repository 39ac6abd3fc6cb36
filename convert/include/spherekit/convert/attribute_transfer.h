// Attribute transfer between members of a consistently parameterized collection (Asirvatham,
// Praun, Hoppe 2005, §5 and Fig. 6: "Consistent parameterizations can also be used to
// transfer mesh properties, such as geometric detail, normals, colors, or texture
// coordinates"). Both meshes are mapped onto the same sphere with corresponding features on
// the same sphere points, so a point of the sphere names corresponding surface points on both.
//
// Per-vertex attributes. Every vertex v of the target `to` has a sphere point S_to(v); it is
// located in the source's sphere map (SphereLocator: the face of `from` containing it and the
// gnomonic barycentrics, exact along the great-circle edges, so neighbouring faces agree on
// their shared edge) and the source's per-vertex values are interpolated with those
// barycentrics. The result is a convex combination of the source values at the corners of one
// face: colours stay in their range, normals are renormalized afterwards. Target vertices
// whose sphere point lies in a hole of the source (holes are uncovered on the sphere) take the
// nearest face's nearest point, and are counted.
//
// Texture coordinates are per face corner, because a texture atlas is cut into charts: two
// neighbouring source faces across a seam have different texture coordinates at the shared
// vertices. Interpolating per target vertex would smear a target face that straddles a seam
// across the whole atlas. Each target face is therefore assigned the chart of the source face
// containing its centre's sphere point; corners whose own source face lies in that chart
// interpolate (the vertex's one texture coordinate, shared by all its faces in the chart),
// the others extrapolate the centre face's texture coordinates with their gnomonic
// barycentrics relative to that face (which may be negative), so the face stays within one
// chart and only stretches across the seam by less than a target face.
//
// Normals as a normal map. Per-vertex normals carry only as much detail as the target has
// vertices; Fig. 6 puts the source's shading on the target's geometry. The members' octahedral
// geometry images share their domain (texel (i, j) is the same sphere point for every member,
// geometry_image.h), so one image of the source's normals, sampled at the texels, applies
// directly to the target's consistent remesh (geometry_image_mesh of the target's image; its
// vertices are the same texels). The map is stored in *object space* (RGB = (n + 1) / 2):
//  * a tangent-space map needs a tangent frame the renderer reproduces exactly (MikkTSpace in
//    glTF); the octahedral unfolding folds the domain along its borders, where any frame
//    derived from the texture coordinates flips, so seams would show. Object-space normals
//    are continuous across the folds (folded texel pairs hold identical values);
//  * members in different orientations are handled by rotating the source normals with the
//    rotation of the similarity that best aligns the source's features with the target's
//    (fit_similarity), which is what carrying normals between two heads in one pose (the
//    paper's figure) needs. Local pose differences (a bent limb) are not compensated.
// three.js renders it with `normalMapType = ObjectSpaceNormalMap`.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "spherekit/convert/png_image.h"
#include "spherekit/geometry_image.h"
#include "spherekit/mesh.h"
#include "spherekit/status.h"

namespace spherekit::convert {

using RowMat2d = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;

/// Per-vertex values moved onto the target.
struct AttributeTransferResult {
  RowMatXd values;             ///< #V_to by k
  int vertices_in_holes = 0;   ///< target vertices whose sphere point is in a hole of the source
};

/// Transfers per-vertex values (#V_from by k, any k >= 1) from `from` to every vertex of `to`.
/// @param S_from, S_to  the members' sphere maps (#V by 3 unit vectors, consistent: one
///                      collection), vertex order of their meshes
/// Errors: InvalidInput (map or value rows differ from the vertex counts, a face index out of
/// range, no usable face in S_from, non-finite values). Deterministic; cost O(#V_to) queries.
[[nodiscard]] Result<AttributeTransferResult> transfer_vertex_attributes(const TriMesh& from, const RowMat3d& S_from,
                                                                         const RowMatXd& values, const TriMesh& to,
                                                                         const RowMat3d& S_to);

/// Area-weighted vertex normals of a mesh (unit; a vertex without non-degenerate faces gets
/// (0, 0, 1)). The normals transfer_vertex_normals uses when the source file has none.
RowMat3d vertex_normals(const TriMesh& mesh);

/// Transfers unit normals (#V_from by 3): interpolated as above, rotated by `rotation` (e.g.
/// fit_similarity(features of from, features of to).R; identity by default), renormalized (a
/// zero interpolant, opposite normals cancelling, gives the rotated normal of the face's first
/// corner). Errors: as transfer_vertex_attributes.
[[nodiscard]] Result<AttributeTransferResult> transfer_vertex_normals(
    const TriMesh& from, const RowMat3d& S_from, const RowMat3d& normals, const TriMesh& to, const RowMat3d& S_to,
    const Eigen::Matrix3d& rotation = Eigen::Matrix3d::Identity());

/// Texture coordinates of the target, per face corner (see the top of this file).
struct UvTransferResult {
  RowMat2d UV;   ///< #T by 2 texture coordinates, the source's convention
  RowMat3i FT;   ///< #F_to by 3 indices into UV
  int seam_faces = 0;         ///< target faces with a corner extrapolated across a chart seam
  int vertices_in_holes = 0;  ///< as in AttributeTransferResult
  int charts = 0;             ///< charts of the source's texture atlas
};

/// Gives `to` the source's texture coordinates, so that the source's texture image applies to
/// the target. @param UV, FT the source's texture coordinates (#T by 2) and per-corner indices
/// (#F_from by 3). Errors: InvalidInput (as transfer_vertex_attributes; FT rows differ from
/// #F_from or index outside UV).
[[nodiscard]] Result<UvTransferResult> transfer_texture_coordinates(const TriMesh& from, const RowMat3d& S_from,
                                                                    const RowMat2d& UV, const RowMat3i& FT,
                                                                    const TriMesh& to, const RowMat3d& S_to);

/// The object-space normal map of a geometry image: pixel (x = j, y = i) holds texel (i, j)'s
/// normal n, rotated by `rotation`, as RGB = round(255 (n + 1) / 2). Applied to another
/// member's remesh through texture coordinates at texel centres (s, t) = ((j + 1/2)/N,
/// (i + 1/2)/N) with t measured from the image's top (glTF; OBJ's v = 1 - t).
/// Errors: InvalidArgument (malformed image: size not 2^k+1 or arrays of the wrong length).
[[nodiscard]] Result<Image8> bake_normal_map(const GeometryImage& image,
                                             const Eigen::Matrix3d& rotation = Eigen::Matrix3d::Identity());

/// The unit normal an object-space normal-map pixel encodes (inverse of the encoding above,
/// up to its 8-bit quantization: at most 0.5/127.5 per component before renormalizing).
Eigen::Vector3d decode_normal_pixel(const std::uint8_t* rgb);

}  // namespace spherekit::convert
