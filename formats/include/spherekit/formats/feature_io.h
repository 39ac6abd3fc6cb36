// Feature (landmark) files and sphere-point files.
//   landmarks:     one line `name vertex_index` (0-based); `#` starts a comment; blank lines ok
//   sphere points: one line `name x y z`
#pragma once

#include <string>
#include <vector>

#include "spherekit/features.h"
#include "spherekit/status.h"

namespace spherekit::formats {

/// Reads a landmark file. `num_vertices` >= 0 checks every index against the mesh.
/// Errors (message names file and line): ParseError (bad line), InvalidInput (index out of
/// range or negative, duplicate name, duplicate vertex).
Result<std::vector<Landmark>> read_landmarks(const std::string& path, int num_vertices = -1);
Status write_landmarks(const std::string& path, const std::vector<Landmark>& landmarks);

/// Reads sphere points. `require_unit`: InvalidInput unless | |p| - 1 | <= 1e-6 for every
/// point (otherwise points are normalised). Errors also for NaN/Inf, zero vectors, duplicate names.
Result<std::vector<SpherePoint>> read_sphere_points(const std::string& path, bool require_unit = false);
/// Writes `name x y z` lines with 17 significant digits, atomically.
Status write_sphere_points(const std::string& path, const std::vector<SpherePoint>& points);

}  // namespace spherekit::formats
