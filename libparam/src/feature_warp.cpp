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
#include <span>

#include <Eigen/Cholesky>

#include "detail/untangle_patch.h"
#include "spherekit/predicates.h"

namespace spherekit::detail {
namespace {

// A feature this close to its target stands still: the network's features are on their
// targets up to the rounding of normalizing them (1e-16), far below any mesh's resolution.
constexpr double kStillAngle = 1e-9;
// Slivers reshaped before the warp gives up. Every successful warp measured needed fewer
// than 80 (faust5k 000 and 013, 40-104 warped features: 49-76); one that needs more is
// stuck behind a feature it cannot pass, and another network (the caller's) resolves that
// faster than more reshaping: with 400, the failing warps of 128 landmarks took 3-12 s each
// and step 2 as a whole 95 s instead of 47 s.
constexpr int kMaxReshapes = 100;

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

SupportCells::SupportCells(const std::vector<Eigen::Vector3d>& centres, double support) {
  // Cells of about half the support (a cell's list then holds the centres within about 1.4
  // supports of its middle), at most 32 per axis; they tile [-1, 1] exactly. Each centre is
  // entered, in ascending order, into the cells its support reaches (two passes over the
  // same cells: counts, then entries).
  n_ = std::clamp(static_cast<int>(std::ceil(4.0 / support)), 1, 32);
  cell_ = 2.0 / n_;
  start_.assign(static_cast<size_t>(n_) * static_cast<size_t>(n_) * static_cast<size_t>(n_) + 1, 0);
  // A centre farther than the support from a cell's box contributes exactly zero to every
  // point of it (the kernel is 0 from r >= 1); the box is widened by kMargin, far above the
  // rounding of the cell index and of r, and covers a unit vector's coordinates rounded a
  // little past +-1 (clamped into the outermost cells).
  constexpr double kMargin = 1e-9;
  const double reach2 = support * support * (1 + 1e-6);
  auto for_each_cell = [&](const Eigen::Vector3d& c, auto&& emit) {
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::clamp(static_cast<int>(std::floor((c[a] - support + 1 - kMargin) / cell_)), 0, n_ - 1);
      hi[a] = std::clamp(static_cast<int>(std::floor((c[a] + support + 1 + kMargin) / cell_)), 0, n_ - 1);
    }
    for (int i = lo[0]; i <= hi[0]; ++i)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int k = lo[2]; k <= hi[2]; ++k) {
          const int idx[3] = {i, j, k};
          double d2 = 0;
          for (int a = 0; a < 3; ++a) {
            const double blo = -1 + idx[a] * cell_ - kMargin, bhi = -1 + (idx[a] + 1) * cell_ + kMargin;
            const double d = c[a] < blo ? blo - c[a] : c[a] > bhi ? c[a] - bhi : 0.0;
            d2 += d * d;
          }
          if (d2 < reach2) emit(key(idx));
        }
  };
  for (const auto& c : centres) for_each_cell(c, [&](size_t key) { ++start_[key + 1]; });
  for (size_t key = 0; key + 1 < start_.size(); ++key) start_[key + 1] += start_[key];
  entries_.resize(static_cast<size_t>(start_.back()));
  std::vector<int> fill(start_.begin(), start_.end() - 1);
  for (size_t j = 0; j < centres.size(); ++j)
    for_each_cell(centres[j], [&](size_t key) { entries_[static_cast<size_t>(fill[key]++)] = static_cast<int>(j); });
  all_.resize(centres.size());
  for (size_t j = 0; j < centres.size(); ++j) all_[j] = static_cast<int>(j);
}

size_t SupportCells::key(const int* idx) const {
  const size_t n = static_cast<size_t>(n_);
  return (static_cast<size_t>(idx[0]) * n + static_cast<size_t>(idx[1])) * n + static_cast<size_t>(idx[2]);
}

std::span<const int> SupportCells::near(const Eigen::Vector3d& x) const {
  int idx[3];
  for (int a = 0; a < 3; ++a) {
    // Unit vectors are within [-1, 1] up to rounding; anything else (never in a map) is
    // given every centre.
    if (!(std::abs(x[a]) <= 1 + 1e-12)) return all_;
    idx[a] = std::clamp(static_cast<int>(std::floor((x[a] + 1) / cell_)), 0, n_ - 1);
  }
  const size_t k = key(idx);
  return {entries_.data() + start_[k], entries_.data() + start_[k + 1]};
}

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

