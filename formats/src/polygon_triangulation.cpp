// Quad splits and ear clipping in the best-fit plane (see polygon_triangulation.h for why;
// ear clipping: Meisters, "Polygons have ears", Amer. Math. Monthly 82, 1975; Newell's normal:
// Sutherland, Sproull, Schumacker, "A characterization of ten hidden-surface algorithms", 1974).
#include "spherekit/formats/polygon_triangulation.h"

#include <algorithm>
#include <cmath>

namespace spherekit::formats {
namespace {

using Tri = std::array<std::uint32_t, 3>;

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

/// Whether a b c turn left by more than rounding: the projection into the plane rounds, so a
/// corner placed exactly on an edge in 3D (a T-junction vertex, common in DCC exports) may come
/// out a hair convex and be cut as a zero-area ear. 1e-12 of |ab| |bc| is far above double
/// rounding of the projection and far below any angle a modelled corner has.
bool left_turn(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return cross2(a, b, c) > 1e-12 * (b - a).norm() * (c - b).norm();
}

/// 2 area / (product of the two longest edges) = the sine of the smallest angle (the smallest
/// angle is at most 60 degrees and every obtuse angle's sine exceeds it): 0 for slivers,
/// sqrt(3)/2 for an equilateral triangle.
double min_angle_sine(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  std::array<double, 3> len{(b - a).norm(), (c - b).norm(), (a - c).norm()};
  std::sort(len.begin(), len.end());
  const double denom = len[1] * len[2];
  return denom > 0 ? cross2(a, b, c) / denom : 0.0;
}

/// Whether p lies inside or on (up to rounding, as in left_turn) triangle abc (counter-clockwise).
bool in_triangle(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                 const Eigen::Vector2d& c) {
  return !left_turn(b, a, p) && !left_turn(c, b, p) && !left_turn(a, c, p);
}

class EarClipper {
 public:
  EarClipper(std::vector<Eigen::Vector2d> q, std::vector<Tri>& out) : q_(std::move(q)), out_(out) {
    const auto n = static_cast<std::uint32_t>(q_.size());
    prev_.resize(n);
    next_.resize(n);
    alive_.assign(n, 1);
    for (std::uint32_t i = 0; i < n; ++i) {
      prev_[i] = (i + n - 1) % n;
      next_[i] = (i + 1) % n;
    }
    convex_.resize(n);
    listed_.assign(n, 0);
    for (std::uint32_t i = 0; i < n; ++i) update_convexity(i);
  }

  void run() {
    auto remaining = static_cast<std::uint32_t>(q_.size());
    const bool choose_best = q_.size() <= kBestEarCorners;
    std::uint32_t cursor = 0;
    while (remaining > 3) {
      std::uint32_t ear = choose_best ? best_ear(cursor) : first_ear(cursor);
      if (ear == kNone) ear = most_convex(cursor);
      out_.push_back({prev_[ear], ear, next_[ear]});
      const std::uint32_t p = prev_[ear], nx = next_[ear];
      next_[p] = nx;
      prev_[nx] = p;
      alive_[ear] = 0;
      --remaining;
      update_convexity(p);
      update_convexity(nx);
      cursor = nx;
    }
    out_.push_back({prev_[cursor], cursor, next_[cursor]});
  }

 private:
  static constexpr std::uint32_t kNone = 0xffffffffu;

  void update_convexity(std::uint32_t i) {
    convex_[i] = left_turn(q_[prev_[i]], q_[i], q_[next_[i]]);
    // Corners that are not strictly convex are the only ones that can lie inside an ear of a
    // simple polygon. Clipping only makes corners more convex, so the list only shrinks
    // (pruned in is_ear); a corner is listed at most once.
    if (!convex_[i] && !listed_[i]) {
      listed_[i] = 1;
      blockers_.push_back(i);
    }
  }

