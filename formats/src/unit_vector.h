// Normalising points read from files without overflow or underflow.
#pragma once

#include <Eigen/Core>

namespace spherekit::formats::detail {

/// `p` / |p| for any finite, non-zero `p`. Dividing by the largest |component| first (which
/// makes the length lie in [1, sqrt 3]) keeps |p|^2 from overflowing for p = (1e303, 0, 0) —
/// the plain quotient would be the zero vector — and from losing its precision in subnormal
/// range for p = (1e-320, 1e-320, 0), where the length itself has only a few significant bits.
inline Eigen::Vector3d unit_vector(Eigen::Vector3d p) {
  p /= p.cwiseAbs().maxCoeff();
  return p / p.norm();
}

}  // namespace spherekit::formats::detail
