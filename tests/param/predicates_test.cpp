// Tests of the exact orientation predicates (predicates.cpp) against slow oracles written here
// with different arithmetic: arbitrary-size integers in base 2^32 built from the IEEE bit
// patterns (any finite double), and __int128 on inputs with few mantissa bits.
//
// The library has three tiers (float filter, floating-point expansions, fixed-width big
// integers); inputs whose coordinates are 0 or within [2^-280, 2^281) take tiers 1-2, the
// others tier 3. Scaling tests below move the same problem across that boundary.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "spherekit/predicates.h"
#include "test_meshes.h"

namespace {

using spherekit::orient3d;
using spherekit::orient3d_origin;
using P3 = std::array<double, 3>;

// ---------------------------------------------------------------------------------------------
// Oracle 1: signed big integers, magnitude in base 2^32 (little endian, no leading zero words).
class BigInt {
 public:
  /// x * 2^-emin as an integer; emin must not exceed the exponent of x's last mantissa bit.
  static BigInt scaled(double x, int emin) {
    BigInt r;
    const std::uint64_t bits = std::bit_cast<std::uint64_t>(x);
    const int biased = static_cast<int>((bits >> 52) & 0x7ff);
    std::uint64_t m = bits & ((std::uint64_t{1} << 52) - 1);
    if (biased != 0) m |= std::uint64_t{1} << 52;
    if (m == 0) return r;
    const int e = (biased == 0 ? 1 : biased) - 1075;  // x = m * 2^e
    const int shift = e - emin;
    REQUIRE(shift >= 0);
    r.neg_ = (bits >> 63) != 0;
    r.mag_.assign(static_cast<size_t>(shift / 32) + 3, 0);
    const int ws = shift / 32, bs = shift % 32;
    const unsigned __int128 v = static_cast<unsigned __int128>(m) << bs;  // < 2^85
    r.mag_[static_cast<size_t>(ws)] = static_cast<std::uint32_t>(v);
    r.mag_[static_cast<size_t>(ws) + 1] = static_cast<std::uint32_t>(v >> 32);
    r.mag_[static_cast<size_t>(ws) + 2] = static_cast<std::uint32_t>(v >> 64);
    r.trim();
    return r;
  }
  /// Exponent of the last mantissa bit of x (x = m * 2^e with m < 2^53): the scaling base.
  static int low_exponent(double x) {
    const int biased = static_cast<int>((std::bit_cast<std::uint64_t>(x) >> 52) & 0x7ff);
    return (biased == 0 ? 1 : biased) - 1075;
  }

  int sign() const { return mag_.empty() ? 0 : (neg_ ? -1 : 1); }
  BigInt operator-() const {
    BigInt r = *this;
    if (!r.mag_.empty()) r.neg_ = !r.neg_;
    return r;
  }
  friend BigInt operator+(const BigInt& a, const BigInt& b) {
    BigInt r;
    if (a.neg_ == b.neg_) {
      r.mag_ = add_mag(a.mag_, b.mag_);
      r.neg_ = a.neg_;
    } else if (cmp_mag(a.mag_, b.mag_) >= 0) {
      r.mag_ = sub_mag(a.mag_, b.mag_);
      r.neg_ = a.neg_;
    } else {
      r.mag_ = sub_mag(b.mag_, a.mag_);
      r.neg_ = b.neg_;
    }
    r.trim();
    return r;
  }
  friend BigInt operator-(const BigInt& a, const BigInt& b) { return a + (-b); }
  friend BigInt operator*(const BigInt& a, const BigInt& b) {
    BigInt r;
    if (a.mag_.empty() || b.mag_.empty()) return r;
    r.mag_.assign(a.mag_.size() + b.mag_.size(), 0);
    for (size_t i = 0; i < a.mag_.size(); ++i) {
      std::uint64_t carry = 0;
      for (size_t j = 0; j < b.mag_.size(); ++j) {
        const std::uint64_t t = std::uint64_t{a.mag_[i]} * b.mag_[j] + r.mag_[i + j] + carry;
        r.mag_[i + j] = static_cast<std::uint32_t>(t);
        carry = t >> 32;
      }
      r.mag_[i + b.mag_.size()] = static_cast<std::uint32_t>(carry);
    }
    r.neg_ = a.neg_ != b.neg_;
    r.trim();
    return r;
  }

