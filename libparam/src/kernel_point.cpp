// Spherical Chebyshev centre of a ring's kernel (see detail/kernel_point.h).
#include "detail/kernel_point.h"

#include "spherekit/predicates.h"

namespace spherekit::detail {
namespace {

constexpr int kAscentSteps = 2000;
// Above this many ring faces the check's O(k^3) candidates cost more than the ascent.
constexpr std::size_t kMaxCheckedRing = 16;

// True when the ring's kernel is certainly empty: no x has n_k . x > 0 for all k. The point
// maximizing min_k n_k . x is the centre of the smallest cap holding every n_k; when that cap is
// smaller than a hemisphere (the max-min positive) its centre is one n_k, the midpoint of two
// or the circumcentre of three, so if none of those candidates gets a min above a margin the
// max-min is not positive and the subgradient ascent below cannot succeed either. Untangling
// a fold that no vertex can undo meets such rings at every step (a woody landmark test map
// failing its Steiner-vertex removal: 80 % of its time in 2000-step ascents that could only
// fail). A candidate over the margin ends the search at once: the ascent decides as before.
bool certainly_empty(const std::vector<Eigen::Vector3d>& nrm) {
  constexpr double kMargin = 1e-9;
  auto over = [&](const Eigen::Vector3d& y) {
    const double l = y.norm();
    if (!(l > 0)) return false;
    const Eigen::Vector3d x = y / l;
    for (const auto& n : nrm)
      if (n.dot(x) < -kMargin) return false;
    return true;
  };
  const std::size_t k = nrm.size();
  for (std::size_t i = 0; i < k; ++i) {
    if (over(nrm[i])) return false;
    for (std::size_t j = i + 1; j < k; ++j) {
      if (over(nrm[i] + nrm[j])) return false;
      for (std::size_t l = j + 1; l < k; ++l) {
        const Eigen::Vector3d c = (nrm[j] - nrm[i]).cross(nrm[l] - nrm[i]);
        if (over(c) || over(-c)) return false;
      }
    }
  }
  return true;
}

}  // namespace

bool kernel_point(const RowMat3d& S, const std::vector<std::array<int, 2>>& ring, const Eigen::Vector3d& start,
                  Eigen::Vector3d* out, Eigen::Vector3d* compromise, long* work) {
  std::vector<Eigen::Vector3d> nrm;
  for (const auto& r : ring) {
    Eigen::Vector3d n = S.row(r[0]).transpose().cross(S.row(r[1]).transpose());
    double l = n.norm();
    if (l > 0) nrm.push_back(n / l);
  }
  if (nrm.empty()) return false;
  // An empty kernel without a compromise wanted: the ascent's answer (false, after its
  // kAscentSteps steps, which count as the callers' work as before) without the ascent. With
  // a compromise wanted the ascent still runs: its approximate point is what the soft
  // untangling was measured with (the exact one changed which woody landmark test maps
  // untangled, and their landmarks came out worse: 38 % -> 25 % within 0.05).
  if (!compromise && nrm.size() <= kMaxCheckedRing && certainly_empty(nrm)) {
    if (work) *work += kAscentSteps;
    return false;
  }
  auto valid = [&](const Eigen::Vector3d& x) {
    for (const auto& r : ring)
      if (orient3d_origin(x.data(), S.row(r[0]).data(), S.row(r[1]).data()) <= 0) return false;
    return true;
  };
  Eigen::Vector3d x = start.normalized(), best_x = x;
  double best_min = -1e300;
  double step = 0.1;
  for (int it = 0; it < kAscentSteps; ++it) {
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
