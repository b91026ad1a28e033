// Unit tests of the cell-list neighbour search (runtime/include/sphc/nnps.h).
//
// The reference is brute force with the same criterion and the same floating operations
// (r^2 < (radius_scale * max(h_i, h_j))^2), so neighbour sets must match exactly.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "sphc/nnps.h"
#include "sphc/particle_array.h"

#include "random_particles.h"

namespace {

using sphc::CellList;
using sphc::ParticleArray;
using sphc::SearchDomain;
using sphc_test::random_array;

constexpr double kRadiusScale = 2.0;

std::vector<std::uint32_t> brute_force(double xi, double yi, double zi, double hi,
                                       const ParticleArray& pa) {
  std::vector<std::uint32_t> out;
  const double *x = pa.f64("x"), *y = pa.f64("y"), *z = pa.f64("z"), *h = pa.f64("h");
  for (std::size_t j = 0; j < pa.n; ++j) {
    const double dx = xi - x[j], dy = yi - y[j], dz = zi - z[j];
    const double rmax = kRadiusScale * std::max(hi, h[j]);
    if (dx * dx + dy * dy + dz * dz < rmax * rmax) out.push_back(static_cast<std::uint32_t>(j));
  }
  return out;
}

// Checks every particle of `pa` (and the extra query points) against brute force; returns the
// number of neighbour pairs found, so tests can check they tested something.
std::size_t check_against_brute_force(const CellList& cl, const ParticleArray& pa,
                                      const std::vector<std::array<double, 4>>& extra = {}) {
  const double *x = pa.f64("x"), *y = pa.f64("y"), *z = pa.f64("z"), *h = pa.f64("h");
  std::vector<std::array<double, 4>> queries = extra;
  for (std::size_t i = 0; i < pa.n; ++i) queries.push_back({x[i], y[i], z[i], h[i]});
  std::size_t pairs = 0;
  std::vector<std::uint32_t> got;
  for (const auto& q : queries) {
    cl.neighbors(q[0], q[1], q[2], q[3], x, y, z, h, kRadiusScale, got);
    std::vector<std::uint32_t> want = brute_force(q[0], q[1], q[2], q[3], pa);
    std::sort(got.begin(), got.end());
    EXPECT_TRUE(std::adjacent_find(got.begin(), got.end()) == got.end())
        << "a candidate was visited twice";
    EXPECT_EQ(got, want) << "query (" << q[0] << ", " << q[1] << ", " << q[2] << ")";
    if (got != want) break;  // one failure is enough to debug
    pairs += got.size();
  }
  return pairs;
}

SearchDomain domain_of(const ParticleArray& pa, int dim) {
  return sphc::make_search_domain({&pa}, dim, kRadiusScale);
}

void build(CellList& cl, const SearchDomain& dom, const ParticleArray& pa) {
  cl.build(dom, pa.f64("x"), pa.f64("y"), pa.f64("z"), pa.n);
}

class NnpsModes : public ::testing::TestWithParam<CellList::Mode> {};

TEST_P(NnpsModes, MatchesBruteForceVariableH) {
  for (int dim : {1, 2, 3}) {
    SCOPED_TRACE("dim " + std::to_string(dim));
    const std::size_t n = dim == 1 ? 300 : dim == 2 ? 2000 : 3000;
    ParticleArray pa = random_array(n, dim, 10.0, dim == 1 ? 0.05 : dim == 2 ? 0.2 : 0.4, 42 + dim);
    CellList cl;
    cl.set_mode(GetParam());
    build(cl, domain_of(pa, dim), pa);
    EXPECT_EQ(cl.size(), n);
    if (GetParam() != CellList::Mode::Auto) {
      EXPECT_EQ(cl.is_dense(), GetParam() == CellList::Mode::Dense);
    }
    EXPECT_GT(check_against_brute_force(cl, pa), 2 * n);  // more than self-pairs
  }
}

TEST_P(NnpsModes, ParticlesMovedOutsideTheDomain) {
  // The domain is made once, then particles move (some far outside it) and the list is
  // rebuilt on the stale domain, as between two domain updates. Query points outside too.
  for (int dim : {2, 3}) {
    SCOPED_TRACE("dim " + std::to_string(dim));
    ParticleArray pa = random_array(1500, dim, 5.0, 0.25, 7 + dim);
    const SearchDomain dom = domain_of(pa, dim);
    std::mt19937_64 rng(99);
    std::uniform_real_distribution<double> shift(-8.0, 8.0);
    double* x = pa.f64("x");
    double* y = pa.f64("y");
    double* z = pa.f64("z");
    for (std::size_t i = 0; i < pa.n; i += 3) {
      x[i] += shift(rng);
      y[i] += shift(rng);
      if (dim == 3) z[i] += shift(rng);
    }
    // A dense pile beyond the upper corner: all of it clamps into one border cell.
    for (std::size_t i = 1; i < pa.n; i += 50) {
      x[i] = 30.0 + 0.01 * i;
      y[i] = 30.0;
    }
    CellList cl;
    cl.set_mode(GetParam());
    build(cl, dom, pa);
    std::vector<std::array<double, 4>> extra = {
        {-100.0, -100.0, 0.0, 0.3}, {100.0, 2.0, 0.0, 0.3}, {2.5, 2.5, 40.0, 0.3},
        {30.5, 30.0, 0.0, 0.3},     {5.3, 5.3, 0.0, 0.3},
    };
    EXPECT_GT(check_against_brute_force(cl, pa, extra), pa.n);
  }
}

// gather_neighbours (what the generated pair loops use) keeps exactly the candidates its test
// accepts, in candidate order (the order every sum over neighbours follows), for any test and
// any number of candidates: a pile of particles in one cell makes the list grow mid-query.
TEST_P(NnpsModes, GatherNeighboursIsTheFilteredCandidateOrder) {
  for (int dim : {1, 2, 3}) {
    SCOPED_TRACE("dim " + std::to_string(dim));
    ParticleArray pa = random_array(dim == 1 ? 300 : 1500, dim, 5.0, dim == 1 ? 0.05 : 0.25,
                                    11 + dim);
    double* x = pa.f64("x");
    double* y = pa.f64("y");
    double* z = pa.f64("z");
    for (std::size_t i = 1; i < pa.n; i += 5) {  // a fifth of the particles in one cell
      x[i] = 2.5 + 1e-4 * static_cast<double>(i % 7);
      y[i] = dim >= 2 ? 2.5 : 0.0;
      z[i] = dim == 3 ? 2.5 : 0.0;
    }
    const double* h = pa.f64("h");
    CellList cl;
    cl.set_mode(GetParam());
    build(cl, domain_of(pa, dim), pa);
    std::vector<std::uint32_t> list;  // starts empty: grows as needed
    std::size_t pairs = 0, grown_at_least_to = 0;
    for (std::size_t i = 0; i < pa.n; ++i) {
      auto is_nbr = [&](std::uint32_t j) {
        const double dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
        const double rmax = kRadiusScale * std::max(h[i], h[j]);
        return dx * dx + dy * dy + dz * dz < rmax * rmax;
      };
      std::vector<std::uint32_t> want, candidates;
      cl.for_each_candidate(x[i], y[i], z[i], [&](std::uint32_t j) {
        candidates.push_back(j);
        if (is_nbr(j)) want.push_back(j);
      });
      const std::size_t count = cl.gather_neighbours(x[i], y[i], z[i], list, is_nbr);
      ASSERT_EQ(count, want.size()) << "particle " << i;
      ASSERT_GE(list.size(), count);
      EXPECT_TRUE(std::equal(want.begin(), want.end(), list.begin())) << "particle " << i;
      // Every candidate accepted: the candidate order itself.
      const std::size_t all =
          cl.gather_neighbours(x[i], y[i], z[i], list, [](std::uint32_t) { return true; });
      ASSERT_EQ(all, candidates.size());
      EXPECT_TRUE(std::equal(candidates.begin(), candidates.end(), list.begin()));
      EXPECT_EQ(cl.gather_neighbours(x[i], y[i], z[i], list, [](std::uint32_t) { return false; }),
                0u);
      pairs += count;
      grown_at_least_to = std::max(grown_at_least_to, candidates.size());
    }
    EXPECT_GT(pairs, 2 * pa.n);           // more than self-pairs
    EXPECT_GE(grown_at_least_to, pa.n / 5);  // the pile was a query's candidates
    EXPECT_GE(list.size(), grown_at_least_to);
  }
}

INSTANTIATE_TEST_SUITE_P(AllModes, NnpsModes,
                         ::testing::Values(CellList::Mode::Auto, CellList::Mode::Dense,
                                           CellList::Mode::Hash),
                         [](const ::testing::TestParamInfo<CellList::Mode>& info) {
                           switch (info.param) {
                             case CellList::Mode::Auto: return std::string("Auto");
                             case CellList::Mode::Dense: return std::string("Dense");
                             case CellList::Mode::Hash: return std::string("Hash");
                           }
                           return std::string("Unknown");
                         });

TEST(Nnps, SparseDomainUsesHash) {
  // Two clusters 1e4 apart with cells of ~0.5: a dense grid would need ~4e8 cells in 2D.
  for (int dim : {2, 3}) {
    SCOPED_TRACE("dim " + std::to_string(dim));
    ParticleArray a = random_array(800, dim, 2.0, 0.1, 1);
    ParticleArray b = random_array(800, dim, 2.0, 0.1, 2);
    for (std::size_t i = 0; i < b.n; ++i) {
      b.f64("x")[i] += 1e4;
      b.f64("y")[i] += 1e4;
    }
    ParticleArray all = a;
    for (std::size_t i = 0; i < b.n; ++i) all.append_from(b, i);
    CellList cl;
    build(cl, domain_of(all, dim), all);
    EXPECT_FALSE(cl.is_dense());
    EXPECT_LE(cl.num_cells(), all.n);
    EXPECT_GT(check_against_brute_force(cl, all), 2 * all.n);
  }
}

TEST(Nnps, TwoArraysShareADomain) {
  // Sources and destinations in different arrays with different h: the domain's cell size
  // comes from the larger h, and a query of one array on the other's list is exact.
  ParticleArray fluid = random_array(1000, 2, 4.0, 0.05, 3);
  ParticleArray solid = random_array(500, 2, 4.0, 0.2, 4);
  const SearchDomain dom = sphc::make_search_domain({&fluid, &solid}, 2, kRadiusScale);
  double hmax = 0.0;
  for (std::size_t i = 0; i < solid.n; ++i) hmax = std::max(hmax, solid.f64("h")[i]);
  EXPECT_DOUBLE_EQ(dom.cell_size, kRadiusScale * hmax);
  CellList cl;
  build(cl, dom, solid);
  std::vector<std::array<double, 4>> queries;
  for (std::size_t i = 0; i < fluid.n; ++i) {
    queries.push_back({fluid.f64("x")[i], fluid.f64("y")[i], 0.0, fluid.f64("h")[i]});
  }
  EXPECT_GT(check_against_brute_force(cl, solid, queries), fluid.n);
}

TEST(Nnps, EmptyAndSingleParticle) {
  ParticleArray pa = random_array(0, 2, 1.0, 0.1, 5);
  CellList unbuilt;
  int calls = 0;
  unbuilt.for_each_candidate(0.0, 0.0, 0.0, [&](std::uint32_t) { ++calls; });
  EXPECT_EQ(calls, 0);

  CellList cl;
  const SearchDomain dom = domain_of(pa, 2);
  EXPECT_GT(dom.cell_size, 0.0);
  build(cl, dom, pa);
  EXPECT_EQ(cl.size(), 0u);
  cl.for_each_candidate(0.5, 0.5, 0.0, [&](std::uint32_t) { ++calls; });
  EXPECT_EQ(calls, 0);

  pa = random_array(1, 2, 1.0, 0.1, 6);
  build(cl, domain_of(pa, 2), pa);
  std::vector<std::uint32_t> got;
  cl.neighbors(pa.f64("x")[0], pa.f64("y")[0], 0.0, 0.1, pa.f64("x"), pa.f64("y"), nullptr,
               pa.f64("h"), kRadiusScale, got);
  EXPECT_EQ(got, std::vector<std::uint32_t>{0});
  cl.neighbors(50.0, 50.0, 0.0, 0.1, pa.f64("x"), pa.f64("y"), nullptr, pa.f64("h"),
               kRadiusScale, got);
  EXPECT_TRUE(got.empty());
}

TEST(Nnps, NonFiniteCoordinatesDoNotCrash) {
  ParticleArray pa = random_array(200, 3, 2.0, 0.1, 8);
  const SearchDomain dom = domain_of(pa, 3);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  pa.f64("x")[3] = nan;
  pa.f64("y")[4] = inf;
  pa.f64("z")[5] = -inf;
  pa.f64("x")[6] = 1e300;
  for (CellList::Mode mode : {CellList::Mode::Dense, CellList::Mode::Hash}) {
    CellList cl;
    cl.set_mode(mode);
    build(cl, dom, pa);
    EXPECT_EQ(cl.size(), pa.n);
    // NaN never satisfies the criterion, infinite distances neither: brute force agrees.
    check_against_brute_force(cl, pa, {{nan, 0.0, 0.0, 0.1}, {inf, -inf, nan, 0.1}});
  }
  // make_search_domain ignores the non-finite coordinates.
  const SearchDomain d2 = domain_of(pa, 3);
  for (int a = 0; a < 3; ++a) {
    EXPECT_TRUE(std::isfinite(d2.lo[a]));
    EXPECT_TRUE(std::isfinite(d2.hi[a]));
  }
}

TEST(Nnps, DeterministicOrderAndRebuild) {
  ParticleArray pa = random_array(1000, 2, 3.0, 0.1, 11);
  const SearchDomain dom = domain_of(pa, 2);
  CellList a, b;
  build(a, dom, pa);
  build(b, dom, pa);
  build(b, dom, pa);  // rebuilding with the same data gives the same list
  for (std::size_t i = 0; i < pa.n; i += 17) {
    std::vector<std::uint32_t> ca, cb;
    a.for_each_candidate(pa.f64("x")[i], pa.f64("y")[i], 0.0,
                         [&](std::uint32_t j) { ca.push_back(j); });
    b.for_each_candidate(pa.f64("x")[i], pa.f64("y")[i], 0.0,
                         [&](std::uint32_t j) { cb.push_back(j); });
    EXPECT_EQ(ca, cb);
  }
  // Shrinking and growing n between builds.
  ParticleArray small = random_array(10, 2, 3.0, 0.1, 12);
  build(b, dom, small);
  check_against_brute_force(b, small);
  build(b, dom, pa);
  check_against_brute_force(b, pa);
}

// The Z (Morton) key of cell (cx, cy, cz), bit by bit: bit k of cx, cy, cz at bits 3k, 3k + 1,
// 3k + 2 (the reference for CellList::locality_order, which spreads the bits by masks).
std::uint64_t z_key_bitwise(std::uint64_t cx, std::uint64_t cy, std::uint64_t cz) {
  std::uint64_t key = 0;
  for (int k = 0; k < 21; ++k)
    key |= ((cx >> k) & 1u) << (3 * k) | ((cy >> k) & 1u) << (3 * k + 1) |
           ((cz >> k) & 1u) << (3 * k + 2);
  return key;
}

TEST(Nnps, LocalityOrderOnALattice) {
  // One particle at the centre of each cell of a 4 x 4 grid (cells of 1, the particles
  // numbered row by row, x fastest): Z order visits 2 x 2 blocks, x as the lowest bit.
  ParticleArray pa;
  pa.name = "fluid";
  pa.add_property("x");
  pa.add_property("y");
  pa.add_property("z");
  pa.add_property("h");
  pa.resize(16);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      pa.f64("x")[4 * j + i] = i + 0.5;
      pa.f64("y")[4 * j + i] = j + 0.5;
      pa.f64("h")[4 * j + i] = 0.5;  // cell = radius_scale * h = 1
    }
  SearchDomain dom;
  dom.dim = 2;
  dom.hi[0] = dom.hi[1] = 4.0;
  dom.cell_size = 1.0;
  for (CellList::Mode mode : {CellList::Mode::Dense, CellList::Mode::Hash}) {
    CellList cl;
    cl.set_mode(mode);
    build(cl, dom, pa);
    std::vector<std::uint32_t> order;
    cl.locality_order(order);
    const std::vector<std::uint32_t> want = {0, 1, 4, 5, 2, 3, 6, 7, 8, 9, 12, 13, 10, 11, 14, 15};
    EXPECT_EQ(order, want) << (mode == CellList::Mode::Dense ? "dense" : "hashed");
  }
}

