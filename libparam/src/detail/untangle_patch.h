// Foldover-free repair of a patch of a spherical map. Used when the path network's Steiner
// vertices are removed (paper §4.3 leaves that step implicit): merging a split edge's faces
// back can invert faces whose repair needs many vertices to move together, which moving one
// vertex at a time into its kernel cannot do.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "spherekit/mesh.h"

namespace spherekit::detail {

/// A face set being edited: faces, and per vertex the faces in use around it (faces that no
/// vertex lists are dead and ignored).
struct PatchMesh {
  const std::vector<std::array<int, 3>>* F = nullptr;
  const std::vector<std::vector<int>>* vf = nullptr;
};

/// The given vertices and every vertex within `rings` face rings of them, sorted, unique.
std::vector<int> grow_rings(const PatchMesh& mesh, std::vector<int> verts, int rings);

struct UntanglePatchStats {
  int free_vertices = 0;
  int faces = 0;
  int outer_iterations = 0;
};

/// Untangles the map S around the `bad` faces: the vertices within `rings` face rings of
/// their corners (except `fixed` ones) move, everything else stays. The patch is taken to
/// the plane by the gnomonic projection about its centre, which maps great arcs to lines
/// and so keeps every face's orientation (sign of orient3d with the origin); there a
/// barrier energy with a vanishing regularization (Garanzha et al., "Foldover-free maps in
/// 50 lines of code", 2021) is minimized, each face measured against its shape in X (the
/// mesh), until every face is positive. Returns true when the bad faces and every face
/// around a moved vertex are positive by the exact predicate; otherwise S is left unchanged. False also when the
/// patch does not fit in a hemisphere cap of 75 degrees.
bool untangle_patch(const PatchMesh& mesh, const std::vector<Eigen::Vector3d>& X, const std::vector<char>& fixed,
                    const std::vector<int>& bad, int rings, RowMat3d* S, UntanglePatchStats* stats = nullptr);

}  // namespace spherekit::detail