 private:
  using Mag = std::vector<std::uint32_t>;
  void trim() {
    while (!mag_.empty() && mag_.back() == 0) mag_.pop_back();
    if (mag_.empty()) neg_ = false;
  }
  static int cmp_mag(const Mag& a, const Mag& b) {
    if (a.size() != b.size()) return a.size() < b.size() ? -1 : 1;
    for (size_t i = a.size(); i-- > 0;)
      if (a[i] != b[i]) return a[i] < b[i] ? -1 : 1;
    return 0;
  }
  static Mag add_mag(const Mag& a, const Mag& b) {
    Mag r(std::max(a.size(), b.size()) + 1, 0);
    std::uint64_t carry = 0;
    for (size_t i = 0; i < r.size(); ++i) {
      const std::uint64_t t = carry + (i < a.size() ? a[i] : 0u) + (i < b.size() ? b[i] : 0u);
      r[i] = static_cast<std::uint32_t>(t);
      carry = t >> 32;
    }
    return r;
  }
  static Mag sub_mag(const Mag& a, const Mag& b) {  // |a| >= |b|
    Mag r(a.size(), 0);
    std::int64_t borrow = 0;
    for (size_t i = 0; i < a.size(); ++i) {
      std::int64_t t = std::int64_t{a[i]} - (i < b.size() ? std::int64_t{b[i]} : 0) - borrow;
      borrow = t < 0 ? 1 : 0;
      if (t < 0) t += std::int64_t{1} << 32;
      r[i] = static_cast<std::uint32_t>(t);
    }
    return r;
  }

  bool neg_ = false;
  Mag mag_;
};

/// Common scaling exponent: the smallest last-bit exponent among the nonzero inputs.
int common_low_exponent(std::initializer_list<const P3*> pts) {
  int emin = std::numeric_limits<int>::max();
  for (const P3* p : pts)
    for (double x : *p)
      if (x != 0.0) emin = std::min(emin, BigInt::low_exponent(x));
  return emin == std::numeric_limits<int>::max() ? 0 : emin;
}

/// det of rows x, y, z by cofactor expansion along x.
BigInt det3(const std::array<BigInt, 3>& x, const std::array<BigInt, 3>& y, const std::array<BigInt, 3>& z) {
  return x[0] * (y[1] * z[2] - y[2] * z[1]) - x[1] * (y[0] * z[2] - y[2] * z[0]) + x[2] * (y[0] * z[1] - y[1] * z[0]);
}

std::array<BigInt, 3> big3(const P3& p, int emin) {
  return {BigInt::scaled(p[0], emin), BigInt::scaled(p[1], emin), BigInt::scaled(p[2], emin)};
}

int oracle_origin(const P3& a, const P3& b, const P3& c) {
  const int emin = common_low_exponent({&a, &b, &c});
  return det3(big3(a, emin), big3(b, emin), big3(c, emin)).sign();
}

/// det[b-a, c-a, d-a] with the differences formed exactly (unlike the library, which never
/// forms them).
int oracle_orient3d(const P3& a, const P3& b, const P3& c, const P3& d) {
  const int emin = common_low_exponent({&a, &b, &c, &d});
  const auto A = big3(a, emin), B = big3(b, emin), C = big3(c, emin), D = big3(d, emin);
  std::array<BigInt, 3> x, y, z;
  for (int k = 0; k < 3; ++k) {
    x[k] = B[k] - A[k];
    y[k] = C[k] - A[k];
    z[k] = D[k] - A[k];
  }
  return det3(x, y, z).sign();
}

// ---------------------------------------------------------------------------------------------
// Oracle 2: __int128 for inputs n * 2^-s with |n| < 2^29 and 0 <= s <= 10; scaled by 2^10 they
// are integers below 2^39, differences below 2^40, triple products below 2^120, and a sum of
// six of them below 2^123: no overflow.
struct SmallCoord {
  std::int64_t n;
  int s;
  double value() const { return std::ldexp(static_cast<double>(n), -s); }
  __int128 scaled() const { return static_cast<__int128>(n) << (10 - s); }
};

int sign128(__int128 v) { return v > 0 ? 1 : (v < 0 ? -1 : 0); }

__int128 det128(const __int128* x, const __int128* y, const __int128* z) {
  return x[0] * (y[1] * z[2] - y[2] * z[1]) - x[1] * (y[0] * z[2] - y[2] * z[0]) + x[2] * (y[0] * z[1] - y[1] * z[0]);
}

// ---------------------------------------------------------------------------------------------
// The naive double evaluation, to show that near-degenerate cases really need exactness.
int naive_origin(const P3& a, const P3& b, const P3& c) {
  const double d = a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) +
                   a[2] * (b[0] * c[1] - b[1] * c[0]);
  return d > 0 ? 1 : (d < 0 ? -1 : 0);
}

