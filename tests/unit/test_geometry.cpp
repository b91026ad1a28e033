// Unit tests of the geometry builders (runtime/include/sphc/geometry.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <tuple>

#include "sphc/geometry.h"

namespace {

using sphc::Points;

// Points as integer lattice keys (coordinates / (dx / 2), rounded): equal points give equal
// keys, so duplicates show up in a set.
std::set<std::tuple<long, long, long>> keys(const Points& p, double dx) {
  std::set<std::tuple<long, long, long>> s;
  for (std::size_t i = 0; i < p.size(); ++i) {
    s.emplace(std::lround(p.x[i] * 2.0 / dx), std::lround(p.y[i] * 2.0 / dx),
              std::lround(p.z[i] * 2.0 / dx));
  }
  return s;
}

// Smallest distance between two different points (brute force; small sets only).
double min_distance(const Points& p) {
  double best = INFINITY;
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      const double dx = p.x[i] - p.x[j], dy = p.y[i] - p.y[j], dz = p.z[i] - p.z[j];
      best = std::min(best, std::sqrt(dx * dx + dy * dy + dz * dz));
    }
  }
  return best;
}

// Expects `f` to throw std::invalid_argument whose message contains each of `words`.
template <class F>
void expect_invalid(F&& f, std::initializer_list<const char*> words) {
  try {
    f();
    ADD_FAILURE() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    for (const char* w : words) {
      EXPECT_NE(std::string(e.what()).find(w), std::string::npos)
          << "message '" << e.what() << "' lacks '" << w << "'";
    }
  }
}

TEST(Geometry, BlockCounts) {
  // 1 x 2 with dx = 0.03: 1 / 0.03 = 33.33 -> 33 cells, 2 / 0.03 = 66.67 -> 67 cells
  // (rounded by hand from 100/3 and 200/3).
  const double lo[3] = {0.0, 0.0, 0.0}, hi[3] = {1.0, 2.0, 0.0};
  const Points p = sphc::block(2, lo, hi, 0.03);
  EXPECT_EQ(p.size(), 33u * 67u);
  // 0.3 / 0.1 is 2.9999999999999996 in floating point: still 3 cells.
  const double hi3[3] = {0.3, 0.3, 0.3};
  EXPECT_EQ(sphc::block(1, lo, hi3, 0.1).size(), 3u);
  EXPECT_EQ(sphc::block(3, lo, hi3, 0.1).size(), 27u);
  EXPECT_EQ(sphc::lattice_count(0.0, 0.3, 0.1), 3u);
  EXPECT_EQ(sphc::lattice_count(0.0, 0.7, 0.1), 7u);
  EXPECT_EQ(sphc::lattice_count(0.0, 0.0, 0.1), 0u);
  // An empty box gives no points, not an error.
  EXPECT_EQ(sphc::block(2, lo, lo, 0.1).size(), 0u);
}

TEST(Geometry, BlockSpacingAndPlacement) {
  const double lo[3] = {-1.0, 0.5, 2.0}, hi[3] = {1.0, 1.5, 2.5};
  const double dx = 0.1;
  const Points p = sphc::block(3, lo, hi, dx);
  EXPECT_EQ(p.size(), 20u * 10u * 5u);
  EXPECT_EQ(keys(p, dx).size(), p.size());  // no duplicates
  // Cell centres: the first at lo + dx/2; spacing dx (1e-12: rounding of i * dx).
  EXPECT_NEAR(*std::min_element(p.x.begin(), p.x.end()), lo[0] + 0.5 * dx, 1e-12);
  EXPECT_NEAR(*std::max_element(p.x.begin(), p.x.end()), hi[0] - 0.5 * dx, 1e-12);
  EXPECT_NEAR(*std::min_element(p.z.begin(), p.z.end()), lo[2] + 0.5 * dx, 1e-12);
  EXPECT_NEAR(min_distance(sphc::block(2, lo, hi, dx)), dx, 1e-12);
  // x varies fastest.
  EXPECT_NEAR(p.x[1] - p.x[0], dx, 1e-12);
  EXPECT_EQ(p.y[1], p.y[0]);
  // Unused axes are 0.
  const Points q = sphc::block(2, lo, hi, dx);
  EXPECT_TRUE(std::all_of(q.z.begin(), q.z.end(), [](double v) { return v == 0.0; }));
}

