// The sphere-map exchange format: an OBJ with the input mesh's vertex order and faces,
// whose vertex positions are the unit-sphere points (17 significant digits, exact).
#pragma once

#include <string>

#include "spherekit/mesh.h"
#include "spherekit/sphere_map.h"
#include "spherekit/status.h"

namespace spherekit::formats {

/// Whether `path` names a file write_sphere_map can write (an .obj), so a caller can refuse a
/// wrong name before any work rather than after it.
Status check_sphere_map_path(const std::string& path);

/// Writes S with the faces of `mesh` atomically; a comment header records provenance.
Status write_sphere_map(const std::string& path, const TriMesh& mesh, const SphereMap& map);

/// Reads a sphere map for `mesh`: InvalidInput if the vertex count differs from the mesh's,
/// if its faces differ from the mesh's (when both have faces: a map of another mesh), or a
/// point is not finite / is zero; points are returned normalised.
Result<SphereMap> read_sphere_map(const std::string& path, const TriMesh& mesh);

}  // namespace spherekit::formats
