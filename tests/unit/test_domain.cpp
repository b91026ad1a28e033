// Unit tests of the domain manager (runtime/include/sphc/domain.h): periodic wrapping,
// periodic and mirror ghosts, and the neighbour search over real particles plus ghosts.
//
// References: a periodic lattice is a piece of the infinite lattice, so with ghosts every
// particle must see the neighbourhood of a point of the infinite lattice (same count, and a
// symmetric one: its displacement vectors sum to zero); random particles in a periodic box
// must find the neighbours brute force finds with the minimum-image distance.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "sphc/domain.h"
#include "sphc/float_arrays.h"
#include "sphc/nnps.h"
#include "sphc/particle_array.h"

namespace {

using sphc::Boundary;
using sphc::Domain;
using sphc::Ghosts;
using sphc::ParticleArray;

constexpr double kRadiusScale = 2.0;

Domain periodic_box(int dim, double L) {
  Domain d;
  d.dim = dim;
  for (int a = 0; a < dim; ++a) {
    d.lo_kind[a] = d.hi_kind[a] = Boundary::Periodic;
    d.lo[a] = 0.0;
    d.hi[a] = L;
  }
  return d;
}

// Periodic in x on [0, 1), a mirror at y = 0 and mirrors at z = 0 and z = 1.
Domain mixed_box() {
  Domain d;
  d.dim = 3;
  d.lo_kind[0] = d.hi_kind[0] = Boundary::Periodic;
  d.hi[0] = 1.0;
  d.lo_kind[1] = Boundary::Mirror;  // y >= 0
  d.lo_kind[2] = d.hi_kind[2] = Boundary::Mirror;
  d.hi[2] = 1.0;
  return d;
}

// 300 random points of [0, 1)^3 with values of type T (float: exact in double too); point 0
// in a corner of mixed_box(), 2 x 2 x 2 - 1 = 7 ghosts.
template <class T>
std::vector<std::array<double, 3>> random_points(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<T> unit(T(0), T(1));
  std::vector<std::array<double, 3>> pts(300);
  for (auto& p : pts) p = {unit(rng), unit(rng), unit(rng)};
  pts[0] = {T(0.01), T(0.02), T(0.03)};
  return pts;
}

ParticleArray make_array(const std::vector<std::array<double, 3>>& pts, double h) {
  ParticleArray pa;
  pa.name = "fluid";
  for (const char* p : {"x", "y", "z", "h", "u", "v", "w", "m"}) pa.add_property(p);
  pa.resize(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    pa.f64("x")[i] = pts[i][0];
    pa.f64("y")[i] = pts[i][1];
    pa.f64("z")[i] = pts[i][2];
    pa.f64("h")[i] = h;
    pa.f64("u")[i] = 1.0 + i;
    pa.f64("v")[i] = 2.0 + i;
    pa.f64("w")[i] = 3.0 + i;
    pa.f64("m")[i] = 10.0 + i;
  }
  return pa;
}

// Cell-centred lattice of nx^dim points in [0, L)^dim.
std::vector<std::array<double, 3>> lattice(int dim, int nx, double L) {
  std::vector<std::array<double, 3>> pts;
  const double dx = L / nx;
  const int ny = dim >= 2 ? nx : 1, nz = dim == 3 ? nx : 1;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        pts.push_back({(i + 0.5) * dx, dim >= 2 ? (j + 0.5) * dx : 0.0,
                       dim == 3 ? (k + 0.5) * dx : 0.0});
  return pts;
}

std::vector<int> all_props(const ParticleArray& pa) {
  std::vector<int> v;
  for (std::size_t k = 0; k < pa.props.size(); ++k) v.push_back(static_cast<int>(k));
  return v;
}

// Neighbours (real and ghost) of every real particle, through a cell list built as the
// generated solvers build it: search domain of the real particles, widened for the ghosts.
std::vector<std::vector<std::uint32_t>> neighbours_with_ghosts(const Domain& d, ParticleArray& pa,
                                                               Ghosts& g) {
  sphc::SearchDomain sd = sphc::make_search_domain({&pa}, d.dim, kRadiusScale);
  const double cutoff = sd.cell_size;
  sphc::add_ghosts(d, pa, cutoff, g, all_props(pa));
  sphc::extend_for_ghosts(sd, d, cutoff);
  sphc::CellList cl;
  cl.build(sd, pa.f64("x"), pa.f64("y"), pa.f64("z"), pa.n + g.size());
  std::vector<std::vector<std::uint32_t>> out(pa.n);
  for (std::size_t i = 0; i < pa.n; ++i)
    cl.neighbors(pa.f64("x")[i], pa.f64("y")[i], pa.f64("z")[i], pa.f64("h")[i], pa.f64("x"),
                 pa.f64("y"), pa.f64("z"), pa.f64("h"), kRadiusScale, out[i]);
  return out;
}

// Points of the infinite lattice (spacing dx) within r of a lattice point, itself included.
int infinite_lattice_count(int dim, double dx, double r) {
  const int k = static_cast<int>(std::ceil(r / dx)) + 1;
  int count = 0;
  for (int c = dim == 3 ? -k : 0; c <= (dim == 3 ? k : 0); ++c)
    for (int b = dim >= 2 ? -k : 0; b <= (dim >= 2 ? k : 0); ++b)
      for (int a = -k; a <= k; ++a) {
        const double x = a * dx, y = b * dx, z = c * dx;
        if (x * x + y * y + z * z < r * r) ++count;
      }
  return count;
}

void check_periodic_lattice(int dim, int nx) {
  const double L = 1.0, dx = L / nx, h = 1.3 * dx;  // 2h = 2.6 dx: no lattice distance
  ParticleArray pa = make_array(lattice(dim, nx, L), h);
  const Domain d = periodic_box(dim, L);
  Ghosts g;
  auto nbrs = neighbours_with_ghosts(d, pa, g);
  const int expected = infinite_lattice_count(dim, dx, kRadiusScale * h);
  ASSERT_GT(expected, 1);
  EXPECT_GT(g.size(), 0u);
  const double *x = pa.f64("x"), *y = pa.f64("y"), *z = pa.f64("z");
  for (std::size_t i = 0; i < pa.n; ++i) {
    ASSERT_EQ(static_cast<int>(nbrs[i].size()), expected) << "particle " << i;
    double sum[3] = {0, 0, 0};
    for (std::uint32_t j : nbrs[i]) {
      sum[0] += x[i] - x[j];
      sum[1] += y[i] - y[j];
      sum[2] += z[i] - z[j];
    }
    for (double s : sum) EXPECT_NEAR(s, 0.0, 1e-12) << "particle " << i;
  }
}

TEST(Domain, PeriodicLatticeHasInfiniteLatticeNeighbourhoods1D) { check_periodic_lattice(1, 20); }
TEST(Domain, PeriodicLatticeHasInfiniteLatticeNeighbourhoods2D) { check_periodic_lattice(2, 20); }
TEST(Domain, PeriodicLatticeHasInfiniteLatticeNeighbourhoods3D) { check_periodic_lattice(3, 8); }

TEST(Domain, RandomParticlesMatchMinimumImageBruteForce) {
  const double L = 1.0, h = 0.04;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, L);
  std::vector<std::array<double, 3>> pts(600);
  for (auto& p : pts) p = {u(rng), u(rng), 0.0};
  ParticleArray pa = make_array(pts, h);
  const Domain d = periodic_box(2, L);
  Ghosts g;
  auto nbrs = neighbours_with_ghosts(d, pa, g);
  const double r = kRadiusScale * h;
  std::size_t pairs = 0;
  for (std::size_t i = 0; i < pa.n; ++i) {
    // Minimum image: each pair within r has exactly one image within r (L > 2r).
    std::vector<std::uint32_t> expect;
    for (std::size_t j = 0; j < pa.n; ++j) {
      double dx = pts[i][0] - pts[j][0], dy = pts[i][1] - pts[j][1];
      dx -= L * std::round(dx / L);
      dy -= L * std::round(dy / L);
      if (dx * dx + dy * dy < r * r) expect.push_back(static_cast<std::uint32_t>(j));
    }
    std::vector<std::uint32_t> got;
    for (std::uint32_t j : nbrs[i]) got.push_back(j < pa.n ? j : g.source[j - pa.n]);
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, expect) << "particle " << i;
    pairs += got.size();
  }
  EXPECT_GT(pairs, 2 * pa.n);  // the test tested something
}