int naive_orient3d(const P3& a, const P3& b, const P3& c, const P3& d) {
  const P3 x = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const P3 y = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const P3 z = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return naive_origin(x, y, z);
}

int orient(const P3& a, const P3& b, const P3& c) { return orient3d_origin(a.data(), b.data(), c.data()); }
int orient(const P3& a, const P3& b, const P3& c, const P3& d) {
  return orient3d(a.data(), b.data(), c.data(), d.data());
}

P3 scaled(const P3& p, int k) { return {std::ldexp(p[0], k), std::ldexp(p[1], k), std::ldexp(p[2], k)}; }

/// Checks the six permutations of (a, b, c): even ones keep the sign, odd ones flip it.
void check_origin_permutations(const P3& a, const P3& b, const P3& c, int expected) {
  CHECK(orient(a, b, c) == expected);
  CHECK(orient(b, c, a) == expected);
  CHECK(orient(c, a, b) == expected);
  CHECK(orient(b, a, c) == -expected);
  CHECK(orient(a, c, b) == -expected);
  CHECK(orient(c, b, a) == -expected);
}

/// Checks all 24 permutations of (a, b, c, d) against the permutation's parity.
void check_orient3d_permutations(const P3& a, const P3& b, const P3& c, const P3& d, int expected) {
  std::array<int, 4> idx = {0, 1, 2, 3};
  const P3* pts[4] = {&a, &b, &c, &d};
  do {
    int inversions = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) inversions += idx[i] > idx[j];
    const int want = inversions % 2 == 0 ? expected : -expected;
    CHECK(orient(*pts[idx[0]], *pts[idx[1]], *pts[idx[2]], *pts[idx[3]]) == want);
  } while (std::next_permutation(idx.begin(), idx.end()));
}

/// A point near the plane through the origin spanned by a and b: fl(s a + t b), so the only
/// thing that moves it off the plane is rounding (|det| ~ 1e-16 |a||b||c|).
P3 near_plane(const P3& a, const P3& b, double s, double t) {
  return {s * a[0] + t * b[0], s * a[1] + t * b[1], s * a[2] + t * b[2]};
}

}  // namespace

TEST_CASE("orient3d_origin: sign convention and exact zeros", "[predicates]") {
  // Counter-clockwise seen from outside (the +x+y+z octant's spherical triangle).
  CHECK(orient({1, 0, 0}, {0, 1, 0}, {0, 0, 1}) == 1);
  CHECK(orient({1, 0, 0}, {0, 0, 1}, {0, 1, 0}) == -1);
  // Points on a great circle (all in the plane z = 0) are exactly degenerate.
  CHECK(orient({1, 0, 0}, {0, 1, 0}, {1, 1, 0}) == 0);
  CHECK(orient({1, 0, 0}, {0, 1, 0}, {-0.6, 0.8, 0}) == 0);
  // Repeated and antipodal points.
  CHECK(orient({0.3, 0.4, 0.5}, {0.3, 0.4, 0.5}, {1, 2, 3}) == 0);
  CHECK(orient({0.3, 0.4, 0.5}, {-0.3, -0.4, -0.5}, {1, 2, 3}) == 0);
  CHECK(orient({0, 0, 0}, {1, 2, 3}, {4, 5, 6}) == 0);
  // Every face of an icosphere is positively oriented.
  const spherekit::TriMesh m = spherekit::test::icosphere(3);
  int positive = 0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    positive += orient3d_origin(m.V.row(m.F(f, 0)).data(), m.V.row(m.F(f, 1)).data(), m.V.row(m.F(f, 2)).data()) == 1;
  CHECK(positive == m.F.rows());
  // Eigen overload.
  CHECK(orient3d_origin(Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1)) == 1);
}

