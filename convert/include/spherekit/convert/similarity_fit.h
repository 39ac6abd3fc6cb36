// Similarity transforms between corresponding point sets (Umeyama 1991, "Least-squares
// estimation of transformation parameters between two point patterns"), and their
// interpolation from the identity: the feature alignment of morphing (morph.h) and the
// orientation of transferred normals (attribute_transfer.h).
//
// A similarity is stored about a centre c (the centroid of the source points):
//     x  ->  c + d + s R (x - c)
// so that interpolating it (c + t d + s^t R_t (x - c), R_t the rotation by t times R's angle
// about its axis) moves the centroid on a straight line while the shape turns and grows about
// it; interpolating x -> s R x + T instead would swing the shape around the origin.
#pragma once

#include <Eigen/Core>

#include "spherekit/mesh.h"
#include "spherekit/status.h"

namespace spherekit::convert {

/// x -> centre + offset + scale * R * (x - centre).
struct Similarity {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  ///< where the centre goes, relative to it
  double scale = 1;                                  ///< > 0
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();   ///< proper rotation (det +1)

  Eigen::Vector3d apply(const Eigen::Vector3d& x) const { return centre + offset + scale * (R * (x - centre)); }
  /// Every row transformed.
  RowMat3d apply(const RowMat3d& X) const;
  /// The inverse map (same centre convention, about the image of the centre).
  Similarity inverse() const;
  /// The similarity t of the way from the identity (t = 0) to this one (t = 1): offset t*d,
  /// scale s^t, rotation by t times R's angle about R's axis (the shorter way).
  Similarity interpolated(double t) const;
  bool is_identity() const;
};

/// The similarity (with `with_scale`; else rigid, scale 1) minimizing the sum of squared
/// distances |T(from_i) - to_i|^2 (Umeyama), centred at the centroid of `from`.
/// @param from, to  #P by 3 corresponding points, #P >= 3 and not all on one line
/// Errors: InvalidArgument (sizes differ, fewer than 3 points, non-finite values),
/// InvalidInput (the points are (nearly) collinear or coincide: no unique rotation; the
/// threshold is relative to the spread of the points, see the .cpp).
[[nodiscard]] Result<Similarity> fit_similarity(const RowMat3d& from, const RowMat3d& to, bool with_scale = true);

}  // namespace spherekit::convert