TEST(Nnps, LocalityOrderIsZOrderOfTheCells) {
  // Random particles in 1, 2 and 3 dimensions, dense and hashed storage: a permutation of
  // 0..n-1 whose cells' Z keys (computed here from the coordinates) never decrease, and
  // ascending index within a cell; both storages give the same order.
  for (int dim : {1, 2, 3}) {
    SCOPED_TRACE("dim " + std::to_string(dim));
    ParticleArray pa = random_array(3000, dim, 3.0, 0.1, 21);
    const SearchDomain dom = domain_of(pa, dim);
    std::vector<std::uint32_t> orders[2];
    int m = 0;
    for (CellList::Mode mode : {CellList::Mode::Dense, CellList::Mode::Hash}) {
      CellList cl;
      cl.set_mode(mode);
      build(cl, dom, pa);
      ASSERT_EQ(cl.is_dense(), mode == CellList::Mode::Dense);
      cl.locality_order(orders[m]);
      EXPECT_EQ(sphc::locality_order(cl), orders[m]);
      ++m;
    }
    EXPECT_EQ(orders[0], orders[1]) << "dense and hashed storage differ";
    const std::vector<std::uint32_t>& order = orders[0];
    ASSERT_EQ(order.size(), pa.n);
    EXPECT_TRUE(sphc::is_permutation_of(order, pa.n));
    const double* xyz[3] = {pa.f64("x"), pa.f64("y"), pa.f64("z")};
    const auto key = [&](std::uint32_t i) {
      std::uint64_t c[3] = {0, 0, 0};
      for (int a = 0; a < dim; ++a)
        c[a] = static_cast<std::uint64_t>(std::floor((xyz[a][i] - dom.lo[a]) / dom.cell_size));
      return z_key_bitwise(c[0], c[1], c[2]);
    };
    std::size_t cells = 1;
    for (std::size_t k = 1; k < order.size(); ++k) {
      const std::uint64_t k0 = key(order[k - 1]), k1 = key(order[k]);
      ASSERT_LE(k0, k1) << "at " << k;
      if (k0 == k1) {
        ASSERT_LT(order[k - 1], order[k]) << "within a cell, at " << k;
      } else {
        ++cells;
      }
    }
    EXPECT_GT(cells, 8u);  // the particles span many cells: the order was tested
  }
}