TEST(Geometry, TankCounts) {
  // 2D inner box 4 x 3, dx 0.1 (40 x 30 cells), 3 layers: the full lattice is
  // (40 + 6) x (30 + 3) without the lid, (40 + 6) x (30 + 6) with it, less the 40 x 30 inside.
  const double lo[3] = {0.0, 0.0, 0.0}, hi[3] = {4.0, 3.0, 0.0};
  const Points open = sphc::tank(2, lo, hi, 0.1, 3, false);
  EXPECT_EQ(open.size(), 46u * 33u - 40u * 30u);
  const Points closed = sphc::tank(2, lo, hi, 0.1, 3, true);
  EXPECT_EQ(closed.size(), 46u * 36u - 40u * 30u);
  // 3D unit box, dx 0.25 (4 cells per axis), 2 layers, vertical axis z.
  const double hi3[3] = {1.0, 1.0, 1.0};
  EXPECT_EQ(sphc::tank(3, lo, hi3, 0.25, 2, false).size(), 8u * 8u * 6u - 64u);
  EXPECT_EQ(sphc::tank(3, lo, hi3, 0.25, 2, true).size(), 8u * 8u * 8u - 64u);
  // 1D: walls at the left (and right with a lid).
  EXPECT_EQ(sphc::tank(1, lo, hi3, 0.25, 2, false).size(), 2u);
  EXPECT_EQ(sphc::tank(1, lo, hi3, 0.25, 2, true).size(), 4u);
}

// A box whose width is not a whole number of dx (4 m at dx = 0.03 is 133.3 dx): the right
// wall continues the lattice of the floor, so no seam wider than dx opens in the corner
// (docs/validation.md, SISPH dam break: water leaked through one of 0.04 m).
TEST(Geometry, TankWallsOnTheLatticeOfTheBox) {
  const double lo[3] = {0.0, 0.0, 0.0}, hi[3] = {4.0, 4.0, 0.0};
  const double dx = 0.03;
  const Points wall = sphc::tank(2, lo, hi, dx, 3, false);
  // Every x of the wall is on the lattice lo + (k + 1/2) dx.
  for (std::size_t i = 0; i < wall.size(); ++i) {
    const double k = wall.x[i] / dx - 0.5;
    EXPECT_NEAR(k, std::round(k), 1e-9) << "x = " << wall.x[i];
  }
  // The right wall's first layer is one dx beyond the floor's last column inside the box.
  double right_inner = INFINITY, floor_last = -INFINITY;
  for (std::size_t i = 0; i < wall.size(); ++i) {
    if (wall.x[i] > hi[0] - 0.5 * dx) right_inner = std::min(right_inner, wall.x[i]);
    if (wall.y[i] < 0.0 && wall.x[i] < hi[0]) floor_last = std::max(floor_last, wall.x[i]);
  }
  EXPECT_NEAR(right_inner - floor_last, dx, 1e-12);
  EXPECT_NEAR(right_inner, 133.5 * dx, 1e-12);
  EXPECT_EQ(keys(wall, dx).size(), wall.size());
}

