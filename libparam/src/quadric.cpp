// n-D quadric error metric: Garland & Heckbert 1998 (§4, "generalized" quadrics).
// For a triangle p0,p1,p2 in R^d with orthonormal in-plane basis e1, e2:
//   A = I - e1 e1^T - e2 e2^T,  b = (p0.e1) e1 + (p0.e2) e2 - p0,
//   c = p0.p0 - (p0.e1)^2 - (p0.e2)^2,
// so Q(x) is the squared distance from x to the triangle's 2-plane.
#include "detail/quadric.h"

#include <cmath>

namespace spherekit::detail {

void QuadricND::add_triangle(const double* p0, const double* p1, const double* p2, double weight, int begin,
                             int end) {
  const int d = end - begin;
  p0 += begin, p1 += begin, p2 += begin;
  std::vector<double> e1(static_cast<size_t>(d)), e2(static_cast<size_t>(d));
  double l1 = 0;
  for (int i = 0; i < d; ++i) {
    e1[i] = p1[i] - p0[i];
    l1 += e1[i] * e1[i];
  }
  l1 = std::sqrt(l1);
  if (!(l1 > 0)) return;
  for (int i = 0; i < d; ++i) e1[i] /= l1;
  double proj = 0;
  for (int i = 0; i < d; ++i) proj += (p2[i] - p0[i]) * e1[i];
  double l2 = 0;
  for (int i = 0; i < d; ++i) {
    e2[i] = p2[i] - p0[i] - proj * e1[i];
    l2 += e2[i] * e2[i];
  }
  l2 = std::sqrt(l2);
  // A triangle whose height is negligible against its base spans no 2-plane; skip it
  // (its area, hence its weight, is ~0 anyway). Relative test: scale-free.
  if (!(l2 > 1e-12 * l1)) return;
  for (int i = 0; i < d; ++i) e2[i] /= l2;
  double pe1 = 0, pe2 = 0, pp = 0;
  for (int i = 0; i < d; ++i) {
    pe1 += p0[i] * e1[i];
    pe2 += p0[i] * e2[i];
    pp += p0[i] * p0[i];
  }
  // Packed upper triangle, row-major: row r starts at r d_ - r (r - 1) / 2 = r (2 d_ - r + 1) / 2.
  for (int i = 0; i < d; ++i) {
    const int r = begin + i;
    size_t k = static_cast<size_t>(r) * static_cast<size_t>(2 * d_ - r + 1) / 2;
    for (int j = i; j < d; ++j, ++k)
      a_[k] += weight * ((i == j ? 1.0 : 0.0) - e1[i] * e1[j] - e2[i] * e2[j]);
  }
  for (int i = 0; i < d; ++i) b_[static_cast<size_t>(begin + i)] += weight * (pe1 * e1[i] + pe2 * e2[i] - p0[i]);
  c_ += weight * (pp - pe1 * pe1 - pe2 * pe2);
}

void QuadricND::add(const QuadricND& o) {
  for (size_t k = 0; k < a_.size(); ++k) a_[k] += o.a_[k];
  for (size_t k = 0; k < b_.size(); ++k) b_[k] += o.b_[k];
  c_ += o.c_;
}

double QuadricND::evaluate(const double* x) const {
  const int d = d_;
  double q = c_;
  size_t k = 0;
  for (int i = 0; i < d; ++i) {
    q += a_[k++] * x[i] * x[i];
    double s = 0;
    for (int j = i + 1; j < d; ++j) s += a_[k++] * x[j];
    q += 2.0 * x[i] * s + 2.0 * b_[i] * x[i];
  }
  // Rounding can make a true 0 slightly negative; the metric is a squared distance.
  return q > 0 ? q : 0.0;
}

}  // namespace spherekit::detail
