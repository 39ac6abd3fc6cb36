// Telling a landmark assignment from its mirror twin through sphere maps (issue 25).
//
// Geodesic distances between extremities cannot tell a near-symmetric shape's left from its
// right, and the turn of matched triples seen from a trilaterated centre fails where the centre
// itself is ambiguous (a human torso's belly and back are about equally far from every limb
// tip, and seen from the back every cyclic order reverses). A sphere map is orientation
// preserving everywhere, so it settles it: each candidate assignment becomes a constrained map
// of the member whose features sit where the reference's map puts the reference's matched
// extremities (Asirvatham, Praun, Hoppe 2005 §4), and the candidate whose dense correspondence
// carries the reference's shape onto the same shape wins. The left/right-swapped assignment
// can only be realised by turning the body round (face onto the back of the head, toes onto
// heels), which no isometry-invariant signal sees but a signed, normal-relative one does.
#pragma once

#include <utility>
#include <vector>

#include "spherekit/mesh.h"

namespace spherekit::detail {

/// Per vertex: how far the surface around it lies below (< 0: convex, a bump) or above
/// (> 0: a dent) its tangent plane, n . (c - p) / sqrt(area), n the outward normal and c the
/// vertex's position after umbrella
/// smoothing whose random walk spreads over about `radius` x sqrt(area) (iterations chosen from
/// the mean edge length, so the scale does not depend on the resolution). Invariant under
/// rigid motions and scale, signed by the outward normal, so it differs between a face and the
/// back of a head.
std::vector<double> smoothed_normal_offset(const TriMesh& mesh, double radius);

/// Pearson correlation of `a` at the reference's vertices and `b` at the member's surface
/// points with the same sphere point (at most ~4000 reference vertices, an even stride). The
/// maps are #V x 3 unit vectors. Returns -2 when the transfer fails.
double correspondence_agreement(const TriMesh& ref, const RowMat3d& S_ref, const std::vector<double>& a,
                                const TriMesh& member, const RowMat3d& S_member, const std::vector<double>& b);

}  // namespace spherekit::detail

namespace spherekit::detail {

/// The sphere test's choice where its two best scores lie within `margin` of each other (the
/// member is then flagged as ambiguous either way). `scored` holds (score, candidate) pairs,
/// best first; candidates are numbered in order of intrinsic cost (0: cheapest). The
/// candidate chosen by triple turns (`turns_pick`, -1 when it was not scored) stands when the
/// test's signal is weak (its best raw correlation `raw_top` below `informative`) or when it
/// scores within `margin` of the best. Otherwise the test has ruled the turns' pick out
/// without deciding between its best few, and the cheapest of those within `margin` of the
/// best is kept. Where the signal is weak, `efficiency` (the constrained map's stretch
/// efficiency per candidate number; empty: not used) still decides when one scored
/// candidate's map is at least `decisive_ratio` times as efficient as every other scored
/// one's: a swapped assignment twists the member's map. Returns the candidate to keep.
int ambiguous_sphere_choice(const std::vector<std::pair<double, int>>& scored, int turns_pick, double raw_top,
                            double margin, double informative, const std::vector<double>& efficiency = {},
                            double decisive_ratio = 0);

}  // namespace spherekit::detail
