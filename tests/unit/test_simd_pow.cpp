// sphc/simd_pow.h: the pow of the SIMD pair loops (sphc --simd-pairs). Its error against
// glibc's pow (itself within 1 ulp of the exact power) over the ranges the bodies use and
// beyond, C's special values, and the same bits in SIMD lanes as in a scalar loop. This file
// is built with the generated solvers' flags (-march=native -fopenmp-simd -ffp-contract=off,
// tests/unit/CMakeLists.txt) so that the `#pragma omp simd` loops below are vectorised as a
// solver's are.
#include "sphc/simd_pow.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace {

// Distance in units in the last place between two finite doubles of the same sign.
double ulps(double a, double b) {
  auto key = [](double d) {
    std::int64_t i;
    std::memcpy(&i, &d, sizeof i);
    return i < 0 ? std::numeric_limits<std::int64_t>::min() - i : i;
  };
  return std::fabs(static_cast<double>(key(a) - key(b)));
}

std::uint64_t bits(double d) {
  std::uint64_t u;
  std::memcpy(&u, &d, sizeof u);
  return u;
}

// The bodies' use: FourtakasDensityDiffusion (stdlib/delta_sph.sph) raises 1 + (p + dph) / B
// to 1 / gamma; the Tait equation of state rho / rho0 to 1 / gamma. Bases in [0.5, 2] (a
// density within a factor 2 of the reference, far past a weakly compressible run's 1-5%),
// gamma = 1..10: within 1 ulp of glibc's pow.
TEST(SimdPow, WithinOneUlpOverTheBodiesRange) {
  std::mt19937_64 gen(16);
  std::uniform_real_distribution<double> base(0.5, 2.0);
  double worst = 0.0;
  for (int gamma = 1; gamma <= 10; ++gamma) {
    const double y = 1.0 / gamma;
    for (int i = 0; i < 200000; ++i) {
      const double x = base(gen);
      worst = std::max(worst, ulps(sphc::simd_pow(x, y), std::pow(x, y)));
    }
  }
  EXPECT_LE(worst, 1.0);
}

// Beyond it the rounding of t = y log(x) (relative 2^-53) carries |t| ulp into exp(t): the
// error grows with |t|. Measured at most 2.03 (1 + |t|) ulp for x in [1e-3, 1e3] and |y| <=
// 100 (586 ulp at |t| = 672): asserted with a margin, 2.5 (1 + |t|), for |y| <= 16.
TEST(SimdPow, ErrorGrowsWithTheLogarithmOfTheResult) {
  std::mt19937_64 gen(17);
  std::uniform_real_distribution<double> lx(std::log(1e-3), std::log(1e3)), ly(-16.0, 16.0);
  double worst = 0.0;
  for (int i = 0; i < 400000; ++i) {
    const double x = std::exp(lx(gen)), y = ly(gen);
    const double ref = std::pow(x, y);
    if (!std::isnormal(ref)) continue;
    const double t = std::fabs(y * std::log(x));
    worst = std::max(worst, ulps(sphc::simd_pow(x, y), ref) / (1.0 + t));
  }
  EXPECT_LE(worst, 2.5);
  EXPECT_GT(worst, 0.0);  // not the C library's pow in disguise
}

TEST(SimdPow, SpecialValuesAsCsPow) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double values[] = {0.0,  -0.0, 1.0,  -1.0, 2.0,    -2.0,    0.5,  -0.5,  inf,
                           -inf, nan,  3.0,  -3.0, 2.5,    -2.5,    7.0,  1e-310, -1e-310,
                           1e300, 1e-300, 0.125, 1.0 / 7.0, 9007199254740993.0};
  for (double x : values)
    for (double y : values) {
      const double got = sphc::simd_pow(x, y), want = std::pow(x, y);
      if (bits(got) == bits(want)) continue;
      if (std::isnan(want)) {
        EXPECT_TRUE(std::isnan(got)) << "pow(" << x << ", " << y << ")";
      } else if (want == 0.0 || std::isinf(want)) {
        EXPECT_EQ(bits(got), bits(want)) << "pow(" << x << ", " << y << ") = " << got;
      } else {
        // Finite results: the sign exact, the size within the error above (|t| up to 700).
        EXPECT_EQ(std::signbit(got), std::signbit(want)) << "pow(" << x << ", " << y << ")";
        EXPECT_LE(ulps(std::fabs(got), std::fabs(want)),
                  2.5 * (1.0 + std::fabs(y * std::log(std::fabs(x)))))
            << "pow(" << x << ", " << y << ") = " << got << ", not " << want;
      }
    }
}

// The same loop over the same inputs, vectorised and not: the bits must agree (the vector
// lanes, the loop's remainder and a scalar build round alike). 1003 elements: a remainder.
__attribute__((noinline, optimize("no-tree-vectorize"))) void scalarLoop(const double* x, const double* y,
                                                                 double* out, int n) {
  for (int i = 0; i < n; ++i) out[i] = sphc::simd_pow(x[i], y[i]);
}
__attribute__((noinline)) void simdLoop(const double* x, const double* y, double* out, int n) {
#pragma omp simd
  for (int i = 0; i < n; ++i) out[i] = sphc::simd_pow(x[i], y[i]);
}
// As in FourtakasDensityDiffusion's SIMD body: the power in a branch.
inline double branchBody(double x, double y) {
  double r = 0.0;
  if (std::fabs(x - 1.0) < 0.01) {
    r = 1.0 + y * (x - 1.0);
  } else {
    r = x > 0.0 ? 3.0 * sphc::simd_pow(x, y) : 0.0;
  }
  return r;
}
__attribute__((noinline, optimize("no-tree-vectorize"))) void scalarBranch(const double* x,
                                                                             double y, double* out,
                                                                             int n) {
  for (int i = 0; i < n; ++i) out[i] = branchBody(x[i], y);
}
__attribute__((noinline)) void simdBranch(const double* x, double y, double* out, int n) {
#pragma omp simd
  for (int i = 0; i < n; ++i) out[i] = branchBody(x[i], y);
}

TEST(SimdPow, SimdLanesGiveTheScalarBits) {
  const int n = 1003;
  std::mt19937_64 gen(18);
  std::uniform_real_distribution<double> lx(std::log(1e-6), std::log(1e6)), uy(-8.0, 8.0),
      near(0.95, 1.05);
  std::vector<double> x(n), y(n), a(n), b(n);
  for (int i = 0; i < n; ++i) {
    x[i] = i % 7 == 0 ? -std::exp(lx(gen)) : std::exp(lx(gen));
    y[i] = i % 5 == 0 ? std::round(uy(gen)) : uy(gen);
  }
  x[1] = 0.0, x[2] = -0.0, x[3] = std::numeric_limits<double>::infinity(), x[4] = 1e-310;
  scalarLoop(x.data(), y.data(), a.data(), n);
  simdLoop(x.data(), y.data(), b.data(), n);
  for (int i = 0; i < n; ++i)
    ASSERT_EQ(bits(a[i]), bits(b[i])) << "pow(" << x[i] << ", " << y[i] << ") at " << i;
  for (int i = 0; i < n; ++i) x[i] = near(gen);
  scalarBranch(x.data(), 1.0 / 7.0, a.data(), n);
  simdBranch(x.data(), 1.0 / 7.0, b.data(), n);
  for (int i = 0; i < n; ++i) ASSERT_EQ(bits(a[i]), bits(b[i])) << "x = " << x[i] << " at " << i;
}

}  // namespace
