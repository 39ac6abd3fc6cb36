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
