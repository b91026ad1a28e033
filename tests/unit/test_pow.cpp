// sphc::pow_int (sphc/pow.h): x^y by multiplications for integer |y| <= 8, std::pow otherwise.
// The bound of the header: relative error <= (|y| - 1) u, + u for y < 0 (u = 2^-53), against
// the exact power (here powl in long double, 11 more bits); within that + 1 ulp of std::pow.
#include "sphc/pow.h"

#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>

namespace {

constexpr double kU = 0x1p-53;

// |a - b| in units of b's ulp (b normal, finite).
double ulps(double a, long double b) {
  const long double ulp = std::ldexp(1.0L, std::ilogb(static_cast<double>(b)) - 52);
  return static_cast<double>(std::fabs(static_cast<long double>(a) - b) / ulp);
}

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void checkAgainstExact(double x, int n) {
  const double got = sphc::pow_int(x, n);
  const long double exact = std::pow(static_cast<long double>(x), n);
  const double bound = (std::abs(n) > 1 ? std::abs(n) - 1 : 0) + (n < 0 ? 1.0 : 0.0);
  ASSERT_TRUE(std::isfinite(got)) << x << "^" << n;
  EXPECT_LE(std::fabs(static_cast<long double>(got) - exact) / std::fabs(exact),
            bound * kU * (1 + 1e-12) + 1e-30L)
      << x << "^" << n;
  EXPECT_LE(ulps(got, std::pow(x, double(n))), bound + 1.0) << x << "^" << n;
}

TEST(PowInt, IntegerExponentsWithinTheBound) {
  std::mt19937_64 rng(16);
  std::uniform_real_distribution<double> wide(-20.0, 20.0);
  std::uniform_real_distribution<double> nearOne(-1e-2, 1e-2);
  for (int n = -8; n <= 8; ++n) {
    for (int i = 0; i < 20000; ++i) checkAgainstExact(wide(rng), n);
    for (int i = 0; i < 20000; ++i) checkAgainstExact(1.0 + nearOne(rng), n);
    for (double x : {1.0, -1.0, 2.0, 0.5, -3.0, 1.0 + DBL_EPSILON, 1.0 - DBL_EPSILON / 2})
      checkAgainstExact(x, n);
  }
}

// The Tait pressure near rho0: p / B = r^7 - 1 cancels; its absolute error is bounded by
// 6 u r^7 (pow_int) + exact subtraction (Sterbenz), against the 7 u carried by r = rho/rho0.
TEST(PowInt, TaitPressureNearRho0) {
  for (int k = -1000; k <= 1000; ++k) {
    const double r = 1.0 + k * 1e-6;
    const long double exact = std::pow(static_cast<long double>(r), 7) - 1.0L;
    const double got = sphc::pow_int(r, 7.0) - 1.0;
    EXPECT_LE(std::fabs(static_cast<long double>(got) - exact), 6.0 * kU * std::pow(r, 7.0) + 1e-30)
        << r;
  }
  EXPECT_EQ(sphc::pow_int(1.0, 7.0) - 1.0, 0.0);
}

TEST(PowInt, SpecialValuesAsStdPow) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (double x : {0.0, -0.0, inf, -inf, nan, DBL_MIN, DBL_TRUE_MIN, 1e-100, 1e200, -1e200,
                   1e-300, -1e-300}) {
    for (int n = -8; n <= 8; ++n) {
      const double want = std::pow(x, double(n));
      const double got = sphc::pow_int(x, double(n));
      if (std::isnan(want)) {
        EXPECT_TRUE(std::isnan(got)) << x << "^" << n;
      } else if (want == 0.0 || std::isinf(want) || std::fabs(want) < DBL_MIN) {
        EXPECT_TRUE(sameBits(got, want)) << x << "^" << n << ": " << got << " vs " << want;
      } else {
        EXPECT_LE(ulps(got, want), std::abs(n) + 1.0) << x << "^" << n;
      }
    }
  }
  EXPECT_EQ(sphc::pow_int(nan, 0.0), 1.0);
  EXPECT_EQ(sphc::pow_int(nan, -0.0), 1.0);
  EXPECT_TRUE(sameBits(sphc::pow_int(-0.0, -3.0), -inf));
  EXPECT_TRUE(sameBits(sphc::pow_int(-0.0, 3.0), -0.0));
  EXPECT_TRUE(sameBits(sphc::pow_int(0.0, -2.0), inf));
}

// Outside the fast path (non-integer y, |y| > 8, NaN or infinite y): std::pow, bit for bit.
TEST(PowInt, FallbackIsStdPow) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (double x : {0.0, -0.0, 0.3, 1.0, -1.0, 1.0001, 2.5, -2.5, 1e10, inf, -inf}) {
    for (double y : {9.0, -9.0, 12.0, 1e6, 0.5, 1.0 / 7.0, 3.5, -7.5, 8.000000000000002,
                     inf, -inf, nan}) {
      const double want = std::pow(x, y);
      const double got = sphc::pow_int(x, y);
      EXPECT_TRUE(sameBits(got, want) || (std::isnan(got) && std::isnan(want)))
          << x << "^" << y << ": " << got << " vs " << want;
    }
  }
}

// x = 1 returns 1 without calling std::pow (a wall at rest: rho0 (1 + p / B)^(1/gamma) with
// p = 0), the bits std::pow gives for every y, NaN and infinities included (C99 F.9.4.4).
TEST(PowInt, OneToAnyPowerIsStdPow) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (double y : {1.0 / 7.0, -1.0 / 7.0, 0.5, 1e300, -1e300, 9.0, 1e-300, 0.0, -0.0, inf, -inf,
                   nan, -nan}) {
    EXPECT_TRUE(sameBits(sphc::pow_int(1.0, y), std::pow(1.0, y))) << y;
    EXPECT_TRUE(sameBits(sphc::pow_int(1.0, y), 1.0)) << y;
  }
}

}  // namespace
