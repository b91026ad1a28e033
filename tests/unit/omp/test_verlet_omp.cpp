// The displacement check of the kept neighbour lists (VerletSkin::must_rebuild,
// runtime/include/sphc/verlet.h) on OpenMP threads: from 16,384 particles its max reduction
// runs in parallel; its answer and what it measured (last_moved) must be those of a plain
// loop bit for bit, with 1, 2 and 3 threads: particles moved, h grown and shrunk (a
// negative growth counts as none), an array without z, and a NaN in the last particle.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "../kept_lists_checks.h"
#include "../random_particles.h"
#include "sphc/cross_pairs.h"
#include "sphc/particle_array.h"
#include "sphc/verlet.h"

namespace {

using sphc::ParticleArray;
using sphc::VerletSkin;

constexpr double kRadiusScale = 2.0;

class OmpVerlet : public ::testing::Test {
 protected:
  void TearDown() override { omp_set_num_threads(saved_); }
  int saved_ = omp_get_max_threads();
};

// 2 max |dx| + radius_scale max(0, max dh) over the arrays, in particle order (the check's
// serial form); x0.. are the marked values.
struct Marked {
  std::vector<double> x, y, z, h;
};
Marked marked(const ParticleArray& pa) {
  auto copy = [&](const char* p) {
    const double* v = pa.f64(p);
    return v ? std::vector<double>(v, v + pa.n) : std::vector<double>(pa.n, 0.0);
  };
  return {copy("x"), copy("y"), pa.find("z") >= 0 ? copy("z") : std::vector<double>(pa.n, 0.0),
          copy("h")};
}
double reference_moved(const std::vector<std::pair<const ParticleArray*, const Marked*>>& arrays) {
  double d2max = 0.0, growth = 0.0;
  for (const auto& [pa, m] : arrays) {
    const bool has_z = pa->find("z") >= 0;
    for (std::size_t i = 0; i < pa->n; ++i) {
      const double dx = pa->f64("x")[i] - m->x[i], dy = pa->f64("y")[i] - m->y[i];
      const double dz = (has_z ? pa->f64("z")[i] : 0.0) - m->z[i];
      const double d2 = dx * dx + dy * dy + dz * dz;
      const double dh = pa->f64("h")[i] - m->h[i];
      d2max = d2 > d2max ? d2 : d2max;
      growth = dh > growth ? dh : growth;
    }
  }
  return 2.0 * std::sqrt(d2max) + kRadiusScale * growth;
}

void perturb(ParticleArray& pa, unsigned seed, double dx, double dh_lo, double dh_hi) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> step(0.0, dx);
  std::uniform_real_distribution<double> dh(dh_lo, dh_hi);
  const bool has_z = pa.find("z") >= 0;
  for (std::size_t i = 0; i < pa.n; ++i) {
    pa.f64("x")[i] += step(rng);
    pa.f64("y")[i] += step(rng);
    if (has_z) pa.f64("z")[i] += step(rng);
    pa.f64("h")[i] += dh(rng);
  }
}