TEST_CASE("orient3d_origin: c = a + b with small integers is exactly coplanar", "[predicates]") {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> I(-1000000, 1000000);
  std::uniform_int_distribution<int> E(-40, 40);
  for (int trial = 0; trial < 2000; ++trial) {
    // Same power-of-two scale for a and b keeps a + b exact (26-bit sums).
    const int k = E(rng);
    const P3 a = scaled({double(I(rng)), double(I(rng)), double(I(rng))}, k);
    const P3 b = scaled({double(I(rng)), double(I(rng)), double(I(rng))}, k);
    const P3 c = {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
    const P3 c2 = {a[0] - 3 * b[0], a[1] - 3 * b[1], a[2] - 3 * b[2]};
    REQUIRE(oracle_origin(a, b, c) == 0);
    check_origin_permutations(a, b, c, 0);
    CHECK(orient(a, b, c2) == 0);
  }
}

TEST_CASE("orient3d_origin: random inputs agree with the __int128 oracle", "[predicates]") {
  std::mt19937_64 rng(12);
  std::uniform_int_distribution<std::int64_t> N(-(std::int64_t{1} << 29) + 1, (std::int64_t{1} << 29) - 1);
  std::uniform_int_distribution<std::int64_t> Small(-8, 8);
  std::uniform_int_distribution<int> S(0, 10);
  int zeros = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    // Every fourth case uses tiny integers (s = 0) so that exact zeros are frequent.
    auto draw = [&]() { return trial % 4 == 0 ? SmallCoord{Small(rng), 0} : SmallCoord{N(rng), S(rng)}; };
    SmallCoord in[9];
    for (auto& x : in) x = draw();
    __int128 v[9];
    P3 p[3];
    for (int i = 0; i < 9; ++i) {
      v[i] = in[i].scaled();
      p[i / 3][i % 3] = in[i].value();
    }
    const int want = sign128(det128(v, v + 3, v + 6));
    zeros += want == 0;
    REQUIRE(orient(p[0], p[1], p[2]) == want);
  }
  CHECK(zeros > 100);
}

TEST_CASE("orient3d_origin: near-degenerate inputs agree with the big-integer oracle", "[predicates]") {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  int naive_wrong = 0, exact_zero = 0, cases = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const P3 a = {U(rng), U(rng), U(rng)};
    const P3 b = {U(rng), U(rng), U(rng)};
    P3 c;
    switch (trial % 3) {
      case 0: c = near_plane(a, b, U(rng), U(rng)); break;
      // c = a (1 + 2^-52): almost parallel to a, nudged by rounding only.
      case 1: c = {a[0] * (1 + 0x1p-52), a[1] * (1 + 0x1p-52), a[2] * (1 - 0x1p-52)}; break;
      default: c = near_plane(a, b, 0.5, 0.25); break;  // exact multiples: often exactly coplanar
    }
    const int want = oracle_origin(a, b, c);
    ++cases;
    exact_zero += want == 0;
    naive_wrong += naive_origin(a, b, c) != want;
    REQUIRE(orient(a, b, c) == want);
    if (trial % 20 == 0) check_origin_permutations(a, b, c, want);
  }
  INFO("naive double sign wrong in " << naive_wrong << " of " << cases << " cases");
  CHECK(naive_wrong > 0);
  CHECK(exact_zero > 0);
  WARN("orient3d_origin near-degenerate: naive double sign wrong in " << naive_wrong << " of " << cases
                                                                        << ", exact zeros " << exact_zero);
}

