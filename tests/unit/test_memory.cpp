// The memory estimate of a run (sphc/memory.h): particle counts without building the
// particles, bytes per particle from the declared properties, the items and the total.
#include <gtest/gtest.h>

#include <cmath>

#include "sphc/geometry.h"
#include "sphc/memory.h"
#include "sphc/particle_array.h"

namespace sphc {
namespace {

// The count a builder gives inside a CountingPass (through the resize of an array), against
// the size of the points it builds outside one.
template <class Build>
void expect_counted_as_built(Build build) {
  const std::size_t built = build().size();
  ParticleArray a;
  a.name = "a";
  std::size_t planned = 0;
  {
    CountingPass pass;
    const Points none = build();
    EXPECT_EQ(none.size(), 0u);  // nothing made
    a.resize(none.size());
    planned = pass.planned(a);
  }
  EXPECT_EQ(planned, built);
  EXPECT_FALSE(counting_particles());
}

TEST(Memory, CountingPassCountsWhatTheBuildersWouldMake) {
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 2, 0.5};
  for (int dim = 1; dim <= 3; ++dim) {
    expect_counted_as_built([&] { return block(dim, lo, hi, 0.03); });
    expect_counted_as_built([&] { return tank(dim, lo, hi, 0.03, 3, false); });
    expect_counted_as_built([&] { return tank(dim, lo, hi, 0.07, 2, true); });
  }
  expect_counted_as_built([] { return disk(0.1, 0.2, 0.5, 0.01); });
  expect_counted_as_built([] { return disk(0, 0, 0.3, 0.1); });  // points on the circle
  expect_counted_as_built([] { return sphere(0, 0, 0, 0.25, 0.05); });
  expect_counted_as_built([] { return cylinder(0, 0, 0.2, -0.1, 0.3, 0.04); });
  const double p0[3] = {0, 0, 0}, p1[3] = {1, 1, 0};
  expect_counted_as_built([&] { return line(p0, p1, 0.01); });
  expect_counted_as_built([&] { return line(p0, p0, 0.01); });
}

TEST(Memory, CountingPassAddsPointsToTheNextResizeOnly) {
  ParticleArray a, b;
  CountingPass pass;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 0};
  block(2, lo, hi, 0.1);  // 100 points
  block(2, lo, hi, 0.5);  // 4 more
  a.resize(3);            // and 3 loaded from a file
  b.resize(0);
  EXPECT_EQ(pass.planned(a), 107u);
  EXPECT_EQ(a.n, 3u);  // only the real ones exist
  EXPECT_EQ(pass.planned(b), 0u);
}

TEST(Memory, TankOfATinySpacingIsCountedByItsWallsNotItsBox) {
  // The dam break's tank at dx = 1e-4: 1.6e9 lattice points in its box, 360,018 in its
  // walls. Only the walls are made, so the builder accepts it.
  const double lo[3] = {0, 0, 0}, hi[3] = {4, 4, 0};
  ParticleArray a;
  CountingPass pass;
  EXPECT_EQ(tank(2, lo, hi, 1e-4, 3, false).size(), 0u);
  a.resize(0);
  EXPECT_EQ(pass.planned(a), 3u * 40000 * 2 + 3u * 40006);
}

TEST(Memory, FootprintFromTheProperties) {
  ParticleArray a;
  a.name = "fluid";
  a.add_property("x");
  a.add_property("L", PropType::F64, 9);
  a.add_property("tag", PropType::I32);
  a.add_property("gid", PropType::U32);
  const ArrayFootprint f = footprint(a, 1000);
  EXPECT_EQ(f.particles, 1000u);
  EXPECT_DOUBLE_EQ(f.bytes_per_particle, 8 + 72 + 4 + 4);
  EXPECT_DOUBLE_EQ(f.doubles_per_particle, 10);
  EXPECT_DOUBLE_EQ(f.largest_property_bytes, 72);
}

TEST(Memory, EstimateItemsAndTotal) {
  ArrayFootprint fluid{"fluid", 2'000'000, 296, 37, 72};
  ArrayFootprint wall{"wall", 100'000, 88, 11, 8};
  const MemoryEstimate d = estimate_memory({fluid, wall}, false);
  double data = 2e6 * 296 + 1e5 * 88;
  double search = 2.1e6 * kSearchBytesPerParticle;
  double scratch = 2e6 * 72;  // the fluid's 9-vector, reordered through one buffer
  double points = 2e6 * 24;
  EXPECT_DOUBLE_EQ(d.total, (data + search + scratch + points) * (1 + kMarginFraction));
  // Float copies (--precision=single): 4 B per double value.
  const MemoryEstimate s = estimate_memory({fluid, wall}, true);
  EXPECT_DOUBLE_EQ(s.total - d.total, (2e6 * 37 + 1e5 * 11) * 4 * (1 + kMarginFraction));
  // The description names the items, largest first.
  const std::string text = d.describe();
  EXPECT_EQ(text.find("particle data of array 'fluid' (2,000,000 particles x 296 B) 565 MB"),
            0u)
      << text;
  EXPECT_NE(text.find("cell lists of the neighbour search"), std::string::npos);
}

TEST(Memory, SizesAndTheirText) {
  EXPECT_EQ(parse_memory_size("2G"), 2.0 * 1024 * 1024 * 1024);
  EXPECT_EQ(parse_memory_size("1.5GB"), 1.5 * 1024 * 1024 * 1024);
  EXPECT_EQ(parse_memory_size("500M"), 500.0 * 1024 * 1024);
  EXPECT_EQ(parse_memory_size("64k"), 64.0 * 1024);
  EXPECT_EQ(parse_memory_size("1e9"), 1e9);
  EXPECT_FALSE(parse_memory_size(""));
  EXPECT_FALSE(parse_memory_size("-1G"));
  EXPECT_FALSE(parse_memory_size("2X"));
  EXPECT_FALSE(parse_memory_size("2GiB"));
  EXPECT_FALSE(parse_memory_size("G"));
  EXPECT_EQ(format_bytes(780), "780 B");
  EXPECT_EQ(format_bytes(1536), "1.5 kB");
  EXPECT_EQ(format_bytes(88.6 * 1024 * 1024 * 1024), "88.6 GB");
  // This machine's memory: some, and finite.
  const auto avail = available_memory();
  ASSERT_TRUE(avail);
  EXPECT_GT(*avail, 0);
  EXPECT_TRUE(std::isfinite(*avail));
}

}  // namespace
}  // namespace sphc
