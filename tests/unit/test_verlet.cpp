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
#include "sphc/verlet_tune.h"

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

// Lists up to kInsertionSortMax are sorted by insertion, longer ones by std::sort: both give
// the increasing order of std::sort, for lists sorted, in ascending runs (as the cells give
// them), reversed and shuffled, of every length around the switch.
// find_occupied (stop 45): the destinations of [begin, end) with a candidate, in increasing
// index; those outside the range and those with empty lists left out, found again after a
// build (the flag cleared, the lists changed).
TEST(VerletLists, OccupiedAreTheDestinationsWithACandidateInTheRange) {
  sphc::VerletLists v(0.1);
  v.lists.resize(8);
  v.lists[0] = {3};
  v.lists[2] = {1, 5};
  v.lists[5] = {0};
  v.lists[7] = {2};
  v.begin = 1;
  v.end = 7;
  EXPECT_FALSE(v.occupied_found);
  sphc::find_occupied(v);
  EXPECT_TRUE(v.occupied_found);
  EXPECT_EQ(v.occupied, (std::vector<std::uint32_t>{2, 5}));
  v.lists[2].clear();
  v.lists[3] = {4};
  v.begin = 0;
  v.end = 8;
  v.occupied_found = false;
  sphc::find_occupied(v);
  EXPECT_EQ(v.occupied, (std::vector<std::uint32_t>{0, 3, 5, 7}));
  for (auto& l : v.lists) l.clear();
  sphc::find_occupied(v);
  EXPECT_TRUE(v.occupied.empty());
  EXPECT_TRUE(v.occupied_found);
}

TEST(VerletSkin, KeptListsByInsertionAreThoseOfStdSort) {
  std::mt19937_64 rng(5);
  for (std::size_t n = 0; n <= 2 * sphc::kInsertionSortMax + 5; ++n) {
    std::vector<std::uint32_t> ids(4 * n + 1);
    for (std::size_t k = 0; k < ids.size(); ++k) ids[k] = static_cast<std::uint32_t>(3 * k + 1);
    std::shuffle(ids.begin(), ids.end(), rng);
    std::vector<std::uint32_t> cand(ids.begin(), ids.begin() + n), want = cand;
    std::sort(want.begin(), want.end());
    std::vector<std::vector<std::uint32_t>> forms = {cand, want, {want.rbegin(), want.rend()}};
    std::vector<std::uint32_t> runs = want;  // three ascending runs, the last first
    std::rotate(runs.begin(), runs.begin() + static_cast<long>(2 * n / 3), runs.end());
    std::rotate(runs.begin(), runs.begin() + static_cast<long>(n / 3), runs.end());
    forms.push_back(runs);
    for (const auto& f : forms) {
      std::vector<std::uint32_t> kept = {7, 7, 7};
      sphc::keep_in_index_order(kept, f.data(), f.size());
      EXPECT_EQ(kept, want) << "n = " << n;
    }
  }
}

