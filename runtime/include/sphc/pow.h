// sphc/pow.h: pow(x, y) with a small integer exponent by multiplications.
//
// The generated solvers call it for the `pow` of equation and stepper bodies (sphc
// --int-pow=on, the default; docs/performance-log.md, "Cheaper arithmetic"): the Tait equation of
// state raises rho / rho0 to gamma = 7 and to (gamma - 1) / 2 = 3 per particle and
// evaluation, and the C library's pow costs ~100 instructions where x^7 is 4 products.
//
// pow_int(x, y): where y is an integer with |y| <= kPowIntMax, x^|y| by repeated squaring
// (pow_uint_small: x^2 = x x, x^4 = x^2 x^2, x^7 = x^4 x^2 x, ...), then 1 / x^|y| for
// y < 0; elsewhere std::pow(x, y). Each product is rounded once
// (relative error u = 2^-53), so x^n carries a relative error of at most (n - 1) u (e_2k =
// 2 e_k + u, e_k+1 = e_k + u, e_1 = 0), one u more for the reciprocal: at most 7.5 u against
// the exact power for |y| <= 8, i.e. within 8 ulp of it, 9 of glibc's pow (< 1 ulp). Where
// the power leaves the normal range (zero, subnormal, infinite, NaN: x = 0 with y < 0, x NaN,
// overflow or underflow, whose intermediate products would round differently) the result is
// std::pow's, so pow_int agrees with pow on every special value. pow(+1, y) is 1 for every
// y, NaN included (C99 F.9.4.4), so x = 1 returns 1 without the call: the same bits, and no
// ~100-instruction call where a particle sits at its reference state (the dam break's walls
// at rho0, p = 0: FourtakasDensityDiffusion's rho0 (1 + p / B)^(1/gamma) per particle).
#ifndef SPHC_POW_H
#define SPHC_POW_H

#include <cfloat>
#include <cmath>

namespace sphc {

constexpr int kPowIntMax = 8;

// x^n, 0 <= n <= kPowIntMax, by the binary method (the order of the products is fixed: the
// same x and n give the same bits everywhere).
inline double pow_uint_small(double x, int n) {
  switch (n) {
    case 0: return 1.0;
    case 1: return x;
    case 2: return x * x;
    case 3: return x * x * x;
    case 4: { const double x2 = x * x; return x2 * x2; }
    case 5: { const double x2 = x * x; return x2 * x2 * x; }
    case 6: { const double x2 = x * x; return x2 * x2 * x2; }
    case 7: { const double x2 = x * x; return x2 * x2 * x2 * x; }
    default: { const double x2 = x * x; const double x4 = x2 * x2; return x4 * x4; }
  }
}

inline double pow_int(double x, double y) {
  if (std::fabs(y) <= double(kPowIntMax)) {   // false for NaN
    const int n = static_cast<int>(y);
    if (double(n) == y) {
      const double r = pow_uint_small(x, n < 0 ? -n : n);
      const double a = std::fabs(r);
      if (a >= DBL_MIN && a <= DBL_MAX) return n < 0 ? 1.0 / r : r;
    }
  }
  if (x == 1.0) return 1.0;   // pow(+1, y) = 1 for every y
  return std::pow(x, y);
}

}  // namespace sphc

#endif  // SPHC_POW_H
