// Feature warp of the constrained stage for dense feature sets (see detail/feature_warp.h).
//
// Why a radial-basis flow: the displacement field d(x) = sum_j c_j phi(|x - p_j| / h) (Wendland's C2 function)
// interpolates the features' displacements (the kernel matrix is positive definite for
// distinct points) and is smooth, so x -> normalize(x + d(x)) is a diffeomorphism
// of the sphere when d is small against its own variation; taking small steps along the great
// arcs from the features' current images to their targets keeps it so, and the exact
// orientation predicate checks every step on the mesh itself (a step that flips a face is
// halved, never accepted). Features already on target have zero displacement, so the
// network's features stay put (up to rounding, snapped at the end).
#include "detail/feature_warp.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>

#include "detail/untangle_patch.h"
#include "spherekit/predicates.h"

namespace spherekit::detail {
namespace {

double angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

// Point at fraction t of the great arc from a to b (a != -b).
Eigen::Vector3d slerp(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double t) {
  const double th = angle(a, b);
  if (th < 1e-12) return (a + t * (b - a)).normalized();
  const double s = std::sin(th);
  return ((std::sin((1 - t) * th) / s) * a + (std::sin(t * th) / s) * b).normalized();
}

// Wendland's C2 function (compact support 1, positive definite in R^3): a smooth field whose
// features far apart do not interact.
double wendland(double r) {
  if (r >= 1) return 0;
  const double a = 1 - r, a2 = a * a;
  return a2 * a2 * (4 * r + 1);
}

bool any_flipped(const RowMat3i& F, const RowMat3d& S) {
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    if (orient3d_origin(S.row(F(f, 0)).data(), S.row(F(f, 1)).data(), S.row(F(f, 2)).data()) <= 0) return true;
  return false;
}

}  // namespace

std::vector<int> spread_subset(const std::vector<Eigen::Vector3d>& targets, int count) {
  const int k = static_cast<int>(targets.size());
  std::vector<int> out;
  if (k == 0 || count <= 0) return out;
  std::vector<double> d(static_cast<size_t>(k), std::numeric_limits<double>::infinity());
  int next = 0;
  while (static_cast<int>(out.size()) < std::min(count, k)) {
    out.push_back(next);
    d[static_cast<size_t>(next)] = -1;
    for (int j = 0; j < k; ++j)
      if (d[static_cast<size_t>(j)] >= 0)
        d[static_cast<size_t>(j)] = std::min(d[static_cast<size_t>(j)], angle(targets[static_cast<size_t>(j)], targets[static_cast<size_t>(next)]));
    next = static_cast<int>(std::max_element(d.begin(), d.end()) - d.begin());
  }
  std::sort(out.begin(), out.end());
  return out;
}

Status warp_features_to_targets(const RowMat3d& X, const RowMat3i& F, const std::vector<int>& fv,
                                const std::vector<Eigen::Vector3d>& targets, const ProgressFn& progress, RowMat3d* S,
                                WarpStats* stats) {
  const int k = static_cast<int>(fv.size());
  if (static_cast<int>(targets.size()) != k) return Status(ErrorCode::InvalidArgument, "one target per feature is required");
  if (any_flipped(F, *S)) return Status(ErrorCode::SolverFailed, "feature warp: the start map is not bijective");
  std::vector<Eigen::Vector3d> start(static_cast<size_t>(k)), q(static_cast<size_t>(k));
  double longest = 0;
  for (int j = 0; j < k; ++j) {
    start[static_cast<size_t>(j)] = S->row(fv[static_cast<size_t>(j)]).transpose();
    q[static_cast<size_t>(j)] = targets[static_cast<size_t>(j)].normalized();
    longest = std::max(longest, angle(start[static_cast<size_t>(j)], q[static_cast<size_t>(j)]));
  }
  if (longest > 3.0) return Status(ErrorCode::SolverFailed, "feature warp: a feature is nearly antipodal to its target");
  // Kernel support: three times the median distance from a target to its nearest other
  // target, the scale at which neighbouring features' displacements may differ.
  std::vector<double> nearest;
  for (int i = 0; i < k; ++i) {
    double m = std::numeric_limits<double>::infinity();
    for (int j = 0; j < k; ++j)
      if (j != i) m = std::min(m, (q[static_cast<size_t>(i)] - q[static_cast<size_t>(j)]).norm());
    nearest.push_back(m);
  }
  std::nth_element(nearest.begin(), nearest.begin() + static_cast<long>(nearest.size() / 2), nearest.end());
  double support = 3 * nearest[nearest.size() / 2];
  double inv_h = 1 / support;
  int widened = 0;

  // For reshaping slivers (untangle_patch): the faces, vertex-face incidence, the mesh.
  std::vector<std::array<int, 3>> faces(static_cast<size_t>(F.rows()));
  std::vector<std::vector<int>> vf(static_cast<size_t>(S->rows()));
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      faces[static_cast<size_t>(f)][static_cast<size_t>(c)] = F(f, c);
      vf[static_cast<size_t>(F(f, c))].push_back(static_cast<int>(f));
    }
  std::vector<Eigen::Vector3d> Xv(static_cast<size_t>(X.rows()));
  for (Eigen::Index v = 0; v < X.rows(); ++v) Xv[static_cast<size_t>(v)] = X.row(v).transpose();
  std::vector<char> fixed(static_cast<size_t>(S->rows()), 0);
  for (int v : fv) fixed[static_cast<size_t>(v)] = 1;
  int reshaped = 0;

