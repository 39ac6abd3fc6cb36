// Levels of detail of a single mesh by quadric simplification of the ORIGINAL mesh, with
// texture coordinates into the octahedral geometry-image domain (issue 22: "LODs by quadric
// simplification with texture coordinates into the geometry-image domain (seams where the
// octahedron folds)").
//
// The adaptive levels (adaptive_lods.h) simplify the finest geometry-image remesh, whose own
// error is a floor under every level. Here the original mesh is simplified instead (its
// vertices are exact samples of the surface), and every vertex carries the octahedral
// coordinate of its sphere point as TEXCOORD_0, so a texture or normal map made from the
// geometry image still applies.
//
// The fold. The octahedral map is continuous on each quadrant {sign x, sign y} of the sphere
// (the quadrant maps onto one quarter of the square, geometry_image.h); the square's border,
// where it folds, is the lower-hemisphere half of the planes x = 0 and y = 0. So the mesh is
// cut along those planes first (cut_along_octahedral_fold): every edge whose sphere chord
// crosses x = 0 (then y = 0) gets a vertex where it crosses (the same barycentric on the mesh
// edge as on the chord: the sphere map is piecewise linear on chords, gnomonic), and the
// faces are re-triangulated; the fold ends (0, +-1, 0), (+-1, 0, 0) and the poles become
// vertices too. No face then crosses the planes, and each face's texture triangle lies in one
// quarter of the square. The fold's edges (both ends on x = 0, or both on y = 0, and z <= 0)
// are a simplifier path network (progressive_mesh.h), so no face ever spans the fold at any
// level; a fold vertex has two domain points (four at the -z pole), and each face takes the
// ones that make its texture triangle smallest.
//
// Holes: closed by fill_holes' fans for the simplifier (weight 1e-3, the rim a constraint like
// the fold, as adaptive_lods.h), and left out of every level.
//
// Level k has max(8, round(V / 4^k)) vertices, V = the original's (lod0_max_vertices if
// smaller): level 0 is the cut original with the cut's extra vertices collapsed again.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "spherekit/convert/gltf_mesh.h"
#include "spherekit/mesh.h"
#include "spherekit/progress.h"
#include "spherekit/status.h"

namespace spherekit::convert {

/// A closed mesh cut along the octahedral fold planes of its sphere map.
struct FoldCutMesh {
  TriMesh mesh;                         ///< closed (holes filled), no face crossing x = 0 or y = 0 of S
  RowMat3d S;                           ///< unit sphere point of every vertex (exact 0 on the planes)
  std::vector<std::uint8_t> hole_faces; ///< per face: 1 if it closes a hole of the original
  int original_vertices = 0;            ///< the first vertices are the original's, in order
  /// A vertex the cut made on an edge: at a + t (b - a) (a, b earlier vertices, a < b).
  struct EdgePoint {
    int a = 0, b = 0;
    double t = 0;
  };
  /// The cut's vertices, which are the last edge_points.size() vertices, in order.
  std::vector<EdgePoint> edge_points;
};

/// Closes `mesh`'s holes (fill_holes; the centre's sphere point is the normalized mean of its
/// rim's) and cuts it along x = 0 and y = 0 of the sphere map S (#V by 3, one point per
/// vertex), and the cut lines along z = 0. Deterministic. Errors: InvalidInput (S's rows, a
/// zero sphere point, fill_holes' errors).
[[nodiscard]] Result<FoldCutMesh> cut_along_octahedral_fold(const TriMesh& mesh, const RowMat3d& S);

/// The octahedral domain points (u, v) in [-1, 1]^2 of sphere point s: one, or two on the fold
/// (x = 0 or y = 0 with z < 0), four at the -z pole (the corners). Ascending (u, then v).
std::vector<Eigen::Vector2d> octahedral_copies(const Eigen::Vector3d& s);

/// Domain point (u, v) -> glTF texture coordinate of a T x T geometry image (gltf_mesh.h:
/// texel (i, j) at ((j + 1/2)/T, (i + 1/2)/T), u = -1 + 2j/(T-1), v = -1 + 2i/(T-1)).
Eigen::Vector2d octahedral_to_texcoord(const Eigen::Vector2d& uv, int texture_size);

struct OriginalLodOptions {
  int levels = 4;              ///< 1..16
  int texture_size = 257;      ///< T of the geometry image the texture coordinates index (2^k+1)
  int lod0_max_vertices = 0;   ///< cap on level 0's vertices (0: the original's count)
};

/// The levels (level 0 finest): points = (vertex, domain copy) pairs, positions of the cut
/// mesh, area-weighted vertex normals of the level, TEXCOORD_0 = octahedral_to_texcoord of
/// each face's copies (texture_size of the result is 0: arbitrary coordinates), position_index
/// = the level's vertex. Hole faces left out. Deterministic. Progress: stage "simplify".
/// Errors: those of cut_along_octahedral_fold, InvalidArgument (levels, texture size),
/// SolverFailed (simplification stuck), Cancelled.
[[nodiscard]] Result<std::vector<GltfMesh>> original_lod_meshes(const TriMesh& mesh, const RowMat3d& S,
                                                                const OriginalLodOptions& options = {},
                                                                const ProgressFn& progress = {});

/// InvalidArgument unless levels is 1..16, texture_size 2^k+1 and lod0_max_vertices >= 0.
Status check_original_lod_options(const OriginalLodOptions& options);

/// The levels of one or more members that share the fold-cut connectivity `cut`: member m's
/// vertex v is at P.row(v).segment<3>(3 m) (P has 3n columns; cut.mesh.V for one member).
/// One simplification in R^3n (memoryless quadrics: every member's distance to its own face
/// planes, summed, ProgressiveMeshOptions::model_planes), so result[k][m]
/// has the same faces, points, texture coordinates and position_index for every m; normals
/// are each member's own. Level vertex counts as original_lod_meshes (from
/// cut.original_vertices). Errors: InvalidArgument (options, P's shape or non-finite
/// values), those of build_progressive_mesh.
[[nodiscard]] Result<std::vector<std::vector<GltfMesh>>> fold_cut_lod_meshes(const FoldCutMesh& cut, const RowMatXd& P,
                                                                            const OriginalLodOptions& options,
                                                                            const ProgressFn& progress = {});

}  // namespace spherekit::convert
