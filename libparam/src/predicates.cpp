// Exact orientation predicates: the only place where SphereKit decides whether a spherical
// triangle is flipped or degenerate (DESIGN.md 3.9: validity is never a float threshold).
//
// Literature:
//   J. R. Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric
//     Predicates", DCG 18(3), 1997 (filtered evaluation, expansions).
//   N. J. Higham, "Accuracy and Stability of Numerical Algorithms", 2nd ed., ch. 2-3 (the
//     standard model fl(x op y) = (x op y)(1 + d), |d| <= u = 2^-53, used for the bounds).
//   S. Boldo, J.-M. Muller, IEEE TC 60(2), 2011 (when an FMA gives the exact product error).
//
// Design: three tiers, all written here (no GMP, no CGAL).
//   1. Filter: the determinant in double plus a forward error bound proportional to its
//      permanent. Decides almost every call in ~20 flops.
//   2. Expansions (detail/predicates_expansion.h): the determinant as a sum of signed triple
//      products of *input coordinates*, each split exactly into four doubles by TwoProduct
//      (FMA), summed exactly by Grow-Expansion. No differences are formed, so orient3d needs no
//      TwoDiff: det[b-a, c-a, d-a] = [b,c,d] - [a,c,d] + [a,b,d] - [a,b,c] (multilinearity;
//      terms with a twice vanish), i.e. 24 triple products instead of 6.
//   3. Big integers (detail/predicates_bigint.h): the same 6 or 24 triple products as exact
//      integers; needed only when an operand lies outside the "safe range" below.
//
// Safe range: every coordinate is 0 or has magnitude in [2^-280, 2^281). Such numbers and their
// differences are integer multiples of 2^-332 (the ulp of 2^-280), hence every product of two or
// three of them is 0 or at least 2^-664 resp. 2^-996 in magnitude: normal, never underflowing,
// so the standard model holds in tier 1 without absolute error terms. In tier 2 every
// TwoProduct error term is the low half of an exact (<= 106-bit) product whose lowest bit is at
// least 2^-996, so it is a double, above the subnormal grain 2^-1074 (Boldo & Muller's
// condition); magnitudes stay below 96 * 2^846, far from overflow.
// Non-finite inputs fail the range test too and give 0: the predicates never abort.
#include "spherekit/predicates.h"

#include <bit>
#include <cmath>
#include <cstdint>

#include "detail/predicates_bigint.h"
#include "detail/predicates_expansion.h"

