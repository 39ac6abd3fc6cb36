// Internal helpers shared by the sphere locator and the remesh error: the closest point on a
// triangle (Ericson, Real-Time Collision Detection, 5.1.5) and the octahedral cell grid.
#pragma once

#include <Eigen/Core>

namespace spherekit::detail {

/// Closest point to `p` on triangle (a, b, c); `bary` receives its barycentrics (>= 0, sum 1).
/// Degenerate triangles are handled (the answer is a closest point on the segment/point).
inline Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                                 const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                                 Eigen::Vector3d& bary) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) {
    bary = {1, 0, 0};
    return a;
  }
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) {
    bary = {0, 1, 0};
    return b;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    bary = {1 - v, v, 0};
    return a + v * ab;
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) {
    bary = {0, 0, 1};
    return c;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    bary = {1 - w, 0, w};
    return a + w * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    bary = {0, 1 - w, w};
    return b + w * (c - b);
  }
  const double sum = va + vb + vc;
  if (!(sum > 0)) {  // degenerate (collinear) triangle that slipped through: nearest corner
    const double da = (p - a).squaredNorm(), db = (p - b).squaredNorm(), dc = (p - c).squaredNorm();
    if (da <= db && da <= dc) {
      bary = {1, 0, 0};
      return a;
    }
    if (db <= dc) {
      bary = {0, 1, 0};
      return b;
    }
    bary = {0, 0, 1};
    return c;
  }
  const double denom = 1.0 / sum;
  const double v = vb * denom, w = vc * denom;
  bary = {1 - v - w, v, w};
  return a + ab * v + ac * w;
}

/// Folds a cell (row, col) of a G x G grid over the octahedral domain that lies outside the
/// grid back inside (point reflection through the midpoint of the side it crossed).
inline void fold_cell(int& row, int& col, int G) {
  for (int guard = 0; guard < 8 && (row < 0 || row >= G || col < 0 || col >= G); ++guard) {
    if (row < 0) {
      row = -1 - row;
      col = G - 1 - col;
    } else if (row >= G) {
      row = 2 * G - 1 - row;
      col = G - 1 - col;
    } else if (col < 0) {
      col = -1 - col;
      row = G - 1 - row;
    } else {
      col = 2 * G - 1 - col;
      row = G - 1 - row;
    }
  }
  row = row < 0 ? 0 : (row >= G ? G - 1 : row);
  col = col < 0 ? 0 : (col >= G ? G - 1 : col);
}

}  // namespace spherekit::detail