// must_rebuild's loop per set of axes (1D x; 2D x, y; 3D x, y, z) answers as the loop over
// x, y and z with a missing axis read as 0 did, and measures the same displacement bit for
// bit (last_moved): arrays without z (2D) or without y and z (1D), displacements around the
// threshold, h growing, NaN.
TEST(VerletSkin, DisplacementCheckPerAxisSetIsTheGenericOne) {
  const double skin = 0.1, h0 = 0.1;
  for (int dim = 1; dim <= 3; ++dim) {
    ParticleArray pa;
    pa.name = "fluid";
    pa.resize(400);
    const char* axes[3] = {"x", "y", "z"};
    for (int k = 0; k < dim; ++k) pa.add_property(axes[k]);
    pa.add_property("h");
    std::mt19937_64 rng(17 + dim);
    std::uniform_real_distribution<double> pos(0.0, 1.0), hs(0.9 * h0, 1.1 * h0);
    for (std::size_t i = 0; i < pa.n; ++i) {
      for (int k = 0; k < dim; ++k) pa.f64(axes[k])[i] = pos(rng);
      pa.f64("h")[i] = hs(rng);
    }
    std::vector<const ParticleArray*> all = {&pa};
    VerletSkin verlet(skin);
    verlet.mark(all);
    std::vector<std::vector<double>> saved;
    for (int k = 0; k < dim; ++k)
      saved.emplace_back(pa.f64(axes[k]), pa.f64(axes[k]) + pa.n);
    const std::vector<double> hsaved(pa.f64("h"), pa.f64("h") + pa.n);
    int yes = 0, no = 0;
    for (int trial = 0; trial < 200; ++trial) {
      // From the marked positions, a few particles moved by up to ~2x the threshold
      // (a rebuild where 2 |d| > 0.1 * 2 * h_min, h_min >= 0.9 h0).
      for (int k = 0; k < dim; ++k) std::copy(saved[k].begin(), saved[k].end(), pa.f64(axes[k]));
      std::copy(hsaved.begin(), hsaved.end(), pa.f64("h"));
      const double dmax = 0.1 * h0 / std::sqrt(static_cast<double>(dim));
      std::uniform_real_distribution<double> d(-dmax, dmax);
      std::uniform_int_distribution<std::size_t> who(0, pa.n - 1);
      for (int m = 0; m < 3; ++m) {
        const std::size_t i = who(rng);
        for (int k = 0; k < dim; ++k) pa.f64(axes[k])[i] += d(rng);
        if (trial % 7 == 0) pa.f64("h")[i] += 0.004 * h0;
      }
      // The generic loop (missing axes 0, as mark() saved them).
      double d2m = 0.0, gm = 0.0;
      for (std::size_t i = 0; i < pa.n; ++i) {
        double c[3] = {0.0, 0.0, 0.0};
        for (int k = 0; k < dim; ++k) c[k] = pa.f64(axes[k])[i] - saved[k][i];
        const double d2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
        const double dh = pa.f64("h")[i] - hsaved[i];
        d2m = d2 > d2m ? d2 : d2m;
        gm = dh > gm ? dh : gm;
      }
      const double moved = 2.0 * std::sqrt(d2m) + kRadiusScale * gm;
      const bool want = !(moved <= skin * kRadiusScale * verlet.hmin());
      EXPECT_EQ(verlet.must_rebuild(all, kRadiusScale), want) << "dim " << dim;
      EXPECT_EQ(verlet.last_moved(), moved) << "dim " << dim;
      (want ? yes : no) += 1;
    }
    EXPECT_GT(yes, 0) << "dim " << dim;  // both answers met
    EXPECT_GT(no, 0) << "dim " << dim;
    verlet.mark(all);  // NaN in the last axis, then in h, each alone forces a rebuild
    EXPECT_FALSE(verlet.must_rebuild(all, kRadiusScale));
    const double x3 = pa.f64(axes[dim - 1])[3];
    pa.f64(axes[dim - 1])[3] = std::nan("");
    EXPECT_TRUE(verlet.must_rebuild(all, kRadiusScale));
    pa.f64(axes[dim - 1])[3] = x3;
    EXPECT_FALSE(verlet.must_rebuild(all, kRadiusScale));
    pa.f64("h")[5] = std::nan("");
    EXPECT_TRUE(verlet.must_rebuild(all, kRadiusScale));
  }
}

// VerletSkin's h_fixed (stop 46: the compiler passes it where nothing writes h): while h is
// what it was at mark(), a skin that reads no h answers as one that does, bit for bit
// (last_moved() too), in 1D, 2D and 3D; a NaN among h at mark() forces every rebuild, as a
// NaN growth does.
TEST(VerletSkin, HFixedAnswersAsTheCheckThatReadsH) {
  const double skin = 0.1, h0 = 0.1;
  for (int dim = 1; dim <= 3; ++dim) {
    ParticleArray pa;
    pa.name = "fluid";
    pa.resize(500);
    const char* axes[3] = {"x", "y", "z"};
    for (int k = 0; k < dim; ++k) pa.add_property(axes[k]);
    pa.add_property("h", sphc::PropType::F64, 1, h0);
    std::mt19937_64 rng(29 + dim);
    std::uniform_real_distribution<double> pos(0.0, 1.0);
    for (std::size_t i = 0; i < pa.n; ++i)
      for (int k = 0; k < dim; ++k) pa.f64(axes[k])[i] = pos(rng);
    std::vector<const ParticleArray*> all = {&pa};
    VerletSkin reads(skin), fixed(skin, true);
    EXPECT_FALSE(reads.h_fixed());
    EXPECT_TRUE(fixed.h_fixed());
    reads.mark(all);
    fixed.mark(all);
    const double step = 0.02 * h0;
    std::uniform_real_distribution<double> d(-step, step);
    int yes = 0, no = 0;
    for (int s = 0; s < 100; ++s) {
      for (std::size_t i = 0; i < pa.n; ++i)
        for (int k = 0; k < dim; ++k) pa.f64(axes[k])[i] += d(rng);
      const bool want = reads.must_rebuild(all, kRadiusScale);
      EXPECT_EQ(fixed.must_rebuild(all, kRadiusScale), want) << "dim " << dim << ", step " << s;
      EXPECT_EQ(fixed.last_moved(), reads.last_moved()) << "dim " << dim << ", step " << s;
      (want ? yes : no) += 1;
      if (want) {
        reads.mark(all);
        fixed.mark(all);
      }
    }
    EXPECT_GT(yes, 2) << "dim " << dim;  // both answers met
    EXPECT_GT(no, 10) << "dim " << dim;
    pa.f64("h")[7] = std::nan("");  // a NaN h at the mark: every check says rebuild
    reads.mark(all);
    fixed.mark(all);
    EXPECT_TRUE(reads.must_rebuild(all, kRadiusScale));
    EXPECT_TRUE(fixed.must_rebuild(all, kRadiusScale));
    pa.f64("h")[7] = h0;
    reads.mark(all);
    fixed.mark(all);
    EXPECT_FALSE(fixed.must_rebuild(all, kRadiusScale));
    pa.f64(axes[0])[3] = std::nan("");  // a NaN position, as before
    EXPECT_TRUE(fixed.must_rebuild(all, kRadiusScale));
  }
}

