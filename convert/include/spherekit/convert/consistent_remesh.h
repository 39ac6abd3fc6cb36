// The consistent remesh of a collection member: its octahedral geometry image resampled
// through its sphere map (sample_geometry_image), as a mesh (geometry_image_mesh). Members
// mapped consistently (one collection, features on the same sphere points) get remeshes with
// *identical connectivity* whose vertex k is the same sphere point for every member, so vertex
// k of one corresponds to vertex k of all (Asirvatham, Praun, Hoppe 2005, §5; Praun & Hoppe
// 2003 geometry images). Morphing (morph.h) and shape statistics (shape_pca.h) work on these.
#pragma once

#include <cstdint>
#include <vector>

#include "spherekit/geometry_image.h"
#include "spherekit/mesh.h"
#include "spherekit/progress.h"
#include "spherekit/status.h"

namespace spherekit::convert {

/// One member's remesh.
struct ConsistentRemesh {
  GeometryImage image;  ///< the geometry image it was made from (size x size texels)
  TriMesh mesh;         ///< geometry_image_mesh(image): (N-2)^2 + 2N - 1 vertices, 2(N-1)^2 faces
  /// Per face: 1 if it spans a hole of the member (geometry_image_hole_faces), else empty when
  /// the member has no holes.
  std::vector<std::uint8_t> hole_faces;
};

/// Remeshes one member. @param S #V by 3 unit vectors (the member's map), @param size 2^k+1.
/// Errors: as sample_geometry_image (InvalidArgument for size, InvalidInput for the mesh).
[[nodiscard]] Result<ConsistentRemesh> consistent_remesh(const TriMesh& mesh, const RowMat3d& S, int size,
                                                         const GeometryImageOptions& options = {});

/// Remeshes every member (stage "remesh", one progress event per member; Cancelled when the
/// callback returns false). Errors: as consistent_remesh, naming the member index;
/// InvalidArgument if the counts of meshes and maps differ.
[[nodiscard]] Result<std::vector<ConsistentRemesh>> consistent_remeshes(const std::vector<TriMesh>& meshes,
                                                                        const std::vector<RowMat3d>& maps, int size,
                                                                        const GeometryImageOptions& options = {},
                                                                        const ProgressFn& progress = {});

}  // namespace spherekit::convert