TEST(Geometry, TankNoDuplicatesAndInnerFace) {
  const double lo[3] = {0.0, 0.0, 0.0}, hi[3] = {1.0, 0.6, 0.0};
  const double dx = 0.05;
  for (bool top : {false, true}) {
    SCOPED_TRACE(top ? "with lid" : "open");
    const Points wall = sphc::tank(2, lo, hi, dx, 3, top);
    EXPECT_EQ(keys(wall, dx).size(), wall.size()) << "duplicate points (corners?)";
    // Every wall particle is outside the box by at least dx/2, and the nearest are exactly
    // dx/2 outside: the inner face is the box.
    double nearest = INFINITY;
    for (std::size_t i = 0; i < wall.size(); ++i) {
      const double out = std::max({lo[0] - wall.x[i], wall.x[i] - hi[0], lo[1] - wall.y[i],
                                   top ? wall.y[i] - hi[1] : -INFINITY});
      EXPECT_GE(out, 0.5 * dx - 1e-12) << "point " << wall.x[i] << ", " << wall.y[i];
      nearest = std::min(nearest, out);
      EXPECT_LT(wall.y[i], top ? hi[1] + 3 * dx : hi[1]);  // walls stop at the top of the box
    }
    EXPECT_NEAR(nearest, 0.5 * dx, 1e-12);
    // A fluid block filling the box sits exactly dx from the walls, and nothing overlaps.
    Points all = sphc::block(2, lo, hi, dx);
    const std::size_t fluid = all.size();
    all.append(wall);
    EXPECT_EQ(all.size(), fluid + wall.size());
    EXPECT_EQ(keys(all, dx).size(), all.size());
    EXPECT_NEAR(min_distance(all), dx, 1e-12);
  }
}

TEST(Geometry, DiskAndSphere) {
  // Lattice points within r of the centre, each standing for dx^d. The points cover the
  // disk up to a boundary strip of width <= dx * sqrt(d) / 2 on either side, so
  // |count dx^d - volume| <= surface * dx * sqrt(d) / 2: relative sqrt(2) dx / r for the disk
  // and 3 sqrt(3) / 2 dx / r for the ball.
  const double r = 1.0, dx = 0.02;
  const Points d = sphc::disk(0.5, -0.25, r, dx);
  EXPECT_NEAR(d.size() * dx * dx, M_PI * r * r, M_PI * r * r * std::sqrt(2.0) * dx / r);
  EXPECT_EQ(keys(d, dx).size(), d.size());
  bool has_centre = false;
  for (std::size_t i = 0; i < d.size(); ++i) {
    EXPECT_LE(std::hypot(d.x[i] - 0.5, d.y[i] + 0.25), r * (1 + 1e-9));
    EXPECT_EQ(d.z[i], 0.0);
    has_centre |= d.x[i] == 0.5 && d.y[i] == -0.25;
  }
  EXPECT_TRUE(has_centre);
  // r a whole number of dx: the 4 points on the circle's axes are kept.
  EXPECT_EQ(sphc::disk(0.0, 0.0, 0.1, 0.05).size(), 13u);  // |i|,|j| <= 2, i^2 + j^2 <= 4

  const double rs = 0.5, dxs = 0.025;
  const Points s = sphc::sphere(0.0, 1.0, 2.0, rs, dxs);
  const double vol = 4.0 / 3.0 * M_PI * rs * rs * rs;
  EXPECT_NEAR(s.size() * dxs * dxs * dxs, vol, vol * 1.5 * std::sqrt(3.0) * dxs / rs);
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double dist = std::sqrt(s.x[i] * s.x[i] + (s.y[i] - 1.0) * (s.y[i] - 1.0) +
                                  (s.z[i] - 2.0) * (s.z[i] - 2.0));
    EXPECT_LE(dist, rs * (1 + 1e-9));
  }
}

TEST(Geometry, Cylinder) {
  const double dx = 0.05;
  const Points c = sphc::cylinder(1.0, 2.0, 0.3, -0.5, 0.5, dx);
  const Points section = sphc::disk(1.0, 2.0, 0.3, dx);
  EXPECT_EQ(c.size(), section.size() * 20u);  // 1 / 0.05 = 20 layers
  EXPECT_NEAR(*std::min_element(c.z.begin(), c.z.end()), -0.5 + 0.5 * dx, 1e-12);
  EXPECT_NEAR(*std::max_element(c.z.begin(), c.z.end()), 0.5 - 0.5 * dx, 1e-12);
  EXPECT_EQ(keys(c, dx).size(), c.size());
}

