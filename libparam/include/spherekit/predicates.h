// Exact orientation predicates. Validity decisions (is a spherical triangle flipped?)
// are made here and nowhere else, never by a float threshold.
#pragma once

#include <Eigen/Core>

namespace spherekit {

/// Sign of det[a, b, c] = a . (b x c), exactly, for finite double inputs: +1, 0 or -1.
/// For unit vectors a, b, c on the sphere, +1 means the spherical triangle (a, b, c)
/// is counter-clockwise seen from outside. A float filter answers most calls; ties fall
/// back to exact arithmetic.
int orient3d_origin(const double* a, const double* b, const double* c);

inline int orient3d_origin(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  return orient3d_origin(a.data(), b.data(), c.data());
}

/// Sign of the orientation of the tetrahedron (a, b, c, d): sign of det[b-a, c-a, d-a]
/// computed exactly (positive when d lies on the side of plane abc that its normal
/// (b-a)x(c-a) points away from... i.e. det > 0). Exact for finite doubles.
int orient3d(const double* a, const double* b, const double* c, const double* d);

// Notes for both predicates (implementation: predicates.cpp):
// - Non-finite input gives 0 (they cannot report errors and never abort).
// - orient3d: the sign is that of (d - a) . ((b - a) x (c - a)), i.e. +1 when d lies on the
//   side of plane abc that the normal (b - a) x (c - a) points to; orient3d(0, e1, e2, e3) = +1.
// - Cost: ~30 flops when the floating-point filter decides (nearly always for non-degenerate
//   input); exactly or nearly degenerate input takes the exact path, about 1 us for
//   orient3d_origin and 1-3 us for orient3d.

}  // namespace spherekit