TEST(Domain, WrapKeepsPositionsInTheBox) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  ParticleArray pa = make_array({{-0.25, 0.5, 0}, {1.25, 1.0, 0}, {0.3, -2.75, 0},
                                 {0.999, 0.0, 0}, {-1e-17, 3.0, 0}, {nan, 0.5, 0}},
                                0.1);
  const Domain d = periodic_box(2, 1.0);
  sphc::wrap_periodic(d, pa);
  const double* x = pa.f64("x");
  const double* y = pa.f64("y");
  EXPECT_DOUBLE_EQ(x[0], 0.75);
  EXPECT_DOUBLE_EQ(x[1], 0.25);
  EXPECT_DOUBLE_EQ(y[1], 0.0);   // hi belongs to the next period
  EXPECT_DOUBLE_EQ(y[2], 0.25);
  EXPECT_EQ(x[3], 0.999);        // inside: untouched, bit for bit
  EXPECT_EQ(y[3], 0.0);
  EXPECT_TRUE(std::isnan(x[5]));  // left for the blow-up check
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_GE(x[i], 0.0);
    EXPECT_LT(x[i], 1.0);
    EXPECT_GE(y[i], 0.0);
    EXPECT_LT(y[i], 1.0);
  }
}

TEST(Domain, MirrorReflectsPositionAndNormalVelocity) {
  Domain d;
  d.dim = 2;
  d.lo_kind[1] = Boundary::Mirror;  // mirror y >= 0
  d.lo[1] = 0.0;
  ParticleArray pa = make_array({{0.5, 0.05, 0}, {0.5, 0.5, 0}}, 0.05);
  Ghosts g;
  sphc::add_ghosts(d, pa, 0.1, g, all_props(pa));
  ASSERT_EQ(g.size(), 1u);  // only the particle within 0.1 of the plane
  EXPECT_EQ(pa.n, 2u);      // real particles only
  const std::size_t k = pa.n;
  EXPECT_EQ(g.source[0], 0u);
  EXPECT_DOUBLE_EQ(pa.f64("x")[k], 0.5);
  EXPECT_DOUBLE_EQ(pa.f64("y")[k], -0.05);
  EXPECT_DOUBLE_EQ(pa.f64("u")[k], 1.0);   // tangential: kept
  EXPECT_DOUBLE_EQ(pa.f64("v")[k], -2.0);  // normal: negated
  EXPECT_DOUBLE_EQ(pa.f64("m")[k], 10.0);
  sphc::remove_ghosts(pa, g);
  EXPECT_EQ(g.size(), 0u);
  for (const auto& p : pa.props) EXPECT_EQ(p.f64.size(), pa.n) << p.name;
}