TEST_CASE("orient3d_origin: a hand-made case where double evaluation gets the sign wrong", "[predicates]") {
  // a and b have coordinates near 1 and 0.5 that differ only in their last bits, and
  // c = fl(0.1 a + 0.7 b) is off the plane of a and b by rounding alone: the determinant's
  // terms are ~0.1 and cancel to ~1e-17, below the double evaluation's error. Walk a small
  // deterministic family until the naive sign is wrong; the oracle decides, the predicate
  // must match it there (and everywhere else).
  bool found = false;
  for (int i = 1; i < 64 && !found; ++i)
    for (int j = 1; j < 64 && !found; ++j) {
      const double e = 0x1p-52;
      const P3 a = {1.0 + i * e, 1.0 + j * e, 1.0};
      const P3 b = {0.5 + j * e / 2, 0.5, 0.5 + i * e / 2};
      const P3 c = near_plane(a, b, 0.1, 0.7);
      const int want = oracle_origin(a, b, c);
      REQUIRE(orient(a, b, c) == want);
      if (want != 0 && naive_origin(a, b, c) != want) {
        found = true;
        INFO("i=" << i << " j=" << j << " exact sign " << want);
        check_origin_permutations(a, b, c, want);
      }
    }
  CHECK(found);
}

TEST_CASE("orient3d_origin: power-of-two scaling keeps the sign, across all tiers", "[predicates]") {
  // Scaling one argument by 2^k scales the determinant by 2^k. Exponents beyond +-280 move
  // the same problem from the expansion tier to the big-integer tier; +-1000 reaches
  // subnormal and near-overflow coordinates.
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const int ks[] = {0, 1, -1, 100, -100, 279, -279, 281, -281, 300, -300, 600, -600, 1000, -1000, 1020, -1070};
  for (int trial = 0; trial < 3000; ++trial) {
    const P3 a = {U(rng), U(rng), U(rng)};
    const P3 b = {U(rng), U(rng), U(rng)};
    const P3 c = trial % 2 ? near_plane(a, b, U(rng), U(rng)) : P3{U(rng), U(rng), U(rng)};
    const int want = oracle_origin(a, b, c);
    REQUIRE(orient(a, b, c) == want);
    const int ka = ks[trial % 17], kb = ks[(trial / 17) % 17], kc = ks[(trial / 7) % 17];
    const P3 sa = scaled(a, ka), sb = scaled(b, kb), sc = scaled(c, kc);
    // Scaling towards subnormals can round away low bits: then the oracle on the scaled
    // inputs is the reference, and invariance is only required when scaling was exact.
    const bool exact = scaled(sa, -ka) == a && scaled(sb, -kb) == b && scaled(sc, -kc) == c;
    const int scaled_want = oracle_origin(sa, sb, sc);
    if (exact) CHECK(scaled_want == want);
    REQUIRE(orient(sa, sb, sc) == scaled_want);
  }
}

