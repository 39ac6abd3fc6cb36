// Feature (landmark) files, sphere-point files and landmark targets.
//   landmarks:     one line `name vertex_index` (0-based); `#` starts a comment; blank lines ok
//   sphere points: one line `name x y z`
//   targets:       one line `name vertex_index x y z` (where a landmark must land on the
//                  sphere; the `--targets` format of shared/tools/evalsphere.py)
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

/// A landmark vertex and the point of the unit sphere it must map to.
struct LandmarkTarget {
  std::string name;
  int vertex = -1;                                ///< 0-based mesh vertex
  Eigen::Vector3d p = Eigen::Vector3d::Zero();    ///< unit vector (normalised on reading)
};

/// How far from 1 a target's length may be. Targets are written by hand or by tools with a
/// few decimals ("0.577 0.577 0.577" has length 0.9994), so rounding must pass; a point that
/// is not meant to be on the sphere at all (a mesh position, "0 0 2") must not be silently
/// projected onto it.
inline constexpr double kTargetUnitTolerance = 1e-3;

/// Reads landmark targets. `num_vertices` >= 0 checks every index against the mesh.
/// Errors (message names file and line): ParseError (bad line), InvalidInput (index out of
/// range or negative, NaN/Inf, | |p| - 1 | > kTargetUnitTolerance, duplicate name, two
/// targets for one vertex). Points are returned normalised.
Result<std::vector<LandmarkTarget>> read_landmark_targets(const std::string& path, int num_vertices = -1);

}  // namespace spherekit::formats