  bool is_ear(std::uint32_t i) {
    if (!convex_[i]) return false;
    const std::uint32_t a = prev_[i], c = next_[i];
    std::size_t keep = 0;
    bool ear = true;
    for (const std::uint32_t r : blockers_) {
      if (!alive_[r] || convex_[r]) {
        listed_[r] = 0;
        continue;
      }
      blockers_[keep++] = r;
      if (!ear || r == a || r == i || r == c) continue;
      const Eigen::Vector2d& p = q_[r];
      // A corner at the same place as one of the ear's (a polygon touching itself) does not
      // block it: the ear's triangle does not cover it.
      if (p == q_[a] || p == q_[i] || p == q_[c]) continue;
      if (in_triangle(p, q_[a], q_[i], q_[c])) ear = false;
    }
    blockers_.resize(keep);
    return ear;
  }

  std::uint32_t best_ear(std::uint32_t start) {
    std::uint32_t best = kNone;
    double best_quality = -1;
    std::uint32_t i = start;
    do {
      if (is_ear(i)) {
        const double quality = min_angle_sine(q_[prev_[i]], q_[i], q_[next_[i]]);
        if (quality > best_quality) {
          best_quality = quality;
          best = i;
        }
      }
      i = next_[i];
    } while (i != start);
    return best;
  }

  std::uint32_t first_ear(std::uint32_t start) {
    std::uint32_t i = start;
    do {
      if (is_ear(i)) return i;
      i = next_[i];
    } while (i != start);
    return kNone;
  }

  /// No ear (a self-intersecting or degenerate polygon): the corner whose angle is most
  /// convex, by the sine of its triangle's smallest angle (the first one if all are flat).
  std::uint32_t most_convex(std::uint32_t start) {
    std::uint32_t best = start;
    double best_value = -2;
    std::uint32_t i = start;
    do {
      const double v = min_angle_sine(q_[prev_[i]], q_[i], q_[next_[i]]);
      if (v > best_value) {
        best_value = v;
        best = i;
      }
      i = next_[i];
    } while (i != start);
    return best;
  }

  std::vector<Eigen::Vector2d> q_;
  std::vector<Tri>& out_;
  std::vector<std::uint32_t> prev_, next_;
  std::vector<char> alive_, convex_, listed_;
  std::vector<std::uint32_t> blockers_;
};

}  // namespace

void triangulate_polygon(const std::vector<Eigen::Vector3d>& points, std::vector<Tri>& triangles) {
  const std::size_t n = points.size();
  if (n < 3) return;
  if (n == 3) {
    triangles.push_back({0, 1, 2});
    return;
  }
  // Newell's normal about the centroid (subtracting it keeps far-from-origin polygons precise).
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) centroid += p;
  centroid /= static_cast<double>(n);
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) normal += (points[i] - centroid).cross(points[(i + 1) % n] - centroid);
  // A basis (u, v) of the plane with u x v along the normal, so the polygon runs
  // counter-clockwise in it. A zero normal (all corners on a line) leaves every corner flat.
  Eigen::Vector3d u, v;
  if (normal.squaredNorm() > 0) {
    normal.normalize();
    Eigen::Index axis = 0;  // the coordinate axis least parallel to the normal
    normal.cwiseAbs().minCoeff(&axis);
    u = normal.cross(Eigen::Vector3d::Unit(axis)).normalized();
    v = normal.cross(u);
  } else {
    u = Eigen::Vector3d::UnitX();
    v = Eigen::Vector3d::UnitY();
  }
  std::vector<Eigen::Vector2d> q(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d d = points[i] - centroid;
    q[i] = Eigen::Vector2d(d.dot(u), d.dot(v));
  }

  if (n == 4) {
    // Diagonal 0-2 gives (0,1,2) (0,2,3); diagonal 1-3 gives (0,1,3) (1,2,3).
    const bool a_ok = left_turn(q[0], q[1], q[2]) && left_turn(q[0], q[2], q[3]);
    const bool b_ok = left_turn(q[0], q[1], q[3]) && left_turn(q[1], q[2], q[3]);
    const bool a_shorter = (points[2] - points[0]).squaredNorm() <= (points[3] - points[1]).squaredNorm();
    const bool use_a = a_ok != b_ok ? a_ok : a_shorter;
    if (use_a) {
      triangles.push_back({0, 1, 2});
      triangles.push_back({0, 2, 3});
    } else {
      triangles.push_back({0, 1, 3});
      triangles.push_back({1, 2, 3});
    }
    return;
  }
  EarClipper(std::move(q), triangles).run();
}

}  // namespace spherekit::formats