TEST_CASE("orient3d_origin: extreme and non-finite inputs", "[predicates]") {
  const double tiny = std::numeric_limits<double>::denorm_min();
  const double big = std::numeric_limits<double>::max();
  CHECK(orient({tiny, 0, 0}, {0, tiny, 0}, {0, 0, tiny}) == 1);
  CHECK(orient({big, 0, 0}, {0, big, 0}, {0, 0, -big}) == -1);
  CHECK(orient({big, big, 0}, {big, -big, 0}, {tiny, tiny, tiny}) == -1);
  // Huge and subnormal components mixed; columns x = big * z are proportional: exactly 0.
  const P3 h0 = {big, tiny, 1}, h1 = {big / 2, tiny, 0.5}, h2 = {big / 4, 3 * tiny, 0.25};
  CHECK(oracle_origin(h0, h1, h2) == 0);
  check_origin_permutations(h0, h1, h2, 0);
  const P3 h3 = {big / 4, 3 * tiny, std::nextafter(0.25, 1.0)};  // one ulp off: decided by tiny
  CHECK(orient(h0, h1, h3) == oracle_origin(h0, h1, h3));
  CHECK(orient(h0, h1, h3) != 0);
  std::mt19937_64 rng(15);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::uniform_int_distribution<int> E(-1074, 1023);
  for (int trial = 0; trial < 3000; ++trial) {
    P3 p[3];
    for (auto& q : p)
      for (double& x : q) x = std::ldexp(U(rng), E(rng));  // may round to subnormal / zero
    REQUIRE(orient(p[0], p[1], p[2]) == oracle_origin(p[0], p[1], p[2]));
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  CHECK(orient({nan, 0, 0}, {0, 1, 0}, {0, 0, 1}) == 0);
  CHECK(orient({1, 0, 0}, {0, inf, 0}, {0, 0, 1}) == 0);
  CHECK(orient({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, nan}) == 0);
}

TEST_CASE("orient3d: sign convention and exactly coplanar points", "[predicates]") {
  const P3 o = {0, 0, 0}, x = {1, 0, 0}, y = {0, 1, 0}, z = {0, 0, 1};
  CHECK(orient(o, x, y, z) == 1);   // det[e1, e2, e3] = +1: d above the ccw triangle abc
  CHECK(orient(o, y, x, z) == -1);
  CHECK(orient(o, x, y, {0.3, 0.2, 0}) == 0);
  CHECK(orient(o, x, y, {5, -7, 0}) == 0);
  // +1 exactly when d lies on the side of plane abc that (b - a) x (c - a) points to.
  std::mt19937_64 rng0(20);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int trial = 0; trial < 1000; ++trial) {
    const Eigen::Vector3d a(U(rng0), U(rng0), U(rng0)), b(U(rng0), U(rng0), U(rng0)), c(U(rng0), U(rng0), U(rng0));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const Eigen::Vector3d up = a + n, down = a - n;
    CHECK(orient3d(a.data(), b.data(), c.data(), up.data()) == 1);
    CHECK(orient3d(a.data(), b.data(), c.data(), down.data()) == -1);
  }
  // d = a + b - c with integer coordinates: d - a = (b - a) - (c - a), exactly coplanar,
  // also far from the origin where the differences are large cancellations.
  std::mt19937_64 rng(21);
  std::uniform_int_distribution<std::int64_t> I(-(1 << 20), 1 << 20);
  const double offsets[] = {0.0, 1e6, 0x1p40, -0x1p45};
  for (int trial = 0; trial < 4000; ++trial) {
    const double off = offsets[trial % 4];
    auto pt = [&]() { return P3{off + double(I(rng)), off + double(I(rng)), off - double(I(rng))}; };
    const P3 a = pt(), b = pt(), c = pt();
    const P3 d = {a[0] + b[0] - c[0], a[1] + b[1] - c[1], a[2] + b[2] - c[2]};
    REQUIRE(oracle_orient3d(a, b, c, d) == 0);
    REQUIRE(orient(a, b, c, d) == 0);
    if (trial % 50 == 0) check_orient3d_permutations(a, b, c, d, 0);
  }
}

TEST_CASE("orient3d: random inputs agree with the __int128 oracle", "[predicates]") {
  std::mt19937_64 rng(22);
  std::uniform_int_distribution<std::int64_t> N(-(std::int64_t{1} << 29) + 1, (std::int64_t{1} << 29) - 1);
  std::uniform_int_distribution<std::int64_t> Small(-6, 6);
  std::uniform_int_distribution<int> S(0, 10);
  int zeros = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    SmallCoord in[12];
    for (auto& x : in) x = trial % 4 == 0 ? SmallCoord{Small(rng), 0} : SmallCoord{N(rng), S(rng)};
    __int128 v[12];
    P3 p[4];
    for (int i = 0; i < 12; ++i) {
      v[i] = in[i].scaled();
      p[i / 3][i % 3] = in[i].value();
    }
    __int128 d[9];
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) d[3 * r + k] = v[3 * (r + 1) + k] - v[k];
    const int want = sign128(det128(d, d + 3, d + 6));
    zeros += want == 0;
    REQUIRE(orient(p[0], p[1], p[2], p[3]) == want);
  }
  CHECK(zeros > 100);
}