TEST(Nnps, SearchDomainAndErrors) {
  ParticleArray pa = random_array(100, 2, 1.0, 0.1, 13);
  const SearchDomain dom = domain_of(pa, 2);
  EXPECT_EQ(dom.dim, 2);
  const double* x = pa.f64("x");
  EXPECT_LE(dom.lo[0], *std::min_element(x, x + pa.n));
  EXPECT_GE(dom.hi[0], *std::max_element(x, x + pa.n));
  EXPECT_EQ(dom.lo[2], 0.0);
  EXPECT_EQ(dom.hi[2], 0.0);

  EXPECT_THROW(sphc::make_search_domain({&pa}, 4, 2.0), std::invalid_argument);
  EXPECT_THROW(sphc::make_search_domain({&pa}, 2, 0.0), std::invalid_argument);
  ParticleArray no_h;
  no_h.name = "wall";
  no_h.resize(3);
  no_h.add_property("x");
  try {
    sphc::make_search_domain({&no_h}, 2, 2.0);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'wall'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'h'"), std::string::npos) << e.what();
  }
  SearchDomain bad = dom;
  bad.dim = 0;
  CellList cl;
  EXPECT_THROW(build(cl, bad, pa), std::invalid_argument);
  // A degenerate cell size does not crash (one cell per axis at worst).
  bad = dom;
  bad.cell_size = 0.0;
  build(cl, bad, pa);
  check_against_brute_force(cl, pa);
}

}  // namespace
