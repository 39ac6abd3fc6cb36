// Error-free transformations and floating-point expansions: the fast exact tier of the
// orientation predicates (predicates.cpp). Internal header, never installed.
//
// Literature:
//   J. R. Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric
//     Predicates", Discrete & Computational Geometry 18(3), 1997: expansions, Grow-Expansion,
//     zero elimination, "the sign of a nonoverlapping expansion is the sign of its largest term".
//   D. E. Knuth, TAOCP vol. 2, 4.2.2: the branch-free TwoSum.
//   S. Boldo, J.-M. Muller, "Exact and Approximated Error of the FMA", IEEE TC 60(2), 2011:
//     a*b - fl(a*b) is a double (so one FMA returns it exactly) unless it underflows.
//
// Preconditions are the caller's: round-to-nearest-even, no -ffast-math, and operands in the
// range where no product underflows or overflows (predicates.cpp checks this per call).
#pragma once

#include <cmath>

#if defined(__FAST_MATH__)
#error "spherekit predicates need IEEE semantics: do not compile with -ffast-math"
#endif

namespace spherekit::detail {

/// s + e == a + b exactly with s = fl(a + b) (Knuth). No precondition on |a| vs |b|.
inline void two_sum(double a, double b, double& s, double& e) {
  const double sum = a + b;
  const double b_virtual = sum - a;
  const double a_virtual = sum - b_virtual;
  e = (a - a_virtual) + (b - b_virtual);
  s = sum;
}

/// p + e == a * b exactly with p = fl(a * b): the FMA computes a*b - p with one rounding, and
/// that difference is representable when its low bits do not underflow (Boldo & Muller).
inline void two_product(double a, double b, double& p, double& e) {
  const double prod = a * b;
  e = std::fma(a, b, -prod);
  p = prod;
}

/// A nonoverlapping floating-point expansion: the exact value is the sum of its components,
/// which are nonzero and sorted by increasing magnitude. Fixed capacity `N`: each add()
/// lengthens it by at most one component, so N >= number of add() calls is enough.
template <int N>
class Expansion {
 public:
  /// Adds one double exactly: Shewchuk's Grow-Expansion with zero elimination. The running
  /// sum q sweeps up from the smallest component; every rounding error h is kept in place.
  void add(double b) {
    double q = b;
    int out = 0;
    for (int i = 0; i < size_; ++i) {
      double h;
      two_sum(q, c_[i], q, h);
      if (h != 0.0) c_[out++] = h;  // out <= i: in-place compaction is safe
    }
    if (q != 0.0 && out < N) c_[out++] = q;
    size_ = out;
  }

  /// Adds sign * x * y * z exactly, as the four components of two nested TwoProducts:
  /// x*y = h + l, then h*z = h1 + l1 and l*z = h2 + l2.
  void add_triple_product(double x, double y, double z, bool negate) {
    double h, l, h1, l1, h2, l2;
    two_product(x, y, h, l);
    two_product(h, z, h1, l1);
    two_product(l, z, h2, l2);
    if (negate) {
      h1 = -h1; l1 = -l1; h2 = -h2; l2 = -l2;
    }
    add(l2);
    add(l1);
    add(h2);
    add(h1);
  }

  /// Sign of the exact sum: the sign of the largest component, since all the smaller
  /// (nonoverlapping) components together are smaller than its lowest nonzero bit.
  int sign() const { return size_ == 0 ? 0 : (c_[size_ - 1] > 0.0 ? 1 : -1); }
  int size() const { return size_; }

 private:
  double c_[N];
  int size_ = 0;
};

}  // namespace spherekit::detail
