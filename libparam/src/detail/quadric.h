// Quadric error metric in any dimension d (Garland & Heckbert 1998, "Simplifying surfaces
// with color and texture using quadric error metrics", the n-D form). For d = 3 this is the
// classic QEM; for d = 3n (the consistent method's step 5, Asirvatham et al. 2005 §3) each
// vertex carries the concatenated positions of n models and the quadric measures the squared
// distance to a face's 2-plane in R^{3n}. That also penalizes inconsistent tangential sliding
// between the models, which a sum of n independent 3D quadrics would not (ALGORITHM.md §4.5).
#pragma once

#include <cstddef>
#include <vector>

namespace spherekit::detail {

/// Q(x) = x^T A x + 2 b^T x + c with symmetric A stored packed (upper triangle, row-major).
class QuadricND {
 public:
  QuadricND() = default;
  explicit QuadricND(int d) : d_(d), a_(static_cast<std::size_t>(d * (d + 1) / 2), 0.0), b_(static_cast<std::size_t>(d), 0.0) {}

  int dim() const { return d_; }

  /// Quadric of the 2-plane through triangle (p0, p1, p2) in R^d, weighted by `weight`.
  /// A degenerate triangle (zero area) adds nothing.
  void add_triangle(const double* p0, const double* p1, const double* p2, double weight) {
    add_triangle(p0, p1, p2, weight, 0, d_);
  }
  /// The same for the coordinates [begin, end) alone (one model's block of a point in
  /// R^3n): the squared distance of x's block to the triangle's plane in that block.
  void add_triangle(const double* p0, const double* p1, const double* p2, double weight, int begin, int end);

  /// this += other
  void add(const QuadricND& other);

  /// Q(x)
  double evaluate(const double* x) const;

 private:
  int d_ = 0;
  std::vector<double> a_;
  std::vector<double> b_;
  double c_ = 0;
};

}  // namespace spherekit::detail
