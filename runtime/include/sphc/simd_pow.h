// sphc/simd_pow.h: pow(x, y) that GCC can put in SIMD lanes, with the same bits in a lane
// and in a scalar loop.
//
// For the SIMD pair loops (sphc --simd-pairs, codegen/SimdPairs.cpp), which refuse bodies
// calling pow: the C library's pow has no SIMD form without -ffast-math (GCC keeps the loop
// scalar, or vectorises it in one build and not in another), and glibc's vector pow
// (libmvec) need not give its scalar pow's bits. Not printed today: with it the dam break's
// fluid <- fluid pass vectorised but ran slower than with the pass refused
// (docs/performance.md, "Bodies calling pow in SIMD lanes"). Everything here is plain
// double arithmetic (+ - * /, quiet comparisons, selects, integer shifts of the bits) in a
// fixed order, so a vector lane, the loop's scalar remainder and a serial or OpenMP build
// round alike (the generated code is built with -ffp-contract=off: no fused multiply-adds).
//
// Method (written from the series, no tables, no branches):
//   x = 2^e m, m in [sqrt(1/2), sqrt(2)), f = m - 1 (exact), s = f / (2 + f), z = s^2:
//     log(m) = 2 atanh(s) = 2 s + 2 s^3 / 3 + 2 s^5 / 5 + ...
//            = f - f^2/2 + s (f^2/2 + R),  R = sum_{k=1..11} 2 z^k / (2k + 1)
//     (|s| <= 0.1716: the first term left out, 2 z^12 / 25, is below 2^-60 of R's first);
//     log(x) = e ln2_hi + (f - (f^2/2 - (s (f^2/2 + R) + e ln2_lo))), ln2_hi with its low
//     bits zero so that e ln2_hi is exact.
//   t = y log(x); k = nearest integer to t / ln 2, r = (t - k ln2_hi) - k ln2_lo,
//     |r| <= ln2 / 2: exp(r) by its Taylor series to r^13 (the remainder below 2^-57),
//     exp(t) = exp(r) 2^k1 2^k2, k1 + k2 = k (two exact scalings, so subnormal results
//     round once).
// Error (tests/unit/test_simd_pow.cpp, against glibc's pow, itself within 1 ulp): at most
// 1 ulp for x in [0.5, 2] and y = 1/gamma, gamma = 1..10 (the bodies' Tait and hydrostatic
// densities). Beyond it the rounding of t = y log(x) carries |t| 2^-53 into the result: at
// most 2.03 (1 + |t|) ulp measured for x in [1e-3, 1e3], |y| <= 100 (the test asserts
// 2.5 (1 + |t|) for |y| <= 16).
// Special values follow C's pow: pow(x, +-0) = pow(1, y) = 1, a NaN in gives NaN, x < 0
// finite with a non-integer y NaN, with an odd integer y the sign of x; zeros and
// infinities as C's (the test compares them with std::pow).
//
// For GCC 12 to vectorise it where a body calls it under an `if` (if-conversion), it has no
// control flow once inlined: selects by bit masks (a chain of `?:` becomes branches), `&`
// and `|` on the conditions (`&&` and `||` are branches), comparisons that raise no
// floating-point exception (__builtin_isless ...: a plain `<` "could trap" and is not
// if-converted under a condition), everything always inlined (no call in the loop; a
// `declare simd` clone GCC 12 does not call under a condition).
#ifndef SPHC_SIMD_POW_H
#define SPHC_SIMD_POW_H

#include <cstdint>
#include <limits>

