// Exact sign of a sum of signed triple products x*y*z of arbitrary finite doubles, with
// fixed-width integer arithmetic: the last-resort tier of predicates.cpp, used only when an
// operand is so small or so large that the floating-point expansion tier could underflow or
// overflow. Internal header, never installed.
//
// Every finite double is m * 2^e with an integer m < 2^53 and -1074 <= e <= 971 (IEEE 754
// binary64). A triple product is then (m1 m2 m3) * 2^(e1+e2+e3): a 159-bit integer at an
// exponent in [-3222, 2913]. Shifting all terms to the smallest exponent of the sum puts them
// into a 6135 + 159 = 6294-bit integer; 24 terms add at most 5 carry bits, so 100 words of 64
// bits always suffice. Positive and negative terms go into two unsigned accumulators that are
// compared at the end, so no borrow ever has to ripple through all 100 words.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

namespace spherekit::detail {

class TripleProductSum {
 public:
  static constexpr int kMaxTerms = 24;

  /// Records sign * x * y * z (x, y, z finite). Terms beyond kMaxTerms are a caller bug and
  /// are ignored rather than written out of bounds.
  void add_triple_product(double x, double y, double z, bool negate) {
    if (n_ >= kMaxTerms || x == 0.0 || y == 0.0 || z == 0.0) return;
    Term& t = terms_[n_++];
    std::uint64_t mx, my, mz;
    int ex, ey, ez;
    decompose(x, mx, ex);
    decompose(y, my, ey);
    decompose(z, mz, ez);
    t.negative = ((x < 0) != (y < 0)) != ((z < 0) != negate);
    t.exponent = ex + ey + ez;
    // (mx*my) has at most 106 bits; times mz at most 159 bits: three words, low first.
    const unsigned __int128 p = static_cast<unsigned __int128>(mx) * my;
    const unsigned __int128 lo = static_cast<unsigned __int128>(static_cast<std::uint64_t>(p)) * mz;
    const unsigned __int128 hi = static_cast<unsigned __int128>(static_cast<std::uint64_t>(p >> 64)) * mz;
    const unsigned __int128 mid = (lo >> 64) + static_cast<std::uint64_t>(hi);
    t.word[0] = static_cast<std::uint64_t>(lo);
    t.word[1] = static_cast<std::uint64_t>(mid);
    t.word[2] = static_cast<std::uint64_t>(hi >> 64) + static_cast<std::uint64_t>(mid >> 64);
  }

  /// Sign of the exact sum of the recorded terms: +1, 0 or -1.
  int sign() const {
    if (n_ == 0) return 0;
    int emin = terms_[0].exponent;
    for (int i = 1; i < n_; ++i) emin = std::min(emin, terms_[i].exponent);
    std::uint64_t pos[kWords] = {}, neg[kWords] = {};
    for (int i = 0; i < n_; ++i) {
      const Term& t = terms_[i];
      accumulate(t.negative ? neg : pos, t, t.exponent - emin);
    }
    for (int w = kWords - 1; w >= 0; --w) {
      if (pos[w] != neg[w]) return pos[w] > neg[w] ? 1 : -1;
    }
    return 0;
  }

 private:
  static constexpr int kWords = 100;

  struct Term {
    std::uint64_t word[3];
    int exponent;
    bool negative;
  };

  /// |x| = m * 2^e with m odd (trailing zeros moved into e, so e >= -1074).
  static void decompose(double x, std::uint64_t& m, int& e) {
    int k;
    const double f = std::frexp(std::fabs(x), &k);  // f in [0.5, 1), exact for subnormals too
    m = static_cast<std::uint64_t>(std::ldexp(f, 53));
    e = k - 53;
    const int tz = std::countr_zero(m);
    m >>= tz;
    e += tz;
  }

  /// acc += t * 2^shift, shift >= 0 (at most 6135 by the bounds above).
  static void accumulate(std::uint64_t* acc, const Term& t, int shift) {
    const int ws = shift / 64, bs = shift % 64;
    std::uint64_t s[4];
    if (bs == 0) {
      s[0] = t.word[0]; s[1] = t.word[1]; s[2] = t.word[2]; s[3] = 0;
    } else {
      s[0] = t.word[0] << bs;
      s[1] = (t.word[1] << bs) | (t.word[0] >> (64 - bs));
      s[2] = (t.word[2] << bs) | (t.word[1] >> (64 - bs));
      s[3] = t.word[2] >> (64 - bs);
    }
    unsigned carry = 0;
    int w = ws;
    for (int k = 0; k < 4 && w < kWords; ++k, ++w) {
      const unsigned __int128 sum = static_cast<unsigned __int128>(acc[w]) + s[k] + carry;
      acc[w] = static_cast<std::uint64_t>(sum);
      carry = static_cast<unsigned>(sum >> 64);
    }
    for (; carry != 0 && w < kWords; ++w) {
      acc[w] += 1;
      carry = acc[w] == 0 ? 1u : 0u;
    }
  }

  Term terms_[kMaxTerms];
  int n_ = 0;
};

}  // namespace spherekit::detail
