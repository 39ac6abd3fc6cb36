// Spherical Chebyshev centre of a ring's kernel (see detail/kernel_point.h).
#include "detail/kernel_point.h"

#include "spherekit/predicates.h"

namespace spherekit::detail {

bool kernel_point(const RowMat3d& S, const std::vector<std::array<int, 2>>& ring, const Eigen::Vector3d& start,
                  Eigen::Vector3d* out, Eigen::Vector3d* compromise, long* work) {
  std::vector<Eigen::Vector3d> nrm;
  for (const auto& r : ring) {
    Eigen::Vector3d n = S.row(r[0]).transpose().cross(S.row(r[1]).transpose());
    double l = n.norm();
    if (l > 0) nrm.push_back(n / l);
  }
  if (nrm.empty()) return false;
  auto valid = [&](const Eigen::Vector3d& x) {
    for (const auto& r : ring)
      if (orient3d_origin(x.data(), S.row(r[0]).data(), S.row(r[1]).data()) <= 0) return false;
    return true;
  };
  Eigen::Vector3d x = start.normalized(), best_x = x;
  double best_min = -1e300;
  double step = 0.1;
  for (int it = 0; it < 2000; ++it) {
    if (work) ++*work;
    double best = 1e300;
    size_t arg = 0;
    for (size_t k = 0; k < nrm.size(); ++k) {
      double d = nrm[k].dot(x);
      if (d < best) {
        best = d;
        arg = k;
      }
    }
    if (best > 0 && valid(x)) {
      // Keep climbing a little while it stays valid: a central point survives later moves.
      Eigen::Vector3d y = (x + 0.5 * step * nrm[arg]).normalized();
      *out = valid(y) ? y : x;
      return true;
    }
    if (best > best_min) {
      best_min = best;
      best_x = x;
    }
    x = (x + step * nrm[arg]).normalized();
    step *= 0.995;
  }
  if (compromise) *compromise = best_x;
  return false;
}

}  // namespace spherekit::detail