// sphc::PhaseDisplacements: several skins over the same arrays checked and marked within one
// phase (positions unchanged) give the answers and last_moved() of skins without it, bit for
// bit; the skins that marked an array in the phase share one copy, and each array's
// displacement is measured once (the second skin's answer follows a change the scan would
// see only if it scanned: moving a particle between the two checks of one phase, which the
// printer rules out, leaves the second answer at the first's).
TEST(VerletSkin, OneDisplacementScanPerPhaseGivesTheAnswersOfAScanPerCheck) {
  const double skin = 0.1, h0 = 0.1;
  ParticleArray fluid, wall;
  for (ParticleArray* pa : {&fluid, &wall}) {
    pa->resize(pa == &fluid ? 300 : 120);
    for (const char* p : {"x", "y", "h"}) pa->add_property(p);
  }
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> pos(0.0, 1.0), hs(0.9 * h0, 1.1 * h0);
  for (ParticleArray* pa : {&fluid, &wall})
    for (std::size_t i = 0; i < pa->n; ++i) {
      pa->f64("x")[i] = pos(rng);
      pa->f64("y")[i] = pos(rng);
      pa->f64("h")[i] = hs(rng);
    }
  const std::vector<const ParticleArray*> ff = {&fluid}, fw = {&fluid, &wall};
  VerletSkin a(skin), b(skin), a_ref(skin), b_ref(skin);  // b, b_ref over fluid and wall
  {
    sphc::PhaseDisplacements phase;
    a.mark(ff, &phase);
    b.mark(fw, &phase);
    ASSERT_NE(phase.marked(&fluid), nullptr);
    ASSERT_NE(phase.marked(&wall), nullptr);
  }
  a_ref.mark(ff);
  b_ref.mark(fw);
  EXPECT_EQ(a.hmin(), a_ref.hmin());
  EXPECT_EQ(b.hmin(), b_ref.hmin());
  int yes = 0, no = 0;
  std::uniform_int_distribution<std::size_t> who(0, fluid.n - 1);
  std::uniform_real_distribution<double> d(-0.06 * h0, 0.06 * h0);
  for (int phase_no = 0; phase_no < 300; ++phase_no) {
    // Between phases a few particles move, and (now and then) the walls' h grows.
    for (int m = 0; m < 2; ++m) {
      const std::size_t i = who(rng);
      fluid.f64("x")[i] += d(rng);
      fluid.f64("y")[i] += d(rng);
    }
    if (phase_no % 37 == 5) wall.f64("h")[3] += 0.003 * h0;
    sphc::PhaseDisplacements phase;
    const bool ra = a.must_rebuild(ff, kRadiusScale, &phase);
    const bool rb = b.must_rebuild(fw, kRadiusScale, &phase);
    if (phase_no == 0) EXPECT_EQ(phase.scans(), 2u);  // one copy of the fluid: scanned once
    const bool want_a = a_ref.must_rebuild(ff, kRadiusScale);
    const bool want_b = b_ref.must_rebuild(fw, kRadiusScale);
    EXPECT_EQ(ra, want_a) << phase_no;
    EXPECT_EQ(rb, want_b) << phase_no;
    EXPECT_EQ(a.last_moved(), a_ref.last_moved()) << phase_no;
    EXPECT_EQ(b.last_moved(), b_ref.last_moved()) << phase_no;
    if (phase_no % 50 == 17) {  // one array's scan in the phase, reused: a move now is not seen
      const double x0 = fluid.f64("x")[7];
      fluid.f64("x")[7] += 10.0;
      EXPECT_EQ(b.must_rebuild(fw, kRadiusScale, &phase), want_b);
      EXPECT_TRUE(b.must_rebuild(fw, kRadiusScale));  // without the phase: scanned, seen
      fluid.f64("x")[7] = x0;
    }
    (want_a ? yes : no) += 1;
    // Rebuilds as a printed phase does them: each due list marks, sharing the phase's copy.
    if (ra) a.mark(ff, &phase);
    if (rb) b.mark(fw, &phase);
    if (want_a) a_ref.mark(ff);
    if (want_b) b_ref.mark(fw);
  }
  EXPECT_GT(yes, 0);
  EXPECT_GT(no, 0);
}