TEST_F(OmpVerlet, DisplacementCheckEqualsThePlainLoop) {
  const std::size_t n = 40000;  // above the parallel threshold (16,384)
  ParticleArray moved3d = sphc_test::random_array(n, 3, 1.0, 0.01, 5, 0.8, 1.2);
  ParticleArray moved2d;  // no z property
  moved2d.name = "walls";
  moved2d.resize(n);
  for (const char* p : {"x", "y", "h"}) moved2d.add_property(p);
  {
    const ParticleArray src = sphc_test::random_array(n, 2, 1.0, 0.01, 6, 0.8, 1.2);
    for (const char* p : {"x", "y", "h"})
      for (std::size_t i = 0; i < n; ++i) moved2d.f64(p)[i] = src.f64(p)[i];
  }
  for (int threads : {1, 2, 3}) {
    omp_set_num_threads(threads);
    for (int trial = 0; trial < 4; ++trial) {
      ParticleArray a = moved3d, b = moved2d;
      const std::vector<const ParticleArray*> one = {&a}, both = {&a, &b};
      for (const auto* arrays : {&one, &both}) {
        VerletSkin skin(0.1);
        skin.mark(*arrays);
        const Marked ma = marked(a), mb = marked(b);
        // trial 0: h only shrinks (growth 0, some dh = -0.0 where unchanged); 1: h grows;
        // 2, 3: larger moves (a rebuild due).
        const double dx = trial < 2 ? 1e-5 : 1e-3;
        const double lo = trial == 0 ? -1e-6 : 0.0, hi = trial == 0 ? 0.0 : 1e-6;
        perturb(a, 100 + trial, dx, lo, hi);
        if (arrays == &both) perturb(b, 200 + trial, dx, lo, hi);
        const double expect =
            arrays == &one ? reference_moved({{&a, &ma}}) : reference_moved({{&a, &ma}, {&b, &mb}});
        const bool due = skin.must_rebuild(*arrays, kRadiusScale);
        EXPECT_EQ(skin.last_moved(), expect) << threads << " threads, trial " << trial;
        EXPECT_EQ(due, !(expect <= 0.1 * kRadiusScale * skin.hmin()));
        if (trial == 0) EXPECT_FALSE(due);
        if (trial >= 2) EXPECT_TRUE(due);
        // A NaN in the last particle: a rebuild, nothing measured.
        a.f64("x")[n - 1] = std::nan("");
        EXPECT_TRUE(skin.must_rebuild(*arrays, kRadiusScale));
        EXPECT_EQ(skin.last_moved(), -1.0);
        a.f64("x")[n - 1] = ma.x[n - 1];
      }
    }
  }
}

// KeptLists built by threads, as the generated loops build them (each particle's list kept
// by the thread that has it, in a static schedule or, for the general case, a dynamic one),
// holds the lists of the builder it replaced element for element, with 1 to 4 threads; and
// CrossSources built from it in blocks on threads gives the arrays of the serial build.
TEST_F(OmpVerlet, ContiguousKeptListsOnThreadsAreThoseOfTheListPerParticle) {
  const std::size_t n = 20000;
  const auto cand = sphc_test::random_candidates(n, 3000, 9);
  const auto want = sphc_test::old_lists(cand, 0, n);
  std::vector<std::vector<std::uint32_t>> by_list(n);  // the candidates as a list per particle
  for (std::size_t i = 0; i < n; ++i) by_list[i] = want[i];
  sphc::CrossSources serial;
  serial.build(by_list, 3000);
  for (int threads = 1; threads <= 4; ++threads) {
    omp_set_num_threads(threads);
    for (bool dynamic : {false, true}) {
      sphc::KeptLists kl;
      for (int build = 0; build < 2; ++build) {  // twice: the storage reused
        kl.start_build(n, omp_get_max_threads());
        const long nl = static_cast<long>(n);
        if (!dynamic) {
#pragma omp parallel for schedule(static)
          for (long i = 0; i < nl; ++i)
            kl.keep(omp_get_thread_num(), static_cast<std::uint32_t>(i), cand[i].data(), cand[i].size());
        } else {
#pragma omp parallel for schedule(dynamic, 7)
          for (long i = 0; i < nl; ++i)
            kl.keep(omp_get_thread_num(), static_cast<std::uint32_t>(i), cand[i].data(), cand[i].size());
        }
        kl.finish_build();
        SCOPED_TRACE(std::to_string(threads) + (dynamic ? " threads, dynamic" : " threads, static"));
        sphc_test::expect_same_lists(kl, want);
      }
      sphc::CrossSources cs;
      cs.build(kl, 3000, omp_get_max_threads());
      EXPECT_EQ(cs.starts, serial.starts);
      EXPECT_EQ(cs.dests, serial.dests);
      EXPECT_EQ(cs.first, serial.first);
      EXPECT_EQ(cs.last, serial.last);
    }
  }
}

}  // namespace
