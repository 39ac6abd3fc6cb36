// Closing the boundary loops of a genus-0 mesh with tagged faces that can be removed again.
#pragma once

#include <vector>

#include "spherekit/mesh.h"
#include "spherekit/status.h"

namespace spherekit {

/// A closed mesh built from an open one: the original vertices and faces come first,
/// unchanged and in order; one centre vertex per hole and the fan faces follow.
/// Removing the hole faces = keeping the first `original_faces` faces and the first
/// `original_vertices` vertices.
struct FilledMesh {
  TriMesh mesh;
  int original_vertices = 0;
  int original_faces = 0;
  int holes = 0;
  /// Each boundary loop, as vertex ids in order: loops[i][k] -> loops[i][k+1] (cyclically)
  /// is an edge of an original face in that face's direction, so the surface lies to the
  /// left of the walk and the hole to the right (seen from outside). Hole i's centre
  /// vertex is original_vertices + i; loops are ordered by their first boundary edge.
  std::vector<std::vector<int>> loops;
  bool is_hole_face(int f) const { return f >= original_faces; }
};

/// Fills each boundary loop with a centre vertex (at the loop's centroid) and a
/// triangle fan, oriented consistently with the mesh. A closed mesh is returned as is.
/// Errors: InvalidInput if the boundary is not a set of simple loops (non-manifold).
///
/// The centroid is length-weighted over the loop polyline. A loop that is not star-shaped
/// from it gives a fan that overlaps itself in 3D; that is accepted (only the closed
/// genus-0 topology matters for parameterization, and hole faces get little weight).
/// Errors also for invalid indices, inconsistent orientation, NaN/Inf coordinates and a
/// vertex where two boundary loops touch (split it with repair_pinched_vertices first).
/// Cost: O(V + F).
Result<FilledMesh> fill_holes(const TriMesh& mesh);

}  // namespace spherekit