std::vector<int> passing_features(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to) {
  const int k = static_cast<int>(from.size());
  // Each feature's arc at 33 points: a pass shorter than 1/32 of the way can slip between
  // samples, which costs only another attempt (the warp's own culprits still name it).
  constexpr int kSamples = 32;
  std::vector<std::vector<Eigen::Vector3d>> path(static_cast<size_t>(k));
  std::vector<char> moving(static_cast<size_t>(k), 0);
  for (int i = 0; i < k; ++i) {
    const auto& a = from[static_cast<size_t>(i)];
    const auto& b = to[static_cast<size_t>(i)];
    moving[static_cast<size_t>(i)] = angle(a, b) > kStillAngle;
    for (int s = 0; s <= kSamples; ++s)
      path[static_cast<size_t>(i)].push_back(moving[static_cast<size_t>(i)] ? slerp(a, b, static_cast<double>(s) / kSamples)
                                                                             : a);
  }
  std::vector<char> passing(static_cast<size_t>(k), 0);
  for (int i = 0; i < k; ++i)
    for (int j = i + 1; j < k; ++j) {
      if (!moving[static_cast<size_t>(i)] && !moving[static_cast<size_t>(j)]) continue;
      const auto& a = path[static_cast<size_t>(i)];
      const auto& b = path[static_cast<size_t>(j)];
      const double ends = std::min(angle(a.front(), b.front()), angle(a.back(), b.back()));
      double closest = ends;
      for (size_t s = 1; s < kSamples; ++s) closest = std::min(closest, angle(a[s], b[s]));
      if (closest >= kPassingRatio * ends) continue;
      // The one that travels farther is the one passing by.
      const bool pick_i = !moving[static_cast<size_t>(j)] ||
                          (moving[static_cast<size_t>(i)] && angle(a.front(), a.back()) >= angle(b.front(), b.back()));
      passing[static_cast<size_t>(pick_i ? i : j)] = 1;
    }
  std::vector<int> out;
  for (int i = 0; i < k; ++i)
    if (passing[static_cast<size_t>(i)]) out.push_back(i);
  return out;
}

