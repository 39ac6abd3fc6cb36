// Triangulation of one polygon face of a mesh file (OBJ, PLY and OFF faces with more than three
// corners), as the readers do it.
//
// A fan (c0, ci, ci+1) is only right for convex planar polygons: around a reflex corner it
// makes triangles that overlap and fold over, which no bijective sphere map can then untangle.
// Instead:
//  * quads are split along the diagonal that leaves both triangles facing the same way as
//    the quad (a non-convex "dart" quad has exactly one such diagonal); when both do, the
//    shorter one (for a non-planar quad it is the one closer to the surface the quad means);
//  * larger polygons are ear-clipped in their best-fit plane (Newell's normal, which for a
//    planar polygon is its normal and for a non-planar one the direction of largest projected
//    area). Each step cuts off an "ear": a convex corner whose triangle holds no other corner,
//    so every triangle faces the polygon's side and none overlap (two ears always exist in a
//    simple polygon: Meisters' two-ears theorem). Among the ears the one with the largest
//    smallest angle goes first (for polygons of up to kBestEarCorners corners; beyond, the
//    first ear found): on irregular polygons it avoids cutting slivers early. (It does not
//    optimise the whole triangulation; a regular n-gon still gets ears of angle pi/n.)
// Self-intersecting or degenerate polygons (repeated corners, all corners on a line) have no
// valid ear at some step: the corner with the most convex angle is cut then, so the result is
// always n - 2 triangles using the polygon's corners in their order (check_mesh reports what
// is wrong with them).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace spherekit::formats {

/// Polygons with more corners than this take the first ear found rather than the best one:
/// choosing costs O(n) ear tests per step, O(n^3) overall.
inline constexpr std::size_t kBestEarCorners = 64;

/// Triangulates the polygon with corners `points` (in order, n >= 3). Appends n - 2 triangles
/// to `triangles`, each as three positions in `points` (0..n-1), oriented like the polygon.
/// Never fails. Cost: O(n) for n <= 4; O(n^3) worst case above (n <= kBestEarCorners: always).
void triangulate_polygon(const std::vector<Eigen::Vector3d>& points, std::vector<std::array<std::uint32_t, 3>>& triangles);

}  // namespace spherekit::formats
