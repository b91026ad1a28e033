// Unit tests of the neighbour lists kept across steps (runtime/include/sphc/verlet.h,
// sphc --verlet-skin): while VerletSkin::must_rebuild says no, the lists built within
// (1 + F) times the support hold every pair within the support now; filter_neighbours keeps
// the candidates that pass the test, in their order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "sphc/particle_array.h"
#include "sphc/verlet.h"

#include "random_particles.h"

namespace {

using sphc::ParticleArray;
using sphc::VerletSkin;
using sphc_test::random_array;

constexpr double kRadiusScale = 2.0;

// The pairs (i, j) with |x_i - x_j| < scale * radius_scale * max(h_i, h_j), per i.
std::vector<std::vector<std::uint32_t>> lists(const ParticleArray& pa, double scale) {
  const double *x = pa.f64("x"), *y = pa.f64("y"), *z = pa.f64("z"), *h = pa.f64("h");
  std::vector<std::vector<std::uint32_t>> out(pa.n);
  for (std::size_t i = 0; i < pa.n; ++i)
    for (std::size_t j = 0; j < pa.n; ++j) {
      const double dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
      const double r = scale * kRadiusScale * std::max(h[i], h[j]);
      if (dx * dx + dy * dy + dz * dz < r * r) out[i].push_back(static_cast<std::uint32_t>(j));
    }
  return out;
}

TEST(VerletSkin, ListsStayCompleteUntilARebuildIsDue) {
  const double skin = 0.15, h0 = 0.1;
  ParticleArray pa = random_array(300, 3, 1.0, h0, 7, 0.8, 1.2);
  std::vector<const ParticleArray*> all = {&pa};
  VerletSkin verlet(skin);
  EXPECT_TRUE(verlet.must_rebuild(all, kRadiusScale));  // never built
  std::mt19937_64 rng(11);
  std::normal_distribution<double> step(0.0, 0.002 * h0);
  std::uniform_real_distribution<double> grow(0.0, 0.002 * h0);
  int rebuilds = 0, checked = 0;
  std::vector<std::vector<std::uint32_t>> kept;
  for (int s = 0; s < 200; ++s) {
    if (verlet.must_rebuild(all, kRadiusScale)) {
      kept = lists(pa, 1.0 + skin);
      verlet.mark(all);
      ++rebuilds;
      EXPECT_FALSE(verlet.must_rebuild(all, kRadiusScale));
    }
    // Every pair within the support now is in the kept lists.
    const auto now = lists(pa, 1.0);
    for (std::size_t i = 0; i < pa.n; ++i)
      for (std::uint32_t j : now[i]) {
        ASSERT_TRUE(std::find(kept[i].begin(), kept[i].end(), j) != kept[i].end())
            << "step " << s << ": pair " << i << ", " << j << " missing";
        ++checked;
      }
    for (std::size_t i = 0; i < pa.n; ++i) {
      pa.f64("x")[i] += step(rng);
      pa.f64("y")[i] += step(rng);
      pa.f64("z")[i] += step(rng);
      pa.f64("h")[i] += grow(rng);
    }
  }
  EXPECT_GT(rebuilds, 2);    // the particles moved past the skin several times
  EXPECT_LT(rebuilds, 100);  // and the lists were kept over several steps
  EXPECT_GT(checked, 10000);
}

TEST(VerletSkin, CountChangeAndNaNForceARebuild) {
  ParticleArray pa = random_array(50, 3, 1.0, 0.1, 3, 0.8, 1.2);
  std::vector<const ParticleArray*> all = {&pa};
  VerletSkin verlet(0.1);
  verlet.mark(all);
  EXPECT_FALSE(verlet.must_rebuild(all, kRadiusScale));
  pa.f64("x")[5] = std::nan("");
  EXPECT_TRUE(verlet.must_rebuild(all, kRadiusScale));
  verlet.mark(all);
  pa.f64("x")[5] = 0.5;
  EXPECT_TRUE(verlet.must_rebuild(all, kRadiusScale));
  verlet.mark(all);
  EXPECT_FALSE(verlet.must_rebuild(all, kRadiusScale));
  pa.resize(49);
  EXPECT_TRUE(verlet.must_rebuild(all, kRadiusScale));
  ParticleArray other = random_array(10, 3, 1.0, 0.1, 4, 0.8, 1.2);
  verlet.mark(all);
  std::vector<const ParticleArray*> two = {&pa, &other};
  EXPECT_TRUE(verlet.must_rebuild(two, kRadiusScale));  // another set of arrays
}

TEST(VerletSkin, FilterKeepsTheCandidatesThatPassInOrder) {
  const std::vector<std::uint32_t> cand = {9, 4, 7, 1, 8, 2, 6};
  std::vector<std::uint32_t> out;
  const std::size_t n = sphc::filter_neighbours(cand.data(), cand.size(), out,
                                                [](std::uint32_t j) { return j % 2 == 0; });
  ASSERT_EQ(n, 4u);
  EXPECT_EQ(std::vector<std::uint32_t>(out.begin(), out.begin() + n),
            (std::vector<std::uint32_t>{4, 8, 2, 6}));
  EXPECT_EQ(sphc::filter_neighbours(cand.data(), 0, out, [](std::uint32_t) { return true; }),
            0u);
}

// The kept list is in increasing index whatever the candidates' order (two builds from
// other cells, other candidate orders, give the same list), and its size is the count.
TEST(VerletSkin, KeptListsAreInIncreasingIndex) {
  const std::vector<std::uint32_t> a = {9, 4, 7, 1, 8, 2, 6, 99, 3};
  const std::vector<std::uint32_t> b = {3, 99, 1, 2, 4, 6, 7, 8, 9};
  std::vector<std::uint32_t> ka = {5, 5, 5, 5, 5, 5, 5, 5, 5, 5, 5, 5}, kb;
  sphc::keep_in_index_order(ka, a.data(), a.size());
  sphc::keep_in_index_order(kb, b.data(), b.size());
  EXPECT_EQ(ka, (std::vector<std::uint32_t>{1, 2, 3, 4, 6, 7, 8, 9, 99}));
  EXPECT_EQ(ka, kb);
  sphc::keep_in_index_order(ka, a.data(), 0);
  EXPECT_TRUE(ka.empty());
}

}  // namespace