namespace sphc {
namespace simd_pow_detail {

__attribute__((always_inline)) inline std::uint64_t bits_of(double x) {
  return __builtin_bit_cast(std::uint64_t, x);
}
__attribute__((always_inline)) inline double double_of(std::uint64_t u) {
  return __builtin_bit_cast(double, u);
}

// 2^52 and 1.5 2^52: added to a double of magnitude below 2^51 they leave its nearest
// integer in the low bits of the sum (rounding to nearest, ties to even).
constexpr double kTwo52 = 4503599627370496.0;
constexpr double kShifter = 6755399441055744.0;
constexpr std::uint64_t kShifterBits = 0x4338000000000000ULL;

// c ? a : b by masks on the bits, without a branch (see above).
__attribute__((always_inline)) inline double select(bool c, double a, double b) {
  const std::uint64_t m = static_cast<std::uint64_t>(0) - static_cast<std::uint64_t>(c);
  return double_of((bits_of(a) & m) | (bits_of(b) & ~m));
}

// 2^k for an integer k (held in a double) in [-1022, 1023].
__attribute__((always_inline)) inline double two_to(double k) {
  const std::uint64_t ki = bits_of(k + kShifter) - kShifterBits;  // k, two's complement
  return double_of((ki + 1023) << 52);
}

}  // namespace simd_pow_detail

__attribute__((always_inline)) inline double simd_pow(double x, double y) {
  using namespace simd_pow_detail;
  // ln 2 = ln2_hi + ln2_lo, ln2_hi with 32 significant bits (k ln2_hi exact for |k| < 2^21).
  constexpr double ln2_hi = 6.93147180369123816490e-01;  // 0x3fe62e42fee00000
  constexpr double ln2_lo = 1.90821492927058770002e-10;
  constexpr double inv_ln2 = 1.44269504088896338700e+00;
  constexpr double sqrt2 = 1.41421356237309504880;

  const double ax = select(__builtin_isless(x, 0.0), -x, x);
  // Subnormal x: scaled by 2^54 first (its exponent field is zero).
  const bool tiny = __builtin_isless(ax, 2.2250738585072014e-308);
  const double xs = select(tiny, ax * 18014398509481984.0, ax);
  const std::uint64_t ux = bits_of(xs);
  // The biased exponent as a double: 2^52 + E, less 2^52.
  double e = double_of((ux >> 52) | bits_of(kTwo52)) - kTwo52 - 1023.0 - select(tiny, 54.0, 0.0);
  double m = double_of((ux & 0x000fffffffffffffULL) | 0x3ff0000000000000ULL);  // [1, 2)
  const bool big = __builtin_isgreater(m, sqrt2);
  m = select(big, 0.5 * m, m);
  e = select(big, e + 1.0, e);
  const double f = m - 1.0;
  const double s = f / (2.0 + f);
  const double z = s * s;
  const double R =
      z * (2.0 / 3.0 +
      z * (2.0 / 5.0 +
      z * (2.0 / 7.0 +
      z * (2.0 / 9.0 +
      z * (2.0 / 11.0 +
      z * (2.0 / 13.0 +
      z * (2.0 / 15.0 +
      z * (2.0 / 17.0 +
      z * (2.0 / 19.0 +
      z * (2.0 / 21.0 +
      z * (2.0 / 23.0)))))))))));
  const double hfsq = 0.5 * f * f;
  const double logx = e * ln2_hi + (f - (hfsq - (s * (hfsq + R) + e * ln2_lo)));

  // exp(t), t clamped where the result is 0 or infinite anyway (keeps k small).
  double t = y * logx;
  t = select(__builtin_isgreater(t, 1100.0), 1100.0, t);
  t = select(__builtin_isless(t, -1100.0), -1100.0, t);
  const double k = (t * inv_ln2 + kShifter) - kShifter;
  const double r = (t - k * ln2_hi) - k * ln2_lo;
  const double q =
      1.0 + r * (1.0 / 2.0 +
      r * (1.0 / 6.0 +
      r * (1.0 / 24.0 +
      r * (1.0 / 120.0 +
      r * (1.0 / 720.0 +
      r * (1.0 / 5040.0 +
      r * (1.0 / 40320.0 +
      r * (1.0 / 362880.0 +
      r * (1.0 / 3628800.0 +
      r * (1.0 / 39916800.0 +
      r * (1.0 / 479001600.0 +
      r * (1.0 / 6227020800.0))))))))))));
  const double expr = 1.0 + r * q;
  const double k1 = (0.5 * k + kShifter) - kShifter;
  double res = expr * two_to(k1) * two_to(k - k1);

  // Special values, as C's pow.
  const double ay = select(__builtin_isless(y, 0.0), -y, y);
  const bool yhuge = __builtin_isgreaterequal(ay, kTwo52);  // an even integer
  const double ysum = ay + kTwo52;
  const bool yint = yhuge | (ysum - kTwo52 == ay);
  const double yhalf = 0.5 * ay;  // odd: half of it not an integer
  const bool yodd = !yhuge & yint & ((yhalf + kTwo52) - kTwo52 != yhalf);
  const bool xinf = __builtin_isgreater(ax, 1.7976931348623157e308);
  const bool xzero = ax == 0.0;
  constexpr double inf = std::numeric_limits<double>::infinity();
  res = select(xzero, select(__builtin_isless(y, 0.0), inf, 0.0), res);
  res = select(xinf, select(__builtin_isless(y, 0.0), 0.0, inf), res);
  const bool negate = __builtin_isless(x, 0.0) | (xzero & ((bits_of(x) >> 63) != 0));
  res = select(negate & yodd, -res, res);
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  res = select(__builtin_isless(x, 0.0) & !xinf & !yint, nan, res);
  res = select((x != x) | (y != y), x + y, res);
  // pow(-1, +-inf) = 1
  res = select((ax == 1.0) & __builtin_isgreater(ay, 1.7976931348623157e308), 1.0, res);
  res = select((y == 0.0) | (x == 1.0), 1.0, res);
  return res;
}

}  // namespace sphc

#endif  // SPHC_SIMD_POW_H
