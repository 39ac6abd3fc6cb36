// The rotation that best carries one set of sphere points onto another (orthogonal
// Procrustes / Kabsch): used to orient a map onto feature targets. Internal to libparam.
#pragma once

#include <cmath>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace spherekit::detail {

/// Proper rotation R minimizing sum |R a_i - b_i|^2; for one point, the smallest rotation
/// taking a to b (a half turn about a perpendicular axis when they are opposite).
inline Eigen::Matrix3d best_rotation(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b) {
  if (a.size() == 1) {
    Eigen::Vector3d axis = a[0].cross(b[0]);
    const double s = axis.norm(), c = a[0].dot(b[0]);
    if (!(s > 1e-15)) {
      if (c > 0) return Eigen::Matrix3d::Identity();
      const Eigen::Vector3d o = std::abs(a[0].x()) < 0.6 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
      axis = (o - o.dot(a[0]) * a[0]).normalized();
      return Eigen::AngleAxisd(M_PI, axis).toRotationMatrix();
    }
    return Eigen::AngleAxisd(std::atan2(s, c), axis / s).toRotationMatrix();
  }
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < a.size(); ++i) M += b[i] * a[i].transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) D(2, 2) = -1;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

}  // namespace spherekit::detail
