// The 2xMM tiles' register test under AVX-512 (runtime sphc/cluster_pairs.h tile_row_any2,
// tile_row_any2_cut; stop 46, docs/performance-log.md "The own dam break's shifting tiles
// (stop 46)"): on random registers of 2 i's x 4 j's, many pairs at the cut-off to the last
// bit, the helpers say yes exactly where the lanes' own test (the printed loop: R2IJ against
// radius2 hmax hmax, the lane tables cl_jlane > cl_ilane + lane_d) finds a lane, so the tiles
// skip the same registers. Built -march=native (sphc_native_unit_tests); skips without
// AVX-512F.
#include "sphc/cluster_pairs.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#if defined(__AVX512F__)
namespace {

constexpr double kIlane[8] = {0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0};
constexpr double kJlane[8] = {0.0, 1.0, 2.0, 3.0, 0.0, 1.0, 2.0, 3.0};

// The lanes' test as the printed loop computes it (sphc compiles with -ffp-contract=off, as
// this file is).
bool lanes_any(const double* xi, const double* yi, const double* hi, const double* xj,
               const double* yj, const double* hj, double lane_d, double radius2, bool uniform,
               double cut2) {
  double any = 0.0;
  for (int l = 0; l < 8; ++l) {
    const double dx = xi[l] - xj[l];
    const double dy = yi[l] - yj[l];
    const double r2 = dx * dx + dy * dy;
    const double hmax = hi[l] > hj[l] ? hi[l] : hj[l];
    const double cut = uniform ? cut2 : radius2 * hmax * hmax;
    const double in = !(r2 >= cut) & (kJlane[l] > kIlane[l] + lane_d) ? 1.0 : 0.0;
    any = any > in ? any : in;
  }
  return any > 0.0;
}

TEST(TileRow2, TheRegisterTestIsTheLanesTest) {
  std::mt19937_64 rng(46);
  std::uniform_real_distribution<double> pos(0.0, 0.2);
  std::uniform_real_distribution<double> hs(0.02, 0.04);
  std::uniform_int_distribution<int> pick(0, 7);
  const double radius2 = 4.0;
  int yes = 0, no = 0, edge = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    alignas(64) double xi[8], yi[8], hi[8], xj[8], yj[8], hj[8];
    const bool uniform = trial % 2 == 0;
    const double h = hs(rng);
    double ih[2], jh[4], ix[2], iy[2], jx[4], jy[4];
    for (int k = 0; k < 2; ++k) ix[k] = pos(rng), iy[k] = pos(rng), ih[k] = uniform ? h : hs(rng);
    for (int k = 0; k < 4; ++k) jx[k] = pos(rng), jy[k] = pos(rng), jh[k] = uniform ? h : hs(rng);
    // a third of the registers: one pair put at the cut-off (r2 == radius2 hmax^2 up to
    // rounding, on either side of it)
    if (trial % 3 == 0) {
      const int l = pick(rng);
      const double hm = ih[l / 4] > jh[l % 4] ? ih[l / 4] : jh[l % 4];
      jx[l % 4] = ix[l / 4] + std::sqrt(radius2) * hm * (trial % 2 ? 1.0 : std::nextafter(1.0, 0.0));
      jy[l % 4] = iy[l / 4];
      ++edge;
    }
    for (int l = 0; l < 8; ++l) {
      xi[l] = ix[l / 4], yi[l] = iy[l / 4], hi[l] = ih[l / 4];
      xj[l] = jx[l % 4], yj[l] = jy[l % 4], hj[l] = jh[l % 4];
    }
    const double lane_d = trial % 5 == 0 ? 0.0 : trial % 5 == 1 ? 2.0 : -8.0;  // diagonal r = 0, 1; off
    const double cut2 = radius2 * h * h;
    const bool want = lanes_any(xi, yi, hi, xj, yj, hj, lane_d, radius2, uniform, cut2);
    const bool got = uniform ? sphc::tile_row_any2_cut<2>(xi, yi, nullptr, xj, yj, nullptr, kJlane,
                                                          kIlane, lane_d, cut2)
                             : sphc::tile_row_any2<2>(xi, yi, nullptr, hi, xj, yj, nullptr, hj,
                                                      kJlane, kIlane, lane_d, radius2);
    ASSERT_EQ(want, got) << "trial " << trial;
    (want ? yes : no) += 1;
  }
  // both answers are common (the test tells them apart)
  EXPECT_GT(yes, 10000);
  EXPECT_GT(no, 10000);
  EXPECT_GT(edge, 10000);
}

}  // namespace
#else
TEST(TileRow2, SkippedWithoutAvx512) { GTEST_SKIP() << "needs AVX-512F"; }
#endif
