// Least-squares similarity between point sets (Umeyama 1991) and its interpolation.
// Umeyama's closed form: with centred points X, Y (#P x 3), Sigma = Y^T X / #P = U D V^T,
// R = U S V^T with S = diag(1, 1, det(U V^T)) (a proper rotation even when the best
// orthogonal map would be a reflection), s = trace(D S) / var(X).
#include "spherekit/convert/similarity_fit.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>

namespace spherekit::convert {

RowMat3d Similarity::apply(const RowMat3d& X) const {
  RowMat3d out(X.rows(), 3);
  for (Eigen::Index i = 0; i < X.rows(); ++i) out.row(i) = apply(Eigen::Vector3d(X.row(i))).transpose();
  return out;
}

Similarity Similarity::inverse() const {
  // y = c + d + s R (x - c)  <=>  x = c + R^T (y - c - d) / s = c' + d' + s' R' (y - c')
  // with c' = c + d, d' = -d, s' = 1/s, R' = R^T.
  Similarity inv;
  inv.centre = centre + offset;
  inv.offset = -offset;
  inv.scale = 1.0 / scale;
  inv.R = R.transpose();
  return inv;
}

Similarity Similarity::interpolated(double t) const {
  Similarity out;
  out.centre = centre;
  out.offset = t * offset;
  out.scale = std::pow(scale, t);
  const Eigen::AngleAxisd aa(R);  // angle in [0, pi]: the shorter way
  out.R = Eigen::AngleAxisd(t * aa.angle(), aa.axis()).toRotationMatrix();
  return out;
}

bool Similarity::is_identity() const {
  return offset == Eigen::Vector3d::Zero() && scale == 1 && R == Eigen::Matrix3d::Identity();
}

Result<Similarity> fit_similarity(const RowMat3d& from, const RowMat3d& to, bool with_scale) {
  if (from.rows() != to.rows())
    return Status(ErrorCode::InvalidArgument, std::to_string(from.rows()) + " source points but " +
                                                  std::to_string(to.rows()) + " target points");
  if (from.rows() < 3)
    return Status(ErrorCode::InvalidArgument, "a similarity needs at least 3 corresponding points, got " +
                                                  std::to_string(from.rows()));
  if (!from.allFinite() || !to.allFinite()) return Status(ErrorCode::InvalidArgument, "non-finite point");
  const double n = static_cast<double>(from.rows());
  const Eigen::RowVector3d mx = from.colwise().mean(), my = to.colwise().mean();
  const Eigen::MatrixXd X = from.rowwise() - mx, Y = to.rowwise() - my;
  const double var_x = X.squaredNorm() / n;
  const Eigen::Matrix3d sigma = Y.transpose() * X / n;
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d d = svd.singularValues();
  // The rotation is unique when the middle singular value of the cross-covariance is not
  // negligible against the largest: 1e-9 relative is far above rounding (1e-16) and far below
  // any real spread of features, which are centimetres apart on metre-sized shapes.
  if (!(var_x > 0) || !(d(0) > 0) || d(1) <= 1e-9 * d(0))
    return Status(ErrorCode::InvalidInput, "the corresponding points are collinear or coincide: no unique rotation");
  Eigen::Vector3d s(1, 1, 1);
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) s(2) = -1;
  Similarity out;
  out.R = svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();
  out.scale = with_scale ? d.dot(s) / var_x : 1.0;
  if (!(out.scale > 0)) return Status(ErrorCode::InvalidInput, "degenerate scale between the point sets");
  out.centre = mx.transpose();
  out.offset = (my - mx).transpose();
  return out;
}

}  // namespace spherekit::convert
