// Physical sanity limits of a run (sphc/sanity.h): bounds, the check of one limit (counts,
// the worst particle), speed, the default bounding box and --limit settings.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "sphc/sanity.h"

namespace sphc {
namespace {

ParticleArray make_fluid() {
  ParticleArray a;
  a.name = "fluid";
  for (const char* p : {"x", "y", "rho", "u", "v"}) a.add_property(p);
  a.resize(4);
  const double x[4] = {0, 1, 2, 3}, rho[4] = {1000, 1050, 700, 2500};
  const double u[4] = {0, 3, 0, -30}, v[4] = {0, 4, 0, 40};
  for (int i = 0; i < 4; ++i) {
    a.f64("x")[i] = x[i];
    a.f64("y")[i] = 0.5 * x[i];
    a.f64("rho")[i] = rho[i];
    a.f64("u")[i] = u[i];
    a.f64("v")[i] = v[i];
  }
  return a;
}

TEST(Sanity, Bounds) {
  const Bounds b{-1, 2};
  EXPECT_TRUE(b.contains(-1));
  EXPECT_TRUE(b.contains(2));
  EXPECT_FALSE(b.contains(2.5));
  EXPECT_DOUBLE_EQ(b.excess(2.5), 0.5);
  EXPECT_DOUBLE_EQ(b.excess(-3), 2);
  EXPECT_DOUBLE_EQ(b.excess(0), 0);
  EXPECT_TRUE(std::isinf(b.excess(NAN)));  // NaN is outside any bound
  EXPECT_EQ(b.text(), "[-1, 2]");
  EXPECT_EQ((Bounds{-HUGE_VAL, 60}.text()), "<= 60");
  EXPECT_EQ((Bounds{0, HUGE_VAL}.text()), ">= 0");
}

TEST(Sanity, CheckCountsAndNamesTheWorstParticle) {
  const ParticleArray a = make_fluid();
  Limit rho{"fluid", "rho", "s.sph:3", Bounds{900, 1100}, Bounds{500, 2000}};
  const LimitCheck c = check_limit(rho, a, 2);
  EXPECT_EQ(c.outside_warn, 2u);  // 700 and 2500
  EXPECT_EQ(c.outside_stop, 1u);  // 2500
  EXPECT_EQ(c.worst, 3u);         // the one past the stop bound
  EXPECT_DOUBLE_EQ(c.value, 2500);
  EXPECT_DOUBLE_EQ(c.excess, 500);
  EXPECT_EQ(describe_particle(a, c.worst, 2, "rho", c.value),
            "particle 3 of array 'fluid' at (3, 1.5) has rho = 2500");
  // Warn only: the worst of the warn bound (700 is 200 below, 2500 1400 above).
  rho.stop.reset();
  const LimitCheck w = check_limit(rho, a, 2);
  EXPECT_EQ(w.outside_stop, 0u);
  EXPECT_EQ(w.worst, 3u);
  EXPECT_DOUBLE_EQ(w.excess, 1400);
}

// A limit's remove: the particles outside the remove bound where the condition on another
// coordinate holds (x = 0, 1, 2, 3 at y = 0, 0.5, 1, 1.5).
TEST(Sanity, RemovalMaskOutsideTheBoundWhereTheConditionHolds) {
  ParticleArray a = make_fluid();
  Limit x{"fluid", "x", "s.sph:4", std::nullopt, Bounds{-1, 2.5}};
  EXPECT_TRUE(removal_mask(x, a, 2).empty());  // no remove bound: nothing
  x.remove = Bounds{0.5, 2.5};
  EXPECT_EQ(removal_mask(x, a, 2), (std::vector<std::uint8_t>{1, 0, 0, 1}));  // every height
  EXPECT_EQ(x.remove_text(), "outside [0.5, 2.5]");
  x.remove_where = "y";
  x.where_bounds = Bounds{1.0, HUGE_VAL};  // above y = 1 only: x = 0 (y = 0) stays
  EXPECT_EQ(removal_mask(x, a, 2), (std::vector<std::uint8_t>{0, 0, 0, 1}));
  EXPECT_EQ(x.remove_text(), "outside [0.5, 2.5] where y >= 1");
  x.where_bounds = Bounds{-1, 0.25};
  EXPECT_EQ(x.remove_text(), "outside [0.5, 2.5] where y in [-1, 0.25]");
  EXPECT_EQ(removal_mask(x, a, 2), (std::vector<std::uint8_t>{1, 0, 0, 0}));
  // NaN in the quantity or the condition: not removed (the NaN check names it).
  a.f64("x")[0] = NAN;
  a.f64("y")[3] = NAN;
  x.where_bounds = Bounds{};
  EXPECT_TRUE(removal_mask(x, a, 2).empty());
  // Removing keeps the others in order.
  a.f64("x")[0] = -5;
  const auto mask = removal_mask(x, a, 2);
  EXPECT_EQ(mask, (std::vector<std::uint8_t>{1, 0, 0, 0}));
  EXPECT_EQ(a.remove_particles(mask), 1u);
  ASSERT_EQ(a.n, 3u);
  EXPECT_DOUBLE_EQ(a.f64("x")[0], 1);
  EXPECT_DOUBLE_EQ(a.f64("rho")[2], 2500);
  // A condition on a coordinate the array lacks is an error naming the limit.
  x.remove_where = "z";
  EXPECT_THROW(removal_mask(x, a, 2), std::runtime_error);
}

TEST(Sanity, SpeedIsTheVelocityMagnitude) {
  const ParticleArray a = make_fluid();
  const Limit speed{"fluid", "speed", "", Bounds{-HUGE_VAL, 4.9}, Bounds{-HUGE_VAL, 49}};
  const LimitCheck c = check_limit(speed, a, 2);
  EXPECT_EQ(c.outside_warn, 2u);  // |(3, 4)| = 5 and |(-30, 40)| = 50
  EXPECT_EQ(c.outside_stop, 1u);
  EXPECT_DOUBLE_EQ(c.value, 50);
  // In 1D only u counts.
  EXPECT_EQ(check_limit(speed, a, 1).outside_stop, 0u);
}

TEST(Sanity, AMissingQuantityIsAnErrorNamingTheLimit) {
  const ParticleArray a = make_fluid();
  const Limit p{"fluid", "p", "s.sph:7", Bounds{0, 1}, std::nullopt};
  try {
    check_limit(p, a, 2);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "limit 'fluid.p' (s.sph:7): array 'fluid' has no property 'p'");
  }
}

TEST(Sanity, DefaultBoxAroundTheSetUp) {
  ParticleArray a = make_fluid();  // x in [0, 3], y in [0, 1.5]: largest side 3
  ParticleArray empty;
  empty.name = "none";
  empty.add_property("x");
  const std::vector<Limit> box = bounding_box_limits({&a, &empty}, 2, 1.0, 10.0);
  ASSERT_EQ(box.size(), 2u);  // x and y of fluid; nothing for the empty array
  EXPECT_EQ(box[0].name(), "fluid.x");
  EXPECT_DOUBLE_EQ(box[0].warn->lo, -3);
  EXPECT_DOUBLE_EQ(box[0].warn->hi, 6);
  EXPECT_DOUBLE_EQ(box[0].stop->lo, -30);
  EXPECT_DOUBLE_EQ(box[1].warn->hi, 4.5);
  // A particle thrown 40 sides away is past the stop bound.
  a.f64("y")[2] = 1.5 + 40 * 3;
  EXPECT_EQ(check_limit(box[1], a, 2).outside_stop, 1u);
}

TEST(Sanity, CommandLineSettings) {
  std::vector<Limit> limits = {
      Limit{"fluid", "rho", "s.sph:3", Bounds{900, 1100}, Bounds{500, 2000}}};
  apply_limit_setting(limits, "fluid.rho.stop=400:");
  EXPECT_DOUBLE_EQ(limits[0].stop->lo, 400);
  EXPECT_TRUE(std::isinf(limits[0].stop->hi));
  EXPECT_EQ(limits[0].where, "--limit");
  apply_limit_setting(limits, "fluid.rho.warn=off");
  EXPECT_FALSE(limits[0].warn);
  apply_limit_setting(limits, "wall.speed.warn=:3.5");
  ASSERT_EQ(limits.size(), 2u);
  EXPECT_EQ(limits[1].name(), "wall.speed");
  EXPECT_DOUBLE_EQ(limits[1].warn->hi, 3.5);
  EXPECT_FALSE(limits[1].stop);
  for (const char* bad : {"fluid.rho=1:2", "fluid.rho.both=1:2", "fluid.rho.stop=1",
                          "fluid.rho.stop=a:2", "fluid.rho.stop=3:2", ".rho.stop=1:2"})
    EXPECT_THROW(apply_limit_setting(limits, bad), std::invalid_argument) << bad;
}

}  // namespace
}  // namespace sphc