namespace spherekit {
namespace {

constexpr double kU = 0x1p-53;  // unit roundoff of binary64, round to nearest

// Filter constant for a . (b x c) with inputs used as given. Per term
// a_i * (b_j c_k - b_k c_j): two products, one difference, one product give an error of at most
// (3u + 3u^2 + u^3) |a_i| (|b_j c_k| + |b_k c_j|); the two additions of the three terms add
// 2u(1 + u) times their magnitudes. Altogether <= (5u + 12u^2) * permanent. The permanent is
// itself computed in floating point (at most 6 roundings, a relative (1 - u)^6 loss) and so is
// the product with the constant; 6u covers all of that with a wide margin (6u(1 - 7u) > 5u + 12u^2).
constexpr double kOriginErrBound = 6.0 * kU;

// Filter constant for det[b-a, c-a, d-a]. The three computed differences carry a relative
// error u each, so the exact determinant of the computed differences differs from the true
// one by at most ((1+u)^3 - 1) / (1-u)^3 * permanent ~ 3u * permanent; evaluating that
// determinant adds the 5u + O(u^2) above: 8u + O(u^2) in total, rounded up to 9u for the
// second-order terms and the floating-point permanent.
constexpr double kOrient3dErrBound = 9.0 * kU;

/// True when x is 0 or 2^-280 <= |x| < 2^281 (see "safe range" above); false for NaN/Inf.
inline bool in_safe_range(double x) {
  const std::uint64_t biased = (std::bit_cast<std::uint64_t>(x) >> 52) & 0x7ffu;
  return x == 0.0 || biased - (1023u - 280u) <= 560u;
}

inline bool in_safe_range3(const double* p) {
  return in_safe_range(p[0]) && in_safe_range(p[1]) && in_safe_range(p[2]);
}

inline bool all_finite3(const double* p) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

/// Adds the six signed triple products of a . (b x c) (negated if `negate`) to `acc`, which
/// is an Expansion or a TripleProductSum.
template <class Acc>
void add_det3(Acc& acc, const double* a, const double* b, const double* c, bool negate) {
  acc.add_triple_product(a[0], b[1], c[2], negate);
  acc.add_triple_product(a[0], b[2], c[1], !negate);
  acc.add_triple_product(a[1], b[2], c[0], negate);
  acc.add_triple_product(a[1], b[0], c[2], !negate);
  acc.add_triple_product(a[2], b[0], c[1], negate);
  acc.add_triple_product(a[2], b[1], c[0], !negate);
}

/// Sign of a . (b x c) exactly (tiers 2-3), for finite inputs.
int orient3d_origin_exact(const double* a, const double* b, const double* c) {
  if (in_safe_range3(a) && in_safe_range3(b) && in_safe_range3(c)) {
    detail::Expansion<24> e;  // 6 triple products x 4 components
    add_det3(e, a, b, c, false);
    return e.sign();
  }
  detail::TripleProductSum s;
  add_det3(s, a, b, c, false);
  return s.sign();
}

/// Sign of det[b-a, c-a, d-a] exactly (tiers 2-3), for finite inputs, through
/// [b,c,d] - [a,c,d] + [a,b,d] - [a,b,c].
int orient3d_exact(const double* a, const double* b, const double* c, const double* d) {
  if (in_safe_range3(a) && in_safe_range3(b) && in_safe_range3(c) && in_safe_range3(d)) {
    // Shortcut: nearby points (the usual near-degenerate case) often have exactly
    // representable differences (Sterbenz: y/2 <= x <= 2y). TwoSum's error term says whether
    // each one is; if all are and stay in the safe range, the 6-term determinant of the
    // differences is the exact answer at a quarter of the cost.
    double diff[3][3];
    bool exact_diffs = true;
    const double* rows[3] = {b, c, d};
    for (int r = 0; r < 3 && exact_diffs; ++r)
      for (int k = 0; k < 3; ++k) {
        double err;
        detail::two_sum(rows[r][k], -a[k], diff[r][k], err);
        exact_diffs = exact_diffs && err == 0.0 && in_safe_range(diff[r][k]);
      }
    if (exact_diffs) return orient3d_origin_exact(diff[0], diff[1], diff[2]);
    detail::Expansion<96> e;  // 24 triple products x 4 components
    add_det3(e, b, c, d, false);
    add_det3(e, a, c, d, true);
    add_det3(e, a, b, d, false);
    add_det3(e, a, b, c, true);
    return e.sign();
  }
  detail::TripleProductSum s;
  add_det3(s, b, c, d, false);
  add_det3(s, a, c, d, true);
  add_det3(s, a, b, d, false);
  add_det3(s, a, b, c, true);
  return s.sign();
}

}  // namespace

int orient3d_origin(const double* a, const double* b, const double* c) {
  if (in_safe_range3(a) && in_safe_range3(b) && in_safe_range3(c)) {
    const double p12 = b[1] * c[2], p21 = b[2] * c[1];
    const double p20 = b[2] * c[0], p02 = b[0] * c[2];
    const double p01 = b[0] * c[1], p10 = b[1] * c[0];
    const double det = a[0] * (p12 - p21) + a[1] * (p20 - p02) + a[2] * (p01 - p10);
    const double permanent = std::fabs(a[0]) * (std::fabs(p12) + std::fabs(p21)) +
                             std::fabs(a[1]) * (std::fabs(p20) + std::fabs(p02)) +
                             std::fabs(a[2]) * (std::fabs(p01) + std::fabs(p10));
    const double bound = kOriginErrBound * permanent;
    if (det > bound) return 1;
    if (-det > bound) return -1;
    // In the safe range nothing underflows, so a zero permanent means every product is
    // exactly zero and so is the determinant.
    if (permanent == 0.0) return 0;
    return orient3d_origin_exact(a, b, c);
  }
  if (!all_finite3(a) || !all_finite3(b) || !all_finite3(c)) return 0;
  return orient3d_origin_exact(a, b, c);
}

int orient3d(const double* a, const double* b, const double* c, const double* d) {
  if (in_safe_range3(a) && in_safe_range3(b) && in_safe_range3(c) && in_safe_range3(d)) {
    const double bx = b[0] - a[0], by = b[1] - a[1], bz = b[2] - a[2];
    const double cx = c[0] - a[0], cy = c[1] - a[1], cz = c[2] - a[2];
    const double dx = d[0] - a[0], dy = d[1] - a[1], dz = d[2] - a[2];
    const double p12 = cy * dz, p21 = cz * dy;
    const double p20 = cz * dx, p02 = cx * dz;
    const double p01 = cx * dy, p10 = cy * dx;
    const double det = bx * (p12 - p21) + by * (p20 - p02) + bz * (p01 - p10);
    const double permanent = std::fabs(bx) * (std::fabs(p12) + std::fabs(p21)) +
                             std::fabs(by) * (std::fabs(p20) + std::fabs(p02)) +
                             std::fabs(bz) * (std::fabs(p01) + std::fabs(p10));
    const double bound = kOrient3dErrBound * permanent;
    if (det > bound) return 1;
    if (-det > bound) return -1;
    // Differences of safe-range numbers are exact zeros only for equal inputs and never
    // underflow, so a zero permanent means an exactly zero determinant.
    if (permanent == 0.0) return 0;
    return orient3d_exact(a, b, c, d);
  }
  if (!all_finite3(a) || !all_finite3(b) || !all_finite3(c) || !all_finite3(d)) return 0;
  return orient3d_exact(a, b, c, d);
}

}  // namespace spherekit