TEST(Domain, CornersGetEveryCombinationOfImages) {
  // Periodic in x on [0, 1), mirror at y = 0: a particle near (0, 0) has three ghosts.
  Domain d;
  d.dim = 2;
  d.lo_kind[0] = d.hi_kind[0] = Boundary::Periodic;
  d.hi[0] = 1.0;
  d.lo_kind[1] = Boundary::Mirror;
  ParticleArray pa = make_array({{0.02, 0.03, 0}}, 0.05);
  Ghosts g;
  sphc::add_ghosts(d, pa, 0.1, g, all_props(pa));
  ASSERT_EQ(g.size(), 3u);
  std::vector<std::array<double, 3>> got;
  for (std::size_t k = 0; k < g.size(); ++k)
    got.push_back({pa.f64("x")[1 + k], pa.f64("y")[1 + k], pa.f64("v")[1 + k]});
  std::sort(got.begin(), got.end());
  const std::vector<std::array<double, 3>> expect = {
      {0.02, -0.03, -2.0}, {1.02, -0.03, -2.0}, {1.02, 0.03, 2.0}};
  for (std::size_t k = 0; k < 3; ++k)
    for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(got[k][c], expect[k][c]) << k << " " << c;
}

TEST(Domain, FindGhostsOnRawPositionsIsTheListOfAddGhosts) {
  // find_ghosts (the OpenCL backend calls it on positions read from the device) and
  // add_ghosts give the same ghosts in the same order: by particle, then image (x fastest).
  const Domain d = mixed_box();
  ParticleArray pa = make_array(random_points<double>(7), 0.05);
  std::vector<double> x(pa.f64("x"), pa.f64("x") + pa.n), y(pa.f64("y"), pa.f64("y") + pa.n),
      z(pa.f64("z"), pa.f64("z") + pa.n);
  Ghosts g, raw;
  sphc::add_ghosts(d, pa, 0.1, g, all_props(pa));
  const double* pos[3] = {x.data(), y.data(), z.data()};
  EXPECT_EQ(sphc::find_ghosts(d, pos, x.size(), 0.1, raw, "fluid"), g.size());
  EXPECT_EQ(raw.source, g.source);
  EXPECT_EQ(raw.image, g.image);
  ASSERT_GE(g.size(), 7u);
  const std::vector<std::uint8_t> corner = {1, 1 << 2, 1 | 1 << 2, 1 << 4, 1 | 1 << 4,
                                            1 << 2 | 1 << 4, 1 | 1 << 2 | 1 << 4};
  EXPECT_EQ(std::vector<std::uint8_t>(g.image.begin(), g.image.begin() + 7), corner);
  for (std::size_t k = 1; k < g.size(); ++k) EXPECT_LE(g.source[k - 1], g.source[k]);
  // An axis with a side needs its positions.
  const double* no_z[3] = {x.data(), y.data(), nullptr};
  EXPECT_THROW(sphc::find_ghosts(d, no_z, x.size(), 0.1, raw, "fluid"), std::invalid_argument);
}