TEST_CASE("orient3d: near-coplanar inputs agree with the big-integer oracle", "[predicates]") {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  int naive_wrong = 0, exact_zero = 0, cases = 0;
  const double offsets[] = {0.0, 0.1, 1.0, 1e3, 1e8, -3.7e12};
  for (int trial = 0; trial < 12000; ++trial) {
    const double off = offsets[trial % 6];
    const P3 a = {off + U(rng), off + U(rng), off + U(rng)};
    const P3 b = {off + U(rng), off + U(rng), off + U(rng)};
    const P3 c = {off + U(rng), off + U(rng), off + U(rng)};
    // d on plane abc up to rounding: a + s (b - a) + t (c - a) evaluated in double.
    const double s = U(rng), t = trial % 5 == 0 ? 0.5 : U(rng);
    const P3 d = {a[0] + s * (b[0] - a[0]) + t * (c[0] - a[0]), a[1] + s * (b[1] - a[1]) + t * (c[1] - a[1]),
                  a[2] + s * (b[2] - a[2]) + t * (c[2] - a[2])};
    const int want = oracle_orient3d(a, b, c, d);
    ++cases;
    exact_zero += want == 0;
    naive_wrong += naive_orient3d(a, b, c, d) != want;
    REQUIRE(orient(a, b, c, d) == want);
    if (trial % 100 == 0) check_orient3d_permutations(a, b, c, d, want);
  }
  CHECK(naive_wrong > 0);
  WARN("orient3d near-coplanar: naive double sign wrong in " << naive_wrong << " of " << cases << ", exact zeros "
                                                              << exact_zero);
}

TEST_CASE("orient3d: power-of-two scaling and extreme magnitudes", "[predicates]") {
  // Scaling all four points by 2^k scales the determinant by 2^3k: the sign is invariant, and
  // k beyond +-280 moves the problem into the big-integer tier.
  std::mt19937_64 rng(24);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const int ks[] = {0, 3, -3, 200, -200, 290, -290, 700, -700, 1000, -1000};
  for (int trial = 0; trial < 3000; ++trial) {
    P3 p[4];
    for (int i = 0; i < 3; ++i) p[i] = {1 + U(rng), U(rng), 2 + U(rng)};
    const double s = U(rng), t = U(rng);
    for (int k = 0; k < 3; ++k) p[3][k] = p[0][k] + s * (p[1][k] - p[0][k]) + t * (p[2][k] - p[0][k]);
    const int want = oracle_orient3d(p[0], p[1], p[2], p[3]);
    REQUIRE(orient(p[0], p[1], p[2], p[3]) == want);
    const int k = ks[trial % 11];
    const P3 q[4] = {scaled(p[0], k), scaled(p[1], k), scaled(p[2], k), scaled(p[3], k)};
    const bool exact = scaled(q[0], -k) == p[0] && scaled(q[1], -k) == p[1] && scaled(q[2], -k) == p[2] &&
                       scaled(q[3], -k) == p[3];
    const int scaled_want = oracle_orient3d(q[0], q[1], q[2], q[3]);
    if (exact) CHECK(scaled_want == want);
    REQUIRE(orient(q[0], q[1], q[2], q[3]) == scaled_want);
  }
  // Random magnitudes over the whole double range (subnormal to near-overflow differences).
  std::uniform_int_distribution<int> E(-1074, 1020);
  for (int trial = 0; trial < 2000; ++trial) {
    P3 p[4];
    for (auto& q : p)
      for (double& x : q) x = std::ldexp(U(rng), E(rng));
    REQUIRE(orient(p[0], p[1], p[2], p[3]) == oracle_orient3d(p[0], p[1], p[2], p[3]));
  }
}
