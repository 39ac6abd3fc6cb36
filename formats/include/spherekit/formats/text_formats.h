// The small text formats of the correspondence and network tools: vertex-index lists
// (`.corr.txt`, `.gt.txt`), point lists (`x y z` lines) and the path network as an OBJ.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "spherekit/status.h"

namespace spherekit::formats {

/// Whitespace-separated vertex indices (a `.corr.txt` or `.gt.txt` file: entry k of every
/// member's file is the same point; -1 = none). Errors: IoError, ParseError naming the line
/// and the token that is not an index in -1..2e9.
Result<std::vector<int>> read_vertex_indices(const std::string& path);

/// `x y z` lines ('#' comments and blank lines allowed). Errors: IoError, ParseError naming
/// the line (not three numbers, not finite), InvalidInput (no points).
Result<std::vector<Eigen::Vector3d>> read_points(const std::string& path);

/// The path network as OBJ text: each surface path as a polyline (`l`) in group `paths`, and
/// each arc between two of `arc_targets` sampled on the unit sphere in group `arcs`, for
/// viewing next to the mesh and its sphere map.
std::string path_network_obj_text(const std::vector<std::vector<Eigen::Vector3d>>& polylines,
                                  const std::vector<std::array<int, 2>>& arcs,
                                  const std::vector<Eigen::Vector3d>& arc_targets);

}  // namespace spherekit::formats
