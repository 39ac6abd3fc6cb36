// Levels of detail of a consistent collection on one member's own connectivity (issue 22:
// "Collections: one simplification of the common remesh with the n-D quadric ..., so every
// member has the same connectivity at every level").
//
// The adaptive levels (adaptive_lods.h) simplify the common geometry-image remesh, whose own
// resampling error is a floor under every level of every member (TOSCA cat0 in {cat0, cat2}:
// level 0 at 76.7 dB with as many vertices as cat0, whose own mesh is exact). Here the common
// mesh is the TEMPLATE member's original mesh instead: a consistent collection already says
// where each of its vertices lies on every other member (the same sphere point, Asirvatham et
// al. 2005 §1), so member m's copy of template vertex v is member m's surface point at the
// template's sphere point of v. The template's levels are then those of its original mesh
// (original_lods.h: cut along the octahedral fold, texture coordinates into the geometry-image
// domain), the other members' are the template's connectivity on their surfaces (every vertex
// an exact surface point of its member), and one simplification in R^3n (memoryless quadrics of
// all members at once) keeps one connectivity per level for every member, so each level is
// also a morph-target glTF.
//
// What it costs the other members: their level 0 is the template's triangulation laid on
// their surface, not their own mesh; its error is that of a remesh with the template's
// vertex count, placed by the correspondence (a poor correspondence shows as slivers).
// Holes: the template's are closed for the simplifier and left out of every level (as
// original_lods.h); a template vertex over another member's hole takes that member's nearest
// surface point (SphereLocator), so the level spans the hole there.
#pragma once

#include <vector>

#include "spherekit/convert/gltf_mesh.h"
#include "spherekit/convert/original_lods.h"
#include "spherekit/mesh.h"
#include "spherekit/progress.h"
#include "spherekit/status.h"

namespace spherekit::convert {

/// One member of a consistent collection: its mesh and its sphere map (#V by 3, consistent
/// with the others').
struct TemplateLodMember {
  const TriMesh* mesh = nullptr;
  const RowMat3d* sphere_map = nullptr;
};

/// The template laid on every member (positions of the fold-cut template mesh per member),
/// with how well it fits each one.
struct TemplateLayout {
  FoldCutMesh cut;     ///< the template's mesh cut along its map's octahedral fold
  RowMatXd positions;  ///< #cut vertices by 3n: member m's copy of vertex v at (v, 3m..3m+2)
  int faces = 0;       ///< the cut's faces that do not close a hole (the ones checked below)
  /// Per member: laid faces folded over on it (normal more than ~78 degrees from the normal
  /// of the member's face nearest the centroid; 0 for the template). Where the member's map,
  /// composed with the template's inverse, is not smooth at the template's triangle scale,
  /// the laid triangulation folds, and its levels are poor surfaces there.
  std::vector<int> folded_faces;
  /// Per member: template vertices whose sphere point falls in a hole of the member (placed
  /// at its nearest surface point).
  std::vector<int> outside_vertices;
};

/// Lays member `template_member`'s mesh on every member. Deterministic. Errors:
/// InvalidArgument (no member, template index, a null mesh or map), InvalidInput (a map's rows
/// differ from its mesh's vertices, a map with no usable face), those of
/// cut_along_octahedral_fold.
[[nodiscard]] Result<TemplateLayout> lay_template(const std::vector<TemplateLodMember>& members, int template_member);

/// result[k][m] is level k of member m (fold_cut_lod_meshes of the layout: the same faces,
/// points, texture coordinates and position_index for every m); level 0 has the template's
/// vertex count (options.lod0_max_vertices if smaller). The template member's levels are
/// original_lod_meshes of its mesh. Deterministic. Progress: stage "simplify". Errors:
/// those of fold_cut_lod_meshes.
[[nodiscard]] Result<std::vector<std::vector<GltfMesh>>> template_lod_meshes(const TemplateLayout& layout,
                                                                            const OriginalLodOptions& options = {},
                                                                            const ProgressFn& progress = {});

}  // namespace spherekit::convert
