// Shape statistics of a collection (Asirvatham, Praun, Hoppe 2005, §5 and Fig. 1: "the
// consistent parameterization can be used for tasks such as classification and retrieval based
// on principal component analysis. On the right side of Figure 1 we show the average of our
// set of heads, and the first three principal components"): the average shape and the
// principal components of the members' consistent remeshes (consistent_remesh.h), which have
// one connectivity and corresponding vertices.
//
// Each remesh with V vertices is one row x_i of length 3V (x, y, z of vertex 0, then vertex
// 1, ...). With the mean m and the centred n x 3V matrix X (rows x_i - m), the thin SVD
// X = U S W^T gives the components (rows of W^T, unit length, ordered by singular value) and
// the collection's coefficients c_ij = (x_i - m) . w_j. A member is reconstructed from its
// first k coefficients as m + sum_{j<k} c_ij w_j: the orthogonal projection of x_i - m onto
// the first k components, so its error never grows with k (the table below is monotone
// non-increasing for every member), and with all components (the rank of X, at most n - 1)
// every member is reproduced up to rounding.
//
// Poses are not factored out: a member turned or moved relative to the others contributes
// that motion to the components. The samples share one frame; align members first (e.g. with
// similarity_fit.h on their features) when they do not.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "spherekit/mesh.h"
#include "spherekit/status.h"

namespace spherekit::convert {

/// The PCA of n same-connectivity shapes.
struct ShapePca {
  RowMat3i F;                          ///< the shared faces
  RowMat3d mean;                       ///< V by 3 average shape
  std::vector<RowMat3d> components;    ///< r components, each V by 3 with unit Frobenius norm
  std::vector<double> singular_values; ///< r values, non-increasing, > 0
  /// n by r coefficients of the members ((x_i - m) . w_j, absolute units).
  Eigen::MatrixXd coefficients;
  /// r standard deviations of the coefficients over the collection (singular value / sqrt(n)):
  /// mean +- sigma_j w_j is one standard deviation along component j.
  std::vector<double> sigma;
  /// r fractions of the total variance explained by each component (sum 1).
  std::vector<double> variance_fraction;
};

/// Computes the mean and the components. Components whose singular value is below 1e-12 of
/// the largest (rounding noise of a rank-deficient collection, e.g. two identical members)
/// are dropped. Signs are fixed deterministically: the largest-magnitude entry of each
/// component is positive.
/// Errors: InvalidArgument (no shapes), InvalidInput (shapes differ in vertex count or faces,
/// empty or non-finite).
[[nodiscard]] Result<ShapePca> compute_shape_pca(const std::vector<TriMesh>& shapes);

/// m + sum_{j<k} coefficients(j) w_j with k = coefficients.size() (<= r; asserted).
RowMat3d reconstruct_shape(const ShapePca& pca, const Eigen::VectorXd& coefficients);

/// Reconstruction error versus number of components.
struct PcaErrorTable {
  /// rows k = 0..r (k components used; k = 0 is the mean shape), columns = members: RMS vertex
  /// distance between the member and its reconstruction (absolute units).
  Eigen::MatrixXd rms;
  /// Same layout: PSNR = 20 log10(peak / rms) in dB (+infinity when rms == 0).
  Eigen::MatrixXd psnr;
  std::vector<double> peak;  ///< per member: bounding-box diagonal of the member (the PSNR peak)
  std::vector<double> mean_rms;   ///< per row k: mean of rms over the members
  std::vector<double> max_rms;    ///< per row k: largest rms
  std::vector<double> mean_psnr;  ///< per row k: mean PSNR (dB), +infinity if any member's is
};

/// The error table of `pca` on the shapes it was computed from (or other shapes with the same
/// connectivity: then the projection on the components, which is still monotone).
/// Errors: InvalidInput (a shape's vertex count differs from the mean's).
[[nodiscard]] Result<PcaErrorTable> pca_error_table(const ShapePca& pca, const std::vector<TriMesh>& shapes);

}  // namespace spherekit::convert