  const RowMat3d saved = *S;
  RowMat3d trial;
  double t = 0, dt = 0.125;
  int steps = 0, rejected = 0;
  std::vector<Eigen::Vector3d> cur = start;
  Eigen::MatrixXd K(k, k), D(k, 3), C;
  while (t < 1) {
    if (dt < 1.0 / 1024 && reshaped < 400) {
      // A face that flips however small the step is a sliver wider than the field's support
      // (left by the Steiner-vertex removal): reshape the faces around it against the mesh's
      // shapes (valid before and after, exact predicate), then go on.
      std::vector<int> bad;
      for (Eigen::Index f = 0; f < F.rows(); ++f)
        if (orient3d_origin(trial.row(F(f, 0)).data(), trial.row(F(f, 1)).data(), trial.row(F(f, 2)).data()) <= 0)
          bad.push_back(static_cast<int>(f));
      // One sliver at a time: together they are spread over the sphere (no one chart).
      bool ok = false;
      for (int f : bad)
        for (int rings : {1, 2, 4})
          if (untangle_patch({&faces, &vf}, Xv, fixed, {f}, rings, S)) {
            ok = true;
            break;
          }
      if (ok) {
        ++reshaped;
        dt = 1.0 / 64;
        continue;
      }
      // Otherwise a smoother field (wider support) moves the sliver nearly affinely.
      if (widened < 4) {
        ++widened;
        support *= 2;
        inv_h = 1 / support;
        dt = 1.0 / 64;
        continue;
      }
    }
    if (dt < 1.0 / 65536 || steps + rejected > 4000) {
      *S = saved;
      return Status(ErrorCode::SolverFailed, "feature warp: a face flips however small the step");
    }
    const double t1 = std::min(1.0, t + dt);
    for (int i = 0; i < k; ++i) {
      const Eigen::Vector3d next = t1 >= 1 ? q[static_cast<size_t>(i)] : slerp(start[static_cast<size_t>(i)], q[static_cast<size_t>(i)], t1);
      D.row(i) = (next - cur[static_cast<size_t>(i)]).transpose();
      for (int j = 0; j < k; ++j) K(i, j) = wendland((cur[static_cast<size_t>(i)] - cur[static_cast<size_t>(j)]).norm() * inv_h);
      K(i, i) += 1e-9;  // ridge: the features are snapped below, the field need not be exact there
    }
    C = K.ldlt().solve(D);
    if (!C.allFinite()) {
      *S = saved;
      return Status(ErrorCode::SolverFailed, "feature warp: the interpolation system is singular");
    }
    trial = *S;
    for (Eigen::Index v = 0; v < trial.rows(); ++v) {
      const Eigen::Vector3d x = S->row(v).transpose();
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      for (int j = 0; j < k; ++j) {
        const double r = (x - cur[static_cast<size_t>(j)]).norm() * inv_h;
        if (r < 1) d += wendland(r) * C.row(j).transpose();
      }
      // Outside every support nothing moves, to the bit (renormalizing could flip a sliver).
      if (d.squaredNorm() > 0) trial.row(v) = (x + d).normalized().transpose();
    }
    // Features land where the step sends them (exactly on target at the end).
    for (int i = 0; i < k; ++i) {
      const Eigen::Vector3d next = t1 >= 1 ? q[static_cast<size_t>(i)] : slerp(start[static_cast<size_t>(i)], q[static_cast<size_t>(i)], t1);
      trial.row(fv[static_cast<size_t>(i)]) = next.transpose();
    }
    if (any_flipped(F, trial)) {
      ++rejected;
      dt *= 0.5;
      continue;
    }
    S->swap(trial);
    for (int i = 0; i < k; ++i) cur[static_cast<size_t>(i)] = S->row(fv[static_cast<size_t>(i)]).transpose();
    t = t1;
    ++steps;
    dt = std::min(0.25, dt * 1.5);
    if (!report_progress(progress, "feature warp", steps, t)) {
      *S = saved;
      return Status(ErrorCode::Cancelled, "cancelled while moving the features onto their targets");
    }
  }
  if (stats) {
    stats->steps = steps;
    stats->rejected = rejected;
    stats->reshaped = reshaped;
  }
  return Status();
}

}  // namespace spherekit::detail