// A set of axes other than x; x, y; x, y, z (here y alone missing) is scanned by the 3D loop
// with the saved zeros read for the missing axis: the displacement of the loop that read it
// as 0, bit for bit.
TEST(VerletSkin, DisplacementCheckWithAMissingMiddleAxis) {
  ParticleArray pa;
  pa.resize(50);
  for (const char* p : {"x", "z", "h"}) pa.add_property(p);
  for (std::size_t i = 0; i < pa.n; ++i) {
    pa.f64("x")[i] = 0.01 * i;
    pa.f64("z")[i] = 0.02 * i;
    pa.f64("h")[i] = 0.1;
  }
  const std::vector<const ParticleArray*> all = {&pa};
  VerletSkin verlet(0.1);
  verlet.mark(all);
  pa.f64("x")[4] += 0.003;
  pa.f64("z")[4] += 0.004;
  EXPECT_FALSE(verlet.must_rebuild(all, kRadiusScale));
  const double dx = (0.01 * 4 + 0.003) - 0.01 * 4, dz = (0.02 * 4 + 0.004) - 0.02 * 4;
  EXPECT_EQ(verlet.last_moved(), 2.0 * std::sqrt(dx * dx + 0.0 * 0.0 + dz * dz));
  pa.f64("z")[9] += 0.02;  // 2 * 0.02 > 0.1 * 2 * 0.1
  EXPECT_TRUE(verlet.must_rebuild(all, kRadiusScale));
}

// --verlet-skin=auto (sphc/verlet_tune.h): the skin minimises the modelled cost per
// evaluation, (1 + F)^dim (1 + k / F): no F of a fine scan around it costs less.
TEST(SkinTuner, OptimalSkinMinimisesTheModelledCost) {
  for (int dim : {1, 2, 3})
    for (double k : {1e-4, 1e-3, 0.01, 0.05, 0.2, 1.0}) {
      const double f = sphc::SkinTuner::optimal_skin(dim, k);
      auto cost = [&](double F) { return std::pow(1.0 + F, dim) * (1.0 + k / F); };
      ASSERT_GT(f, 0.0);
      for (double F = 1e-3; F < 3.0; F *= 1.01)
        EXPECT_GE(cost(F), cost(f) * (1.0 - 1e-12)) << "dim " << dim << " k " << k << " F " << F;
    }
  EXPECT_EQ(sphc::SkinTuner::optimal_skin(2, 0.0), 0.0);
  // Rebuild / filter cost per candidate: 9 / pi + 1 in 2D, 27 / (4 pi / 3) + 1 in 3D.
  EXPECT_NEAR(sphc::SkinTuner::cost_ratio(2), 3.8648, 1e-4);
  EXPECT_NEAR(sphc::SkinTuner::cost_ratio(3), 7.4458, 1e-4);
}