TEST(Domain, MirroredLatticeIsTheInfiniteLattice) {
  // Periodic in x, mirrors at y = 0 and y = 1: a cell-centred lattice reflects onto itself.
  const int nx = 16;
  const double dx = 1.0 / nx, h = 1.3 * dx;
  Domain d;
  d.dim = 2;
  d.lo_kind[0] = d.hi_kind[0] = Boundary::Periodic;
  d.lo_kind[1] = d.hi_kind[1] = Boundary::Mirror;
  d.hi[0] = d.hi[1] = 1.0;
  ParticleArray pa = make_array(lattice(2, nx, 1.0), h);
  Ghosts g;
  auto nbrs = neighbours_with_ghosts(d, pa, g);
  const int expected = infinite_lattice_count(2, dx, kRadiusScale * h);
  for (std::size_t i = 0; i < pa.n; ++i) ASSERT_EQ(static_cast<int>(nbrs[i].size()), expected);
}

TEST(Domain, OnlyCarriedPropertiesAreCopiedAndRefreshWorks) {
  ParticleArray pa = make_array({{0.01, 0.5, 0}}, 0.05);
  const Domain d = periodic_box(2, 1.0);
  Ghosts g;
  const std::vector<int> carried = {pa.find("x"), pa.find("y")};
  sphc::add_ghosts(d, pa, 0.1, g, carried);
  ASSERT_EQ(g.size(), 1u);
  EXPECT_DOUBLE_EQ(pa.f64("x")[1], 1.01);
  EXPECT_EQ(pa.f64("m")[1], 0.0);  // not carried: storage only
  pa.f64("m")[0] = 42.0;
  sphc::refresh_ghosts(d, pa, g, {pa.find("m")});
  EXPECT_EQ(pa.f64("m")[1], 42.0);
}

