// Adaptive levels of detail of a geometry-image remesh (issue 22): quadric edge-collapse
// simplification instead of coarser uniform images, so the levels spend vertices where the
// surface bends.
//
// The remesh of the finest image (geometry_image_mesh: a closed genus-0 manifold, one vertex
// per welded texel) is simplified by libparam's progressive mesh (half-edge collapses at the
// original positions, ordered by the n-D quadric, Garland & Heckbert 1998). Vertices keep
// their texels, so every vertex of every level keeps its texel's texture coordinate exactly
// (gltf_mesh.h convention): one texture or normal map made from the image serves every level.
// Positions: by default each level vertex moves to the minimum of its cluster's quadric
// (fit_positions), so that the coarse surface straddles the fine one.
//
// Seams. Texture coordinates jump where the octahedron folds (the border of the square
// domain, welded pairwise, and its four corners, one vertex). Those border edges are given to
// the simplifier as a path network (ProgressiveMeshOptions::constraint_edges): a border vertex
// only collapses along the border into its border neighbour, the four fold ends (the side
// midpoints) and the corner vertex never move. So no face ever spans the fold: each face lies
// in the square, and a border vertex takes, per face, the copy (texel) that makes the face's
// texture triangle smallest (the wrong copy is across the square).
//
// Collections (Asirvatham et al. 2005 §3, the R^3n mesh of step 4/5): the members' remeshes
// share one connectivity (consistent maps: same texels), so ONE simplification of the mesh
// whose vertex i is every member's vertex i stacked in R^3n gives every member the same
// faces and points at every level; the quadrics measure the error of all members at once, each
// member's distance to its own face planes summed (ProgressiveMeshOptions::model_planes: the
// 2-plane in R^3n would also charge the members' tangential disagreement, no error of a level).
// Each level's members therefore still make a morph-target glTF (gltf_morph.h).
//
// Level k has max(6, round(L / 4^k)) vertices, L = V * lod0_vertex_fraction (V the remesh's)
// or lod0_max_vertices if fewer: the uniform images' factor 4 per level. The cap is the
// original mesh's vertex count: a remesh with more vertices than the mesh it stands for
// cannot be as good as that mesh (its vertices are exact samples, the remesh's are not), and
// would only cost bytes (TOSCA cat0, 5000 vertices: level 0 had 16.5k).
#pragma once

#include <vector>

#include "spherekit/convert/gltf_mesh.h"
#include "spherekit/geometry_image.h"
#include "spherekit/progress.h"
#include "spherekit/status.h"

namespace spherekit::convert {

struct AdaptiveLodOptions {
  int levels = 4;                     ///< >= 1
  /// Vertices of level 0 as a fraction of the finest remesh's (0, 1]; each further level has a
  /// quarter of the previous one's.
  double lod0_vertex_fraction = 0.25;
  /// At most this many vertices in level 0 (0: no cap); the original mesh's vertex count (the
  /// largest member's for a collection).
  int lod0_max_vertices = 0;
  /// Leave out the faces spanning holes of member 0 (geometry_image_hole_faces). The rim
  /// between them and the surface is a simplifier constraint (like the octahedral fold), so
  /// every face keeps its side at every level and the holes stay the size they are in the
  /// finest remesh. Without the constraint, a coarse face with two corners in a hole covered
  /// surface too and was dropped with it: the bunny's coarsest level lost whole patches
  /// around its base (22.7 dB). Changes the connectivity per member: single meshes only.
  bool drop_hole_faces = false;
  /// Place each level's vertices at the minimum of their cluster's plane quadric, per member
  /// (Garland & Heckbert 1997), instead of at their texel's sample; texture coordinates stay
  /// the texel's. false: every vertex is its texel's sample exactly.
  bool fit_positions = true;
};

/// The adaptive levels of one or more members (consistent geometry images of one size):
/// result[k][m] is level k of member m as a glTF primitive (points = (vertex, texel) pairs,
/// positions and normals of the member's image, TEXCOORD_0 of the finest image, position_index
/// = the level's vertex). For every k all members have identical F, UV and position_index.
/// Deterministic. Progress: stage "simplify" (from build_progressive_mesh). Errors:
/// InvalidArgument (no member, sizes differ, malformed image, levels < 1, fraction not in
/// (0, 1]), SolverFailed (simplification stuck), Cancelled.
[[nodiscard]] Result<std::vector<std::vector<GltfMesh>>> adaptive_lod_meshes(const std::vector<GeometryImage>& members,
                                                                            const AdaptiveLodOptions& options = {},
                                                                            const ProgressFn& progress = {});

}  // namespace spherekit::convert