// Particles of a 3D array that move at a constant speed, with the lists rebuilt when due
// and their skin the tuner's: the skin starts at kStart, then is the model's optimum for the
// measured movement per evaluation (clamped to [kMin, kMax]), larger for faster particles;
// a rebuild after forget() (a sort) measures nothing. Returns the last skin.
double tuned_skin(double speed, int evaluations, int* rebuilds) {
  const double h0 = 0.1;
  ParticleArray pa = random_array(200, 3, 1.0, h0, 5, 0.8, 1.2);
  for (std::size_t i = 0; i < pa.n; ++i) pa.f64("h")[i] = h0;  // one h: h_min = h0
  std::vector<const ParticleArray*> all = {&pa};
  sphc::VerletLists lists(sphc::SkinTuner::kStart);
  sphc::SkinTuner tuner(3);
  EXPECT_EQ(tuner.skin(), sphc::SkinTuner::kStart);
  *rebuilds = 0;
  for (int e = 0; e < evaluations; ++e) {
    if (lists.skin.must_rebuild(all, kRadiusScale)) {
      tuner.rebuilt(lists.skin, kRadiusScale);
      lists.skin.set_skin(tuner.skin());
      lists.skin.mark(all);
      ++*rebuilds;
    }
    for (std::size_t i = 0; i < pa.n; ++i) pa.f64("x")[i] += speed * h0;  // moved 2 speed h0
  }
  // Each measured rebuild saw moved = 2 speed h0 per evaluation over radius_scale h_min =
  // 2 h0: u = speed.
  const double u = speed;
  const double expect = std::min(
      sphc::SkinTuner::kMax,
      std::max(sphc::SkinTuner::kMin,
               sphc::SkinTuner::optimal_skin(3, sphc::SkinTuner::cost_ratio(3) * u)));
  EXPECT_NEAR(tuner.skin(), expect, 1e-6 * expect) << "speed " << speed;
  // A sort (forget) then a rebuild: nothing measured, the skin stays.
  lists.skin.forget();
  EXPECT_TRUE(lists.skin.must_rebuild(all, kRadiusScale));
  const double before = tuner.skin();
  tuner.rebuilt(lists.skin, kRadiusScale);
  EXPECT_EQ(tuner.skin(), before);
  return tuner.skin();
}

TEST(SkinTuner, SkinFollowsTheMeasuredMovement) {
  int slow_rebuilds = 0, fast_rebuilds = 0;
  const double slow = tuned_skin(1e-3, 400, &slow_rebuilds);
  const double fast = tuned_skin(1e-2, 400, &fast_rebuilds);
  EXPECT_LT(slow, sphc::SkinTuner::kStart);  // slow particles: shorter lists
  EXPECT_GT(fast, slow);
  EXPECT_GT(slow_rebuilds, 2);
  EXPECT_GT(fast_rebuilds, slow_rebuilds);
  // Very fast particles hit kMax.
  int n = 0;
  EXPECT_EQ(tuned_skin(0.2, 50, &n), sphc::SkinTuner::kMax);
}

// The lists stay complete when the skin changes from build to build (each set is checked
// against the skin it was built with): random motion with growing h, the skin chosen by the
// tuner at each rebuild, every pair within the support in the kept lists.
TEST(SkinTuner, ListsStayCompleteWhileTheSkinChanges) {
  const double h0 = 0.1;
  ParticleArray pa = random_array(300, 3, 1.0, h0, 9, 0.8, 1.2);
  std::vector<const ParticleArray*> all = {&pa};
  VerletSkin verlet(sphc::SkinTuner::kStart);
  sphc::SkinTuner tuner(3);
  std::mt19937_64 rng(13);
  std::normal_distribution<double> step(0.0, 0.004 * h0);
  std::uniform_real_distribution<double> grow(0.0, 0.001 * h0);
  std::vector<std::vector<std::uint32_t>> kept;
  std::vector<double> skins;
  for (int s = 0; s < 200; ++s) {
    if (verlet.must_rebuild(all, kRadiusScale)) {
      tuner.rebuilt(verlet, kRadiusScale);
      verlet.set_skin(tuner.skin());
      kept = lists(pa, 1.0 + verlet.skin());
      verlet.mark(all);
      skins.push_back(verlet.skin());
    }
    const auto now = lists(pa, 1.0);
    for (std::size_t i = 0; i < pa.n; ++i)
      for (std::uint32_t j : now[i])
        ASSERT_TRUE(std::find(kept[i].begin(), kept[i].end(), j) != kept[i].end())
            << "step " << s << ": pair " << i << ", " << j << " missing";
    for (std::size_t i = 0; i < pa.n; ++i) {
      pa.f64("x")[i] += step(rng);
      pa.f64("y")[i] += step(rng);
      pa.f64("z")[i] += step(rng);
      pa.f64("h")[i] += grow(rng);
    }
  }
  ASSERT_GT(skins.size(), 3u);
  EXPECT_NE(skins.front(), skins.back());  // the skin did change
}