TEST(Domain, FloatCopyGetsTheGhostsOfTheDoubles) {
  // --precision=single: the ghosts of a float copy are those of the double array it was made
  // from (positions that are floats, so both see the same positions): the same list, and
  // every ghost value the double one rounded to float (the shifts by 1 and reflections in 0
  // and 1 of a float are exact in double, so rounding once gives float arithmetic's result).
  // Integer properties grow ghosts in the host array; the host doubles stay at n particles.
  const Domain d = mixed_box();
  ParticleArray pa = make_array(random_points<float>(11), 0.05);
  std::mt19937 rng(12);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const int tag = pa.add_property("tag", sphc::PropType::I32);
  for (std::size_t i = 0; i < pa.n; ++i) pa.i32(tag)[i] = static_cast<std::int32_t>(i);
  for (const char* p : {"u", "v", "w", "m"})
    for (std::size_t i = 0; i < pa.n; ++i) pa.f64(p)[i] = unit(rng);
  sphc::FloatArray f;
  f.upload(pa);
  ParticleArray ref = pa;
  Ghosts g, gref;
  const std::size_t n = pa.n;
  sphc::add_ghosts(d, ref, 0.1, gref, all_props(ref));
  ASSERT_EQ(sphc::add_ghosts(d, f, pa, 0.1, g, all_props(pa)), gref.size());
  ASSERT_GE(g.size(), 7u);
  EXPECT_EQ(g.source, gref.source);
  EXPECT_EQ(g.image, gref.image);
  for (std::size_t i = 0; i < pa.props.size(); ++i) {
    const auto& p = pa.props[i];
    if (p.type != sphc::PropType::F64) {
      EXPECT_EQ(p.i32, ref.props[i].i32) << p.name;  // ghosts in the host array
      continue;
    }
    EXPECT_EQ(p.f64.size(), n) << p.name;  // the doubles are left alone
    ASSERT_EQ(f.props[i].size(), n + g.size()) << p.name;
    for (std::size_t k = n; k < n + g.size(); ++k)
      ASSERT_EQ(f.props[i][k], static_cast<float>(ref.props[i].f64[k])) << p.name << " " << k;
  }
  // The corner particle's images through y = 0 have v negated, in the float copy too.
  EXPECT_EQ(f.f(pa.find("v"))[n + 1], -f.f(pa.find("v"))[0]);
  // Refresh after a phase changed the real particles' values; then back to n particles.
  f.f(pa.find("m"))[0] = 42.0f;
  sphc::refresh_ghosts(d, f, pa, g, {pa.find("m")});
  for (std::size_t k = 0; k < g.size(); ++k)
    if (g.source[k] == 0) EXPECT_EQ(f.f(pa.find("m"))[n + k], 42.0f);
  sphc::remove_ghosts(f, pa, g);
  EXPECT_EQ(g.size(), 0u);
  for (std::size_t i = 0; i < pa.props.size(); ++i)
    EXPECT_EQ(pa.props[i].type == sphc::PropType::F64 ? f.props[i].size() : pa.props[i].i32.size(),
              n)
        << pa.props[i].name;
  EXPECT_NO_THROW(f.download(pa));
}

TEST(Domain, FloatWrapStaysInTheFloatBox) {
  // Wrapping in float: -1e-9 plus the period rounds to 1.0f, the high end, which belongs to
  // the next period; the checks after the shift bring it back to the low end.
  ParticleArray pa = make_array({{-0.25, 0.5, 0}, {1.25, 1.0, 0}, {-1e-9, -2.75, 0}}, 0.1);
  sphc::FloatArray f;
  f.upload(pa);
  sphc::wrap_periodic(periodic_box(2, 1.0), f, pa);
  const float* x = f.f(pa.find("x"));
  const float* y = f.f(pa.find("y"));
  EXPECT_EQ(x[0], 0.75f);
  EXPECT_EQ(x[1], 0.25f);
  EXPECT_EQ(y[1], 0.0f);
  EXPECT_EQ(y[2], 0.25f);
  EXPECT_GE(x[2], 0.0f);
  EXPECT_LT(x[2], 1.0f);
  EXPECT_EQ(pa.f64("x")[0], -0.25);  // the host doubles are left alone
}

