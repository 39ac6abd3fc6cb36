// PCA of a collection's consistent remeshes (Asirvatham, Praun, Hoppe 2005, Fig. 1); the
// formulation is in shape_pca.h.
//
// Cost: the n x 3V matrix has few rows (a collection of tens of shapes) and many columns, so
// the SVD is taken of X^T's thin factorization via Eigen's JacobiSVD with thin U/W, which
// QR-preconditions the wide matrix: O(n^2 V). Memory: n x 3V doubles twice.
#include "spherekit/convert/shape_pca.h"

#include <Eigen/SVD>
#include <cmath>
#include <limits>
#include <string>

namespace spherekit::convert {
namespace {

Eigen::Map<const Eigen::RowVectorXd> flat(const RowMat3d& V) { return {V.data(), 3 * V.rows()}; }

double bbox_diagonal(const RowMat3d& V) {
  return V.rows() ? (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm() : 0.0;
}

}  // namespace

Result<ShapePca> compute_shape_pca(const std::vector<TriMesh>& shapes) {
  if (shapes.empty()) return Status(ErrorCode::InvalidArgument, "PCA of an empty collection");
  const TriMesh& first = shapes[0];
  if (first.V.rows() == 0 || first.F.rows() == 0) return Status(ErrorCode::InvalidInput, "shape 0 is empty");
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    const TriMesh& s = shapes[i];
    if (s.V.rows() != first.V.rows() || s.F.rows() != first.F.rows() || s.F != first.F)
      return Status(ErrorCode::InvalidInput, "shape " + std::to_string(i) + " does not have the connectivity of shape 0 (" +
                                                 std::to_string(s.V.rows()) + " vs " + std::to_string(first.V.rows()) +
                                                 " vertices): use consistent remeshes of one collection");
    if (!s.V.allFinite()) return Status(ErrorCode::InvalidInput, "shape " + std::to_string(i) + " has a non-finite vertex");
  }
  const auto n = static_cast<Eigen::Index>(shapes.size());
  const Eigen::Index cols = 3 * first.V.rows();
  Eigen::MatrixXd X(n, cols);
  for (Eigen::Index i = 0; i < n; ++i) X.row(i) = flat(shapes[static_cast<std::size_t>(i)].V);
  const Eigen::RowVectorXd mean = X.colwise().mean();
  X.rowwise() -= mean;

  ShapePca out;
  out.F = first.F;
  out.mean = Eigen::Map<const RowMat3d>(mean.data(), first.V.rows(), 3);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(X, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& s = svd.singularValues();
  // 1e-12 of the largest singular value: far above the ~1e-16 relative rounding of the SVD of
  // centred data, far below any real shape variation.
  Eigen::Index r = 0;
  while (r < s.size() && s(r) > 1e-12 * s(0) && s(r) > 0) ++r;
  Eigen::MatrixXd W = svd.matrixV().leftCols(r);  // 3V x r, orthonormal columns
  for (Eigen::Index j = 0; j < r; ++j) {
    Eigen::Index big = 0;
    W.col(j).cwiseAbs().maxCoeff(&big);
    if (W(big, j) < 0) W.col(j) = -W.col(j);
  }
  // Coefficients as projections (not U S): the truncated reconstructions are then orthogonal
  // projections whatever the SVD's rounding, which keeps the error table monotone.
  out.coefficients = X * W;
  double total = 0;
  for (Eigen::Index j = 0; j < r; ++j) total += s(j) * s(j);
  for (Eigen::Index j = 0; j < r; ++j) {
    const Eigen::VectorXd w = W.col(j);
    out.components.push_back(Eigen::Map<const RowMat3d>(w.data(), first.V.rows(), 3));
    out.singular_values.push_back(s(j));
    out.sigma.push_back(s(j) / std::sqrt(static_cast<double>(n)));
    out.variance_fraction.push_back(total > 0 ? s(j) * s(j) / total : 0.0);
  }
  return out;
}

RowMat3d reconstruct_shape(const ShapePca& pca, const Eigen::VectorXd& coefficients) {
  RowMat3d out = pca.mean;
  for (Eigen::Index j = 0; j < coefficients.size(); ++j)
    out += coefficients(j) * pca.components[static_cast<std::size_t>(j)];
  return out;
}

Result<PcaErrorTable> pca_error_table(const ShapePca& pca, const std::vector<TriMesh>& shapes) {
  const auto r = static_cast<Eigen::Index>(pca.components.size());
  const auto n = static_cast<Eigen::Index>(shapes.size());
  PcaErrorTable t;
  t.rms.resize(r + 1, n);
  t.psnr.resize(r + 1, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const TriMesh& s = shapes[static_cast<std::size_t>(i)];
    if (s.V.rows() != pca.mean.rows())
      return Status(ErrorCode::InvalidInput, "shape " + std::to_string(i) + " has " + std::to_string(s.V.rows()) +
                                                 " vertices, the PCA " + std::to_string(pca.mean.rows()));
    const double peak = bbox_diagonal(s.V);
    t.peak.push_back(peak);
    // Projections of this shape (equal to pca.coefficients for a member).
    Eigen::VectorXd c(r);
    const RowMat3d centred = s.V - pca.mean;
    for (Eigen::Index j = 0; j < r; ++j) c(j) = flat(centred).dot(flat(pca.components[static_cast<std::size_t>(j)]));
    for (Eigen::Index k = 0; k <= r; ++k) {
      const RowMat3d rec = reconstruct_shape(pca, c.head(k));
      const double rms = std::sqrt((rec - s.V).squaredNorm() / static_cast<double>(s.V.rows()));
      t.rms(k, i) = rms;
      t.psnr(k, i) = rms > 0 ? 20 * std::log10(peak / rms) : std::numeric_limits<double>::infinity();
    }
  }
  for (Eigen::Index k = 0; k <= r; ++k) {
    t.mean_rms.push_back(n ? t.rms.row(k).mean() : 0.0);
    t.max_rms.push_back(n ? t.rms.row(k).maxCoeff() : 0.0);
    t.mean_psnr.push_back(n ? t.psnr.row(k).mean() : 0.0);
  }
  return t;
}

}  // namespace spherekit::convert