// The symmetric loops' start in a kept list: the first j >= i (the self pair included).
TEST(VerletSkin, UpperStartIsTheFirstIndexNotBelowTheParticle) {
  const std::vector<std::uint32_t> kept = {1, 4, 5, 9};
  EXPECT_EQ(sphc::upper_start(kept, 0), 0u);
  EXPECT_EQ(sphc::upper_start(kept, 4), 1u);  // i itself
  EXPECT_EQ(sphc::upper_start(kept, 6), 3u);
  EXPECT_EQ(sphc::upper_start(kept, 10), 4u);  // none: the end
  EXPECT_EQ(sphc::upper_start({}, 3), 0u);
}

// The sort criterion: the share of places where the cell order breaks the present order.
TEST(SkinTuner, SortWhenTheParticlesLeftCellOrder) {
  std::vector<std::uint32_t> order(101);
  for (std::uint32_t k = 0; k < order.size(); ++k) order[k] = k;
  EXPECT_EQ(sphc::out_of_order(order), 0.0);  // sorted already
  sphc::SkinTuner tuner(2);
  EXPECT_FALSE(tuner.sort_due(order));
  std::swap(order[10], order[11]);  // two particles swapped: 3 breaks in 100 places
  EXPECT_DOUBLE_EQ(sphc::out_of_order(order), 0.03);
  EXPECT_FALSE(tuner.sort_due(order));
  // Every other pair swapped: 3 of every 4 places break.
  for (std::size_t k = 0; k + 1 < order.size(); k += 4) std::swap(order[k], order[k + 1]);
  EXPECT_GT(sphc::out_of_order(order), sphc::SkinTuner::kSortDisorder);
  EXPECT_TRUE(tuner.sort_due(order));
  EXPECT_EQ(tuner.sorts(), 1);
  EXPECT_EQ(sphc::out_of_order({}), 0.0);
}

}  // namespace

// --precision=single: the skin over the float copies (sphc::FloatArray) answers as over the
// doubles the floats are (the same displacements, last_moved bit for bit), with its own
// marked copy per array in a phase.
TEST(VerletSkin, FloatCopiesAnswerAsTheirDoubles) {
  const double skin = 0.1, h0 = 0.1;
  ParticleArray pa = random_array(200, 3, 1.0, h0, 5, 0.8, 1.2);
  // The host doubles rounded to float, so that both arrays hold the same values.
  for (const char* p : {"x", "y", "z", "h"})
    for (std::size_t i = 0; i < pa.n; ++i)
      pa.f64(p)[i] = static_cast<float>(pa.f64(p)[i]);
  sphc::FloatArray fa;
  fa.upload(pa);
  VerletSkin on_doubles(skin), on_floats(skin);
  const std::vector<const ParticleArray*> d = {&pa};
  EXPECT_TRUE(on_floats.must_rebuild({&fa}, kRadiusScale));  // never built
  on_doubles.mark(d);
  on_floats.mark({&fa});
  EXPECT_EQ(on_doubles.hmin(), on_floats.hmin());
  std::mt19937_64 rng(3);
  std::normal_distribution<double> step(0.0, 0.003 * h0);
  const int ix = pa.find("x");
  int rebuilds = 0;
  for (int s = 0; s < 100; ++s) {
    for (std::size_t i = 0; i < pa.n; ++i) {
      const float moved = static_cast<float>(pa.f64(ix)[i] + step(rng));
      pa.f64(ix)[i] = moved;
      fa.f(ix)[i] = moved;
    }
    const bool a = on_doubles.must_rebuild(d, kRadiusScale);
    const bool b = on_floats.must_rebuild({&fa}, kRadiusScale);
    EXPECT_EQ(a, b);
    EXPECT_EQ(on_doubles.last_moved(), on_floats.last_moved());
    if (a) {
      on_doubles.mark(d);
      on_floats.mark({&fa});
      ++rebuilds;
    }
  }
  EXPECT_GT(rebuilds, 0);  // the walk moved past the skin
  // A particle count change rebuilds, as over the doubles.
  fa.n += 1;
  EXPECT_TRUE(on_floats.must_rebuild({&fa}, kRadiusScale));
}