TEST(Domain, FloatKeptGhostsFollowTheirOriginals) {
  // Kept ghosts in single precision (--verlet-skin with a domain): hide_ghosts ends an
  // evaluation on the float copy (its storage and the host's integers back to n, the ghost
  // list kept), restore_ghosts makes the same ghosts again from the moved originals: each
  // value what add_ghosts would give now, in the same order. wrap_periodic_far wraps the
  // float positions beyond margin * h only.
  const Domain d = mixed_box();
  ParticleArray pa = make_array(random_points<float>(11), 0.05);
  const int tag = pa.add_property("tag", sphc::PropType::I32);
  for (std::size_t i = 0; i < pa.n; ++i) pa.i32(tag)[i] = static_cast<std::int32_t>(i);
  sphc::FloatArray f;
  f.upload(pa);
  const std::size_t n = pa.n;
  Ghosts g;
  sphc::add_ghosts(d, f, pa, 0.1, g, all_props(pa));
  ASSERT_GE(g.size(), 7u);
  sphc::hide_ghosts(f, pa);
  EXPECT_GE(g.size(), 7u);  // the list is kept
  for (std::size_t i = 0; i < pa.props.size(); ++i)
    EXPECT_EQ(pa.props[i].type == sphc::PropType::F64 ? f.props[i].size() : pa.props[i].i32.size(),
              n)
        << pa.props[i].name;
  // The originals move a little (less than a skin): the same ghosts follow them.
  float* x = f.f(pa.find("x"));
  for (std::size_t i = 0; i < n; ++i) x[i] += 0.001f;
  ASSERT_EQ(sphc::restore_ghosts(d, f, pa, g, all_props(pa)), g.size());
  sphc::FloatArray fresh = f;
  ParticleArray host = pa;
  sphc::hide_ghosts(fresh, host);
  Ghosts gref;
  sphc::add_ghosts(d, fresh, host, 0.1, gref, all_props(host));
  for (std::size_t i = 0; i < pa.props.size(); ++i) {
    if (pa.props[i].type != sphc::PropType::F64) continue;
    for (std::size_t k = 0; k < g.size(); ++k) {
      // The same (particle, image) in the fresh list, where it is found there too.
      for (std::size_t j = 0; j < gref.size(); ++j)
        if (gref.source[j] == g.source[k] && gref.image[j] == g.image[k])
          ASSERT_EQ(f.props[i][n + k], fresh.props[i][n + j]) << pa.props[i].name << " " << k;
    }
  }
  for (std::size_t k = 0; k < g.size(); ++k)
    EXPECT_EQ(pa.i32(tag)[n + k], static_cast<std::int32_t>(g.source[k]));
  sphc::hide_ghosts(f, pa);
  EXPECT_NO_THROW(f.download(pa));
  // wrap_periodic_far: 0.4 h outside stays, 0.6 h outside is wrapped (margin 0.5).
  ParticleArray w = make_array({{1.0 + 0.4 * 0.1, 0.5, 0}, {1.0 + 0.6 * 0.1, 0.5, 0}}, 0.1);
  sphc::FloatArray fw;
  fw.upload(w);
  sphc::wrap_periodic_far(periodic_box(2, 1.0), fw, w, 0.5);
  EXPECT_EQ(fw.f(w.find("x"))[0], static_cast<float>(1.0 + 0.4 * 0.1));
  EXPECT_LT(fw.f(w.find("x"))[1], 1.0f);
  EXPECT_GE(fw.f(w.find("x"))[1], 0.0f);
  EXPECT_EQ(w.f64("x")[1], 1.0 + 0.6 * 0.1);  // the host doubles are left alone
}

TEST(Domain, RejectsBadDomains) {
  Domain d = periodic_box(2, 1.0);
  EXPECT_NO_THROW(sphc::check_domain(d));
  Domain one_sided = d;
  one_sided.hi_kind[0] = Boundary::Mirror;
  EXPECT_THROW(sphc::check_domain(one_sided), std::invalid_argument);
  Domain empty = d;
  empty.hi[1] = 0.0;
  EXPECT_THROW(sphc::check_domain(empty), std::invalid_argument);
  Domain beyond = d;
  beyond.lo_kind[2] = beyond.hi_kind[2] = Boundary::Periodic;
  beyond.hi[2] = 1.0;
  EXPECT_THROW(sphc::check_domain(beyond), std::invalid_argument);
  // A period shorter than the interaction radius cannot be covered by one image per side.
  ParticleArray pa = make_array({{0.01, 0.01, 0}}, 0.05);
  Ghosts g;
  EXPECT_THROW(sphc::add_ghosts(periodic_box(2, 0.05), pa, 0.1, g, {}), std::invalid_argument);
}

}  // namespace