TEST(Geometry, Line) {
  const double p0[3] = {0.0, 0.0, 0.0}, p1[3] = {1.0, 0.0, 0.0};
  // 1 / 0.3 = 3.33 -> 3 intervals of 1/3: 4 points, both ends included exactly.
  Points l = sphc::line(p0, p1, 0.3);
  ASSERT_EQ(l.size(), 4u);
  EXPECT_EQ(l.x.front(), 0.0);
  EXPECT_EQ(l.x.back(), 1.0);
  EXPECT_NEAR(l.x[1], 1.0 / 3.0, 1e-15);
  // Diagonal: length 5, dx 0.5 -> 10 intervals, 11 points, spacing exactly 0.5.
  const double a[3] = {1.0, 1.0, 0.0}, b[3] = {4.0, 5.0, 0.0};
  l = sphc::line(a, b, 0.5);
  ASSERT_EQ(l.size(), 11u);
  EXPECT_NEAR(min_distance(l), 0.5, 1e-12);
  EXPECT_EQ(l.x.back(), 4.0);
  EXPECT_EQ(l.y.back(), 5.0);
  // Shorter than dx: still both ends. Zero length: one point.
  EXPECT_EQ(sphc::line(p0, p1, 10.0).size(), 2u);
  EXPECT_EQ(sphc::line(p0, p0, 0.1).size(), 1u);
}

TEST(Geometry, PointsAppend) {
  Points a, b;
  a.push(1, 2, 3);
  b.push(4, 5, 6);
  b.push(7, 8, 9);
  a.append(b);
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(a.x[2], 7.0);
  EXPECT_EQ(a.z[1], 6.0);
}

TEST(Geometry, BadArguments) {
  const double lo[3] = {0.0, 0.0, 0.0}, hi[3] = {1.0, 1.0, 1.0}, bad_hi[3] = {1.0, -1.0, 1.0};
  expect_invalid([&] { sphc::block(2, lo, hi, 0.0); }, {"block", "dx"});
  expect_invalid([&] { sphc::block(2, lo, hi, -0.1); }, {"block", "dx"});
  expect_invalid([&] { sphc::block(2, lo, hi, NAN); }, {"block", "dx"});
  expect_invalid([&] { sphc::block(2, lo, bad_hi, 0.1); }, {"block", "ymax", "ymin"});
  expect_invalid([&] { sphc::block(4, lo, hi, 0.1); }, {"block", "dim"});
  expect_invalid([&] { sphc::block(3, lo, hi, 1e-5); }, {"block", "points"});  // 1e15 points
  expect_invalid([&] { sphc::tank(2, lo, hi, 0.1, 0); }, {"tank", "layers"});
  expect_invalid([&] { sphc::tank(2, lo, bad_hi, 0.1, 3); }, {"tank", "ymax"});
  expect_invalid([&] { sphc::tank(2, lo, hi, -1.0, 3); }, {"tank", "dx"});
  expect_invalid([] { sphc::disk(0, 0, 0.0, 0.1); }, {"disk", "r"});
  expect_invalid([] { sphc::disk(0, 0, -1.0, 0.1); }, {"disk", "r"});
  expect_invalid([] { sphc::disk(0, 0, 1.0, 0.0); }, {"disk", "dx"});
  expect_invalid([] { sphc::disk(NAN, 0, 1.0, 0.1); }, {"disk", "cx"});
  expect_invalid([] { sphc::sphere(0, 0, 0, -1.0, 0.1); }, {"sphere", "r"});
  expect_invalid([] { sphc::cylinder(0, 0, 1.0, 1.0, 0.0, 0.1); }, {"cylinder", "zmax"});
  expect_invalid([] { sphc::cylinder(0, 0, 0.0, 0.0, 1.0, 0.1); }, {"cylinder", "r"});
  expect_invalid([&] { sphc::line(lo, hi, 0.0); }, {"line", "dx"});
}

}  // namespace