Status warp_features_to_targets(const RowMat3d& X, const RowMat3i& F, const std::vector<int>& fv,
                                const std::vector<Eigen::Vector3d>& targets, const ProgressFn& progress, RowMat3d* S,
                                WarpStats* stats, const WarpRelaxFn& relax) {
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
  int relaxed = 0;
  bool relax_failed = false;
  while (t < 1) {
    if (dt < 1.0 / 1024 && relax && !relax_failed && relaxed < kMaxRelaxes) {
      // The mesh between features has been squeezed below what a step can carry: let the
      // stretch optimizer spread it out (features fixed where they are now), then go on.
      ++relaxed;
      RowMat3d R = *S;
      const Status rs = relax(&R);
      if (rs.code() == ErrorCode::Cancelled) {
        *S = saved;
        return rs;
      }
      if (rs.ok() && !any_flipped(F, R)) {
        S->swap(R);
        dt = 1.0 / 64;
        continue;
      }
      relax_failed = true;  // it did not help; the remedies below get their turn
    }
    if (dt < 1.0 / 1024 && reshaped < kMaxReshapes) {
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
      if (stats) {
        // The features that could not get on: for each face that keeps flipping, the two
        // nearest features still on their way.
        stats->culprits.clear();
        for (Eigen::Index f = 0; f < F.rows(); ++f) {
          if (orient3d_origin(trial.row(F(f, 0)).data(), trial.row(F(f, 1)).data(), trial.row(F(f, 2)).data()) > 0)
            continue;
          const Eigen::Vector3d c = (S->row(F(f, 0)) + S->row(F(f, 1)) + S->row(F(f, 2))).transpose();
          std::vector<std::pair<double, int>> near;
          for (int j = 0; j < k; ++j)
            if (angle(cur[static_cast<size_t>(j)], q[static_cast<size_t>(j)]) > kStillAngle)
              near.push_back({angle(c, cur[static_cast<size_t>(j)]), j});
          std::sort(near.begin(), near.end());
          for (size_t m = 0; m < std::min<size_t>(2, near.size()); ++m) stats->culprits.push_back(near[m].second);
        }
        std::sort(stats->culprits.begin(), stats->culprits.end());
        stats->culprits.erase(std::unique(stats->culprits.begin(), stats->culprits.end()), stats->culprits.end());
        stats->relaxed = relaxed;
      }
      *S = saved;
      return Status(ErrorCode::SolverFailed, "feature warp: a face flips however small the step");
    }
    const double t1 = std::min(1.0, t + dt);
    SupportCells cells(cur, support);  // the features' supports at their current positions
    K.setZero();
    for (int i = 0; i < k; ++i) {
      const Eigen::Vector3d next = t1 >= 1 ? q[static_cast<size_t>(i)] : slerp(start[static_cast<size_t>(i)], q[static_cast<size_t>(i)], t1);
      D.row(i) = (next - cur[static_cast<size_t>(i)]).transpose();
      for (int j : cells.near(cur[static_cast<size_t>(i)]))
        K(i, j) = wendland((cur[static_cast<size_t>(i)] - cur[static_cast<size_t>(j)]).norm() * inv_h);
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
      for (int j : cells.near(x)) {
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
    stats->relaxed = relaxed;
  }
  return Status();
}

int leave_out_folded_samples(const RowMat3i& F, const RowMat3d& Sc, const std::vector<int>& spread,
                             std::vector<char>* inside) {
  std::vector<char> folded(static_cast<size_t>(Sc.rows()), 0), near(static_cast<size_t>(Sc.rows()), 0);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    if (orient3d_origin(Sc.row(F(f, 0)).data(), Sc.row(F(f, 1)).data(), Sc.row(F(f, 2)).data()) <= 0)
      for (int c = 0; c < 3; ++c) folded[static_cast<size_t>(F(f, c))] = 1;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const bool touches = folded[static_cast<size_t>(F(f, 0))] || folded[static_cast<size_t>(F(f, 1))] ||
                         folded[static_cast<size_t>(F(f, 2))];
    if (touches)
      for (int c = 0; c < 3; ++c) near[static_cast<size_t>(F(f, c))] = 1;
  }
  int marked = 0;
  for (int w : spread)
    if ((*inside)[static_cast<size_t>(w)] && near[static_cast<size_t>(w)]) {
      (*inside)[static_cast<size_t>(w)] = 0;
      ++marked;
    }
  return marked;
}

int snap_toward_targets(const RowMat3i& F, const RowMat3d& T, const std::vector<char>& movable, int sweeps,
                        RowMat3d* S) {
  const Eigen::Index nv = S->rows();
  std::vector<int> start(static_cast<size_t>(nv) + 1, 0), faces(static_cast<size_t>(3 * F.rows()));
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) ++start[static_cast<size_t>(F(f, c)) + 1];
  for (Eigen::Index v = 0; v < nv; ++v) start[static_cast<size_t>(v) + 1] += start[static_cast<size_t>(v)];
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) faces[static_cast<size_t>(fill[static_cast<size_t>(F(f, c))]++)] = static_cast<int>(f);
  // Half the signed volume: a face may shrink to half its size in one move (per sweep; the
  // floor from the start of the sweeps instead lost 2-10% of the gain on the shared families).
  constexpr double kKeep = 0.5;
  int moves = 0;
  for (int sweep = 0; sweep < sweeps; ++sweep)
    for (Eigen::Index v = 0; v < nv; ++v) {
      if (!movable[static_cast<size_t>(v)]) continue;
      const Eigen::Vector3d a = S->row(v).transpose(), b = T.row(v).transpose();
      if (a == b) continue;
      for (double t : {1.0, 0.5, 0.25, 0.125}) {
        Eigen::Vector3d c = (1 - t) * a + t * b;
        if (!(c.norm() > 0)) continue;
        c.normalize();
        bool ok = true;
        for (int k = start[static_cast<size_t>(v)]; k < start[static_cast<size_t>(v) + 1] && ok; ++k) {
          const int f = faces[static_cast<size_t>(k)];
          Eigen::Vector3d was[3], now[3];
          for (int i = 0; i < 3; ++i) {
            was[i] = S->row(F(f, i)).transpose();
            now[i] = F(f, i) == v ? c : was[i];
          }
          ok = orient3d_origin(now[0], now[1], now[2]) > 0 &&
               now[0].dot(now[1].cross(now[2])) >= kKeep * was[0].dot(was[1].cross(was[2]));
        }
        if (ok) {
          S->row(v) = c.transpose();
          ++moves;
          break;
        }
      }
    }
  return moves;
}

}  // namespace spherekit::detail
