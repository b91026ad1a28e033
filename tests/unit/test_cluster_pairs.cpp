// Unit tests of the cluster-pair lists (runtime/include/sphc/cluster_pairs.h): the layout is a
// permutation into columns of clusters of 8 (and of the other widths: 4, 2, 1, 5) with padding
// only at a column's end; every pair
// of particles within the radius lies in a listed cluster pair (brute force over all pairs),
// for one array (each pair once, j >= i) and two (cross), 2D and 3D, random positions and a
// perturbed lattice, with padding and empty columns; the pruned list keeps every pair within
// the pruning radius after the particles moved by up to half the skin; gather and add round-
// trip exactly; padding positions lie at least pad_offset from every real particle.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "sphc/cluster_pairs.h"

namespace {

using sphc::build_cluster_layout;
using sphc::build_cluster_pairs;
using sphc::ClusterLayout;
using sphc::ClusterPairList;
using sphc::kClusterSize;
using sphc::kPadSlot;
using sphc::prune_cluster_pairs;

struct Points {
  int dim = 3;
  std::vector<double> x, y, z;
  std::size_t n() const { return x.size(); }
  const double* zp() const { return dim == 3 ? z.data() : nullptr; }
};

// n points uniform in [0, L]^dim; with `blobs`, in two cubes of side L/4 at opposite corners
// (most columns empty).
Points random_points(std::size_t n, int dim, double L, unsigned seed, bool blobs = false) {
  Points p;
  p.dim = dim;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (std::size_t i = 0; i < n; ++i) {
    double c[3];
    const double off = blobs ? (i % 2 ? 0.75 * L : 0.0) : 0.0;
    const double ext = blobs ? 0.25 * L : L;
    for (int a = 0; a < 3; ++a) c[a] = a < dim ? off + ext * u(rng) : 0.0;
    p.x.push_back(c[0]), p.y.push_back(c[1]), p.z.push_back(c[2]);
  }
  return p;
}

// A lattice of nx^dim points of spacing dx, each coordinate moved by up to +-pert dx, shuffled.
Points lattice(int nx, int dim, double dx, double pert, unsigned seed) {
  Points p;
  p.dim = dim;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-pert, pert);
  const int nz = dim == 3 ? nx : 1;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < nx; ++j)
      for (int i = 0; i < nx; ++i) {
        p.x.push_back((i + 0.5 + u(rng)) * dx);
        p.y.push_back((j + 0.5 + u(rng)) * dx);
        p.z.push_back(dim == 3 ? (k + 0.5 + u(rng)) * dx : 0.0);
      }
  std::vector<std::size_t> perm(p.n());
  for (std::size_t i = 0; i < perm.size(); ++i) perm[i] = i;
  std::shuffle(perm.begin(), perm.end(), rng);
  Points q = p;
  for (std::size_t i = 0; i < perm.size(); ++i)
    q.x[i] = p.x[perm[i]], q.y[i] = p.y[perm[i]], q.z[i] = p.z[perm[i]];
  return q;
}

// The cluster widths every test runs with: the default (8, by the API without a width), the 2D
// tiles' 4 (docs/performance-log.md, "SIMD tiles in 2D, measured by hand (stop 38)"), and 2, 1, 5.
const int kWidths[] = {kClusterSize, 4, 2, 1, 5};

ClusterLayout layout_of(const Points& p, double side, int width = kClusterSize) {
  ClusterLayout L;
  if (width == kClusterSize)
    build_cluster_layout(L, p.x.data(), p.y.data(), p.zp(), p.n(), p.dim, side);  // the default
  else
    build_cluster_layout(L, p.x.data(), p.y.data(), p.zp(), p.n(), p.dim, side, width);
  EXPECT_EQ(L.width, width);
  return L;
}

// Positions in slot order (padding far away), the boxes updated from them.
void refresh(ClusterLayout& L, const Points& p, double pad_offset) {
  std::vector<double> xs(L.slots()), ys(L.slots()), zs(L.slots());
  sphc::gather_positions(L, p.x.data(), p.y.data(), p.zp(), xs.data(), ys.data(),
                         p.dim == 3 ? zs.data() : nullptr, pad_offset);
  sphc::update_boxes(L, xs.data(), ys.data(), p.dim == 3 ? zs.data() : nullptr);
}

double dist2(const Points& a, std::size_t i, const Points& b, std::size_t j) {
  const double dx = a.x[i] - b.x[j], dy = a.y[i] - b.y[j], dz = a.z[i] - b.z[j];
  return dx * dx + dy * dy + dz * dz;
}

bool listed(const ClusterPairList& l, std::uint32_t ci, std::uint32_t cj) {
  return std::binary_search(l.j.begin() + l.begin[ci], l.j.begin() + l.begin[ci + 1], cj);
}

// The list's form: CSR of the right size, j increasing per i-cluster, j >= i for once.
void expect_well_formed(const ClusterLayout& a, const ClusterLayout& b, const ClusterPairList& l,
                        bool once) {
  ASSERT_EQ(l.begin.size(), a.n_clusters + 1);
  EXPECT_EQ(l.begin.front(), 0u);
  EXPECT_EQ(l.begin.back(), l.j.size());
  for (std::size_t ci = 0; ci < a.n_clusters; ++ci) {
    ASSERT_LE(l.begin[ci], l.begin[ci + 1]);
    for (std::uint32_t e = l.begin[ci]; e < l.begin[ci + 1]; ++e) {
      ASSERT_LT(l.j[e], b.n_clusters);
      if (e > l.begin[ci]) ASSERT_LT(l.j[e - 1], l.j[e]) << "i-cluster " << ci;
      if (once) ASSERT_GE(l.j[e], ci);
    }
  }
}

// Every pair within `radius` (brute force) in a listed cluster pair; returns the pairs
// (unordered for once, i in a x j in b for cross) within the radius.
long expect_complete(const Points& pa, const ClusterLayout& a, const Points& pb,
                     const ClusterLayout& b, const ClusterPairList& l, double radius, bool once) {
  long inside = 0, missing = 0;
  const double r2 = radius * radius;
  for (std::size_t i = 0; i < pa.n(); ++i)
    for (std::size_t j = once ? i : 0; j < pb.n(); ++j) {
      if (!(dist2(pa, i, pb, j) < r2)) continue;
      ++inside;
      std::uint32_t ci = a.slot_of[i] / a.width, cj = b.slot_of[j] / b.width;
      if (once && cj < ci) std::swap(ci, cj);
      if (!listed(l, ci, cj)) {
        if (++missing < 5) ADD_FAILURE() << "pair " << i << ", " << j << " (clusters " << ci << ", " << cj
                                         << ") within the radius, not listed";
      }
    }
  EXPECT_EQ(missing, 0);
  return inside;
}

// The layout: a permutation into slots, padding only at the end of a column's last cluster,
// real_mask consistent, each column's particles in the column's square, sorted by the last axis.
void expect_layout(const Points& p, const ClusterLayout& L) {
  ASSERT_EQ(L.n, p.n());
  ASSERT_EQ(L.slot.size(), L.slots());
  ASSERT_EQ(L.slot_of.size(), p.n());
  ASSERT_EQ(L.real_mask.size(), L.n_clusters);
  ASSERT_EQ(L.box.size(), 6 * L.n_clusters);
  ASSERT_EQ(L.column_begin.size(), L.columns[0] * L.columns[1] + 1);
  std::vector<int> seen(p.n(), 0);
  for (std::size_t s = 0; s < L.slots(); ++s) {
    const bool real = L.real_mask[s / L.width] >> (s % L.width) & 1u;
    if (L.slot[s] == kPadSlot) {
      ASSERT_FALSE(real);
      continue;
    }
    ASSERT_TRUE(real);
    ASSERT_LT(L.slot[s], p.n());
    ++seen[L.slot[s]];
    ASSERT_EQ(L.slot_of[L.slot[s]], s);
  }
  for (int c : seen) ASSERT_EQ(c, 1);
  const std::vector<double>& key = p.dim == 3 ? p.z : p.y;
  for (std::size_t col = 0; col + 1 < L.column_begin.size(); ++col) {
    const std::size_t c0 = L.column_begin[col], c1 = L.column_begin[col + 1];
    ASSERT_LE(c0, c1);
    for (std::size_t c = c0; c < c1; ++c) {
      const unsigned m = L.real_mask[c];
      ASSERT_NE(m, 0u);
      ASSERT_EQ(m & (m + 1), 0u) << "real slots first";
      ASSERT_EQ(m & ~unsigned{L.full_mask()}, 0u) << "bits only for the width's slots";
      if (c + 1 < c1) ASSERT_EQ(m, L.full_mask()) << "padding only in a column's last cluster";
    }
    const std::size_t cx = col % L.columns[0], cy = col / L.columns[0];
    double prev = -HUGE_VAL;
    for (std::size_t s = c0 * L.width; s < c1 * L.width; ++s) {
      if (L.slot[s] == kPadSlot) continue;
      const std::uint32_t q = L.slot[s];
      const double x0 = L.origin[0] + cx * L.column_side;
      EXPECT_GE(p.x[q], x0 - 1e-12 * L.column_side);
      EXPECT_LE(p.x[q], x0 + L.column_side * (1 + 1e-12));
      if (p.dim == 3) {
        const double y0 = L.origin[1] + cy * L.column_side;
        EXPECT_GE(p.y[q], y0 - 1e-12 * L.column_side);
        EXPECT_LE(p.y[q], y0 + L.column_side * (1 + 1e-12));
      }
      EXPECT_GE(key[q], prev);
      prev = key[q];
    }
  }
  // Boxes hold their real particles.
  for (std::size_t s = 0; s < L.slots(); ++s) {
    if (L.slot[s] == kPadSlot) continue;
    const double* b = &L.box[6 * (s / L.width)];
    const double q[3] = {p.x[L.slot[s]], p.y[L.slot[s]], p.dim == 3 ? p.z[L.slot[s]] : 0.0};
    for (int a = 0; a < 3; ++a) {
      EXPECT_LE(b[a], q[a]);
      EXPECT_GE(b[3 + a], q[a]);
    }
  }
}

struct Case {
  const char* name;
  Points p;
  double radius, side;
};

std::vector<Case> cases() {
  std::vector<Case> cs;
  // Random: ~30 neighbours within the radius in 3D, ~20 in 2D.
  cs.push_back({"random 3D", random_points(3000, 3, 1.0, 1), 0.134, 0.0});
  cs.push_back({"random 2D", random_points(2500, 2, 1.0, 2), 0.05, 0.0});
  cs.push_back({"lattice 3D", lattice(14, 3, 1.0 / 14, 0.05, 3), 2.2 * 1.5 / 14, 2.0 / 14});
  cs.push_back({"lattice 2D", lattice(50, 2, 1.0 / 50, 0.05, 4), 2.2 * 1.3 / 50, 0.0});
  cs.push_back({"blobs 3D (empty columns)", random_points(2000, 3, 1.0, 5, true), 0.06, 0.03});
  cs.push_back({"blobs 2D (empty columns)", random_points(2000, 2, 1.0, 6, true), 0.02, 0.01});
  // Columns wider than the radius and narrower.
  cs.push_back({"random 3D, wide columns", random_points(2000, 3, 1.0, 7), 0.1, 0.3});
  cs.push_back({"random 3D, thin columns", random_points(2000, 3, 1.0, 8), 0.15, 0.02});
  return cs;
}

TEST(ClusterPairs, LayoutIsAPermutationIntoSortedColumns) {
  for (int width : kWidths)
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    SCOPED_TRACE(width);
    const ClusterLayout L = layout_of(c.p, c.side, width);
    expect_layout(c.p, L);
    if (width == kClusterSize || (width == 4 && c.p.n() % 4 != 0))
      EXPECT_GT(L.slots(), L.n) << "the cases have padding";
    if (width == 1) EXPECT_EQ(L.slots(), L.n);
  }
}

TEST(ClusterPairs, OnceListsHoldEveryPairWithinTheRadius) {
  for (int width : kWidths)
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    SCOPED_TRACE(width);
    const ClusterLayout L = layout_of(c.p, c.side, width);
    ClusterPairList l;
    build_cluster_pairs(L, L, c.radius, true, l);
    expect_well_formed(L, L, l, true);
    const long inside = expect_complete(c.p, L, c.p, L, l, c.radius, true);
    EXPECT_GT(inside, static_cast<long>(4 * c.p.n()));
    // Every listed pair's boxes within the radius; the diagonal always listed.
    for (std::size_t ci = 0; ci < L.n_clusters; ++ci) {
      EXPECT_TRUE(listed(l, ci, ci));
      for (std::uint32_t e = l.begin[ci]; e < l.begin[ci + 1]; ++e) {
        const double *bi = &L.box[6 * ci], *bj = &L.box[6 * l.j[e]];
        double d2 = 0;
        for (int a = 0; a < 3; ++a) {
          const double g = std::max({0.0, bj[a] - bi[3 + a], bi[a] - bj[3 + a]});
          d2 += g * g;
        }
        EXPECT_LE(d2, c.radius * c.radius * (1 + 1e-9));
      }
    }
  }
}

TEST(ClusterPairs, CrossListsHoldEveryPairWithinTheRadius) {
  // Two arrays: a fluid block and a wall around it (a lattice and random points), 2D and 3D.
  for (int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    const Points fluid = dim == 3 ? lattice(12, 3, 1.0 / 14, 0.05, 11) : lattice(40, 2, 1.0 / 50, 0.05, 12);
    const Points wall = random_points(dim == 3 ? 1500 : 1200, dim, 1.0, 13);
    const double radius = dim == 3 ? 2.2 * 1.5 / 14 : 2.2 * 1.3 / 50;
    for (int wa : {kClusterSize, 4})
    for (int wb : {kClusterSize, 4})
    for (int dir = 0; dir < 2; ++dir) {
      SCOPED_TRACE(wa);
      SCOPED_TRACE(wb);
      const ClusterLayout a = layout_of(fluid, 0.0, wa), b = layout_of(wall, 0.0, wb);
      const ClusterLayout& A = dir ? b : a;
      const ClusterLayout& B = dir ? a : b;
      const Points& PA = dir ? wall : fluid;
      const Points& PB = dir ? fluid : wall;
      ClusterPairList l;
      build_cluster_pairs(A, B, radius, false, l);
      expect_well_formed(A, B, l, false);
      EXPECT_GT(expect_complete(PA, A, PB, B, l, radius, false), 1000);
    }
  }
}

TEST(ClusterPairs, PrunedListsKeepEveryPairAfterMovingByHalfTheSkin) {
  const double skin = 0.1;
  for (int width : kWidths)
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    SCOPED_TRACE(width);
    const double support = c.radius / (1 + skin);
    ClusterLayout L = layout_of(c.p, c.side, width);
    ClusterPairList outer, pruned, direct;
    build_cluster_pairs(L, L, c.radius, true, outer);
    // At the build's positions, pruning to the support gives the list built at the support.
    refresh(L, c.p, 1e6);
    prune_cluster_pairs(L, L, outer, support, pruned);
    build_cluster_pairs(L, L, support, true, direct);
    EXPECT_EQ(pruned.begin, direct.begin);
    EXPECT_EQ(pruned.j, direct.j);
    // Every particle moved by up to skin * support / 2 (a random direction and length).
    Points moved = c.p;
    std::mt19937_64 rng(99);
    std::normal_distribution<double> g;
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (std::size_t i = 0; i < moved.n(); ++i) {
      double d[3] = {g(rng), g(rng), c.p.dim == 3 ? g(rng) : 0.0};
      const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      const double s = 0.5 * skin * support * std::cbrt(u(rng)) / len * (1 - 1e-12);
      moved.x[i] += s * d[0], moved.y[i] += s * d[1], moved.z[i] += s * d[2];
    }
    refresh(L, moved, 1e6);
    prune_cluster_pairs(L, L, outer, support, pruned);
    expect_well_formed(L, L, pruned, true);
    EXPECT_LE(pruned.j.size(), outer.j.size());
    for (std::size_t ci = 0; ci < L.n_clusters; ++ci)
      for (std::uint32_t e = pruned.begin[ci]; e < pruned.begin[ci + 1]; ++e)
        ASSERT_TRUE(listed(outer, ci, pruned.j[e]));
    expect_complete(moved, L, moved, L, pruned, support, true);
    // The outer list rebuilt from the moved boxes (columns searched with their overhang)
    // holds every pair too; so does one from boxes moved across several columns.
    ClusterPairList again;
    build_cluster_pairs(L, L, c.radius, true, again);
    expect_complete(moved, L, moved, L, again, c.radius, true);
    Points far = c.p;
    for (std::size_t i = 0; i < far.n(); ++i) far.x[i] += 3 * L.column_side * std::sin(37.0 * i);
    refresh(L, far, 1e6);
    build_cluster_pairs(L, L, c.radius, true, again);
    expect_well_formed(L, L, again, true);
    expect_complete(far, L, far, L, again, c.radius, true);
  }
}

TEST(ClusterPairs, GatherAndAddRoundTripExactly) {
  for (int width : kWidths)
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    SCOPED_TRACE(width);
    const ClusterLayout L = layout_of(c.p, c.side, width);
    std::vector<double> v(c.p.n());
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (double& q : v) q = u(rng);
    std::vector<double> s(L.slots(), -7.0), back(c.p.n(), 0.0);
    sphc::gather_slots(L, v.data(), s.data());
    for (std::size_t k = 0; k < L.slots(); ++k) {
      const std::size_t first = k / L.width * L.width;
      EXPECT_EQ(s[k], v[L.slot[k] == kPadSlot ? L.slot[first] : L.slot[k]]);
    }
    // gather_slots_doubled (the 2xMM tiles' copies, stop 39): each cluster's values twice.
    std::vector<double> s2(2 * L.slots(), -7.0);
    sphc::gather_slots_doubled(L, v.data(), s2.data());
    for (std::size_t k = 0; k < L.slots(); ++k) {
      const std::size_t c = k / L.width, at = 2 * c * L.width + k % L.width;
      EXPECT_EQ(s2[at], s[k]);
      EXPECT_EQ(s2[at + L.width], s[k]);
    }
    {  // the arrays' form (one call for several copies, tilemerge): the same values
      std::vector<double> w(v.size());
      for (std::size_t i = 0; i < v.size(); ++i) w[i] = -v[i];
      std::vector<double> a2(2 * L.slots(), -5.0), b2(2 * L.slots(), -5.0);
      const double* from[] = {v.data(), w.data()};
      double* to[] = {a2.data(), b2.data()};
      sphc::gather_slots_doubled(L, from, to, 2);
      EXPECT_EQ(a2, s2);
      for (std::size_t k = 0; k < s2.size(); ++k) EXPECT_EQ(b2[k], -s2[k]);
    }
    sphc::add_slots(L, s.data(), back.data());
    EXPECT_EQ(back, v);
    // add_slots adds to what is there; padding slots are never read.
    for (std::size_t k = 0; k < L.slots(); ++k)
      if (L.slot[k] == kPadSlot) s[k] = NAN;
    sphc::add_slots(L, s.data(), back.data());
    for (std::size_t i = 0; i < v.size(); ++i) EXPECT_EQ(back[i], 2 * v[i]);
    // float
    std::vector<float> vf(v.begin(), v.end()), sf(L.slots()), bf(c.p.n(), 0.0f);
    sphc::gather_slots(L, vf.data(), sf.data());
    sphc::add_slots(L, sf.data(), bf.data());
    EXPECT_EQ(bf, vf);
  }
}

// Stop 39: the per-evaluation pieces in one call each give exactly the values of the calls
// they replace: gather_positions_boxes = gather_positions then update_boxes (positions,
// padding and boxes bit for bit), gather_slots and add_slots of several arrays = one call per
// array; with parallel = false too.
TEST(ClusterPairs, OnePassPiecesEqualTheCallsTheyReplace) {
  for (int width : kWidths)
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    SCOPED_TRACE(width);
    const ClusterLayout built = layout_of(c.p, c.side, width);
    // Moved since the build (boxes change).
    std::vector<double> x = c.p.x, y = c.p.y, z = c.p.dim == 3 ? c.p.z : std::vector<double>();
    for (std::size_t i = 0; i < x.size(); ++i) {
      x[i] += 0.03 * c.radius * std::sin(1.0 + i), y[i] += 0.03 * c.radius * std::cos(2.0 * i);
      if (c.p.dim == 3) z[i] -= 0.02 * c.radius * std::sin(3.0 * i);
    }
    const double* zp = c.p.dim == 3 ? z.data() : nullptr;
    const double pad = 3.0 * c.radius;
    const std::size_t S = built.slots();
    for (bool parallel : {true, false}) {
      SCOPED_TRACE(parallel);
      ClusterLayout a = built, b = built;
      std::vector<double> xa(S, -1.0), ya(S, -1.0), za(S, -1.0), xb(S, -2.0), yb(S, -2.0), zb(S, -2.0);
      sphc::gather_positions(a, x.data(), y.data(), zp, xa.data(), ya.data(), c.p.dim == 3 ? za.data() : nullptr, pad);
      sphc::update_boxes(a, xa.data(), ya.data(), c.p.dim == 3 ? za.data() : nullptr);
      sphc::gather_positions_boxes(b, x.data(), y.data(), zp, xb.data(), yb.data(),
                                   c.p.dim == 3 ? zb.data() : nullptr, pad, parallel);
      EXPECT_EQ(xa, xb);
      EXPECT_EQ(ya, yb);
      if (c.p.dim == 3) EXPECT_EQ(za, zb);
      EXPECT_EQ(a.box, b.box);
      if (x.size() > 0) EXPECT_NE(a.box, built.box);
      // Three arrays gathered and added back.
      std::mt19937_64 rng(11);
      std::uniform_real_distribution<double> u(-1.0, 1.0);
      std::vector<std::vector<double>> v(3, std::vector<double>(x.size()));
      for (auto& w : v)
        for (double& q : w) q = u(rng);
      std::vector<std::vector<double>> one(3, std::vector<double>(S, 5.0)), all(3, std::vector<double>(S, 6.0));
      for (int k = 0; k < 3; ++k) sphc::gather_slots(a, v[k].data(), one[k].data());
      const double* from[3] = {v[0].data(), v[1].data(), v[2].data()};
      double* to[3] = {all[0].data(), all[1].data(), all[2].data()};
      sphc::gather_slots(a, from, to, 3, parallel);
      EXPECT_EQ(one, all);
      std::vector<std::vector<double>> back1(3, std::vector<double>(x.size(), 0.5)), back3 = back1;
      for (int k = 0; k < 3; ++k)
        for (std::size_t s2 = 0; s2 < S; ++s2) one[k][s2] = u(rng);
      for (int k = 0; k < 3; ++k) sphc::add_slots(a, one[k].data(), back1[k].data());
      const double* sums[3] = {one[0].data(), one[1].data(), one[2].data()};
      double* into[3] = {back3[0].data(), back3[1].data(), back3[2].data()};
      sphc::add_slots(a, sums, into, 3, parallel);
      EXPECT_EQ(back1, back3);
      // None: nothing written.
      sphc::gather_slots(a, from, to, 0, parallel);
      sphc::add_slots(a, sums, into, 0, parallel);
      EXPECT_EQ(back1, back3);
    }
  }
}

TEST(ClusterPairs, PaddingPositionsLieFarFromEveryRealParticle) {
  for (int width : kWidths)
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    SCOPED_TRACE(width);
    ClusterLayout L = layout_of(c.p, c.side, width);
    const double pad = 3.0 * c.radius;
    std::vector<double> xs(L.slots()), ys(L.slots()), zs(L.slots());
    sphc::gather_positions(L, c.p.x.data(), c.p.y.data(), c.p.zp(), xs.data(), ys.data(),
                           c.p.dim == 3 ? zs.data() : nullptr, pad);
    long pads = 0;
    for (std::size_t k = 0; k < L.slots(); ++k) {
      if (L.slot[k] != kPadSlot) {
        EXPECT_EQ(xs[k], c.p.x[L.slot[k]]);
        EXPECT_EQ(ys[k], c.p.y[L.slot[k]]);
        if (c.p.dim == 3) EXPECT_EQ(zs[k], c.p.z[L.slot[k]]);
        continue;
      }
      ++pads;
      ASSERT_TRUE(std::isfinite(xs[k]) && std::isfinite(ys[k]) && (c.p.dim == 2 || std::isfinite(zs[k])));
      for (std::size_t i = 0; i < c.p.n(); ++i) {
        const double dx = xs[k] - c.p.x[i], dy = ys[k] - c.p.y[i], dz = c.p.dim == 3 ? zs[k] - c.p.z[i] : 0.0;
        ASSERT_GE(std::sqrt(dx * dx + dy * dy + dz * dz), pad);
      }
      // As far from every other padding slot (up to the rounding of x + k pad_offset).
      for (std::size_t q = 0; q < k; ++q)
        if (L.slot[q] == kPadSlot) ASSERT_GE(std::fabs(xs[k] - xs[q]), pad * (1 - 1e-12));
    }
    if (width == kClusterSize || (width == 4 && c.p.n() % 4 != 0)) EXPECT_GT(pads, 0);
    // The boxes from these positions are those of the build (padding not in a box).
    const std::vector<double> built = L.box;
    sphc::update_boxes(L, xs.data(), ys.data(), c.p.dim == 3 ? zs.data() : nullptr);
    EXPECT_EQ(L.box, built);
  }
}

// The way a tile loop uses the pieces: positions and a property into slot order, every lane of
// every tile of the pruned list computed (padding lanes too, no test of real_mask: only the
// cut-off), each pair once with i's and j's sums in slot order, added back: the sums of a brute
// force over all pairs (the same terms, summed in another order: 1e-12 of the largest).
TEST(ClusterPairs, TilesOverThePrunedListGiveTheBruteForceSums) {
  for (int width : kWidths)
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    SCOPED_TRACE(width);
    const double support = c.radius / 1.1, r2 = support * support;
    ClusterLayout L = layout_of(c.p, c.side, width);
    ClusterPairList outer, pruned;
    build_cluster_pairs(L, L, c.radius, true, outer);
    // Each particle moved by less than half the skin (0.02 support per coordinate: at most
    // 0.035 support in 3D; clusters of 1 have no box slack beyond the rule's).
    Points moved = c.p;
    for (std::size_t i = 0; i < moved.n(); ++i) {
      moved.x[i] += 0.02 * support * std::sin(1.7 * i);
      moved.y[i] += 0.02 * support * std::cos(2.3 * i);
      if (c.p.dim == 3) moved.z[i] += 0.02 * support * std::sin(0.9 * i + 1);
    }
    std::vector<double> m(moved.n());
    for (std::size_t i = 0; i < m.size(); ++i) m[i] = 1.0 + 0.5 * std::sin(0.37 * i);
    const std::size_t S = L.slots();
    std::vector<double> xs(S), ys(S), zs(S, 0.0), ms(S), sums(S, 0.0);
    sphc::gather_positions(L, moved.x.data(), moved.y.data(), moved.zp(), xs.data(), ys.data(),
                           c.p.dim == 3 ? zs.data() : nullptr, 2 * support);
    sphc::gather_slots(L, m.data(), ms.data());
    sphc::update_boxes(L, xs.data(), ys.data(), c.p.dim == 3 ? zs.data() : nullptr);
    prune_cluster_pairs(L, L, outer, support, pruned);
    // Term of pair (i, j) for i: m_j (r2 - r^2); for j: m_i (r2 - r^2).
    for (std::size_t ci = 0; ci < L.n_clusters; ++ci)
      for (std::uint32_t e = pruned.begin[ci]; e < pruned.begin[ci + 1]; ++e) {
        const std::size_t cj = pruned.j[e];
        const std::size_t W = static_cast<std::size_t>(L.width);
        for (std::size_t i = ci * W; i < (ci + 1) * W; ++i)
          for (std::size_t j = cj * W; j < (cj + 1) * W; ++j) {
            const double dx = xs[i] - xs[j], dy = ys[i] - ys[j], dz = zs[i] - zs[j];
            const double q = dx * dx + dy * dy + dz * dz;
            const bool lane = q < r2 && (cj != ci || j > i);  // the mask
            const double w = r2 - q;
            sums[i] += lane ? ms[j] * w : 0.0;
            sums[j] += lane ? ms[i] * w : 0.0;
          }
      }
    std::vector<double> got(moved.n(), 0.0), want(moved.n(), 0.0);
    sphc::add_slots(L, sums.data(), got.data());
    double scale = 0;
    for (std::size_t i = 0; i < moved.n(); ++i)
      for (std::size_t j = i + 1; j < moved.n(); ++j) {
        const double q = dist2(moved, i, moved, j);
        if (!(q < r2)) continue;
        want[i] += m[j] * (r2 - q);
        want[j] += m[i] * (r2 - q);
      }
    for (double v : want) scale = std::max(scale, std::fabs(v));
    ASSERT_GT(scale, 0);
    for (std::size_t i = 0; i < moved.n(); ++i) ASSERT_NEAR(got[i], want[i], 1e-12 * scale) << "particle " << i;
  }
}

TEST(ClusterPairs, SmallAndDegenerateInputs) {
  // None, fewer than a cluster, all at one point, a stray particle far away (columns widened).
  for (int width : {kClusterSize, 4})
  for (int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    SCOPED_TRACE(width);
    Points none;
    none.dim = dim;
    ClusterLayout L = layout_of(none, 0.0, width);
    EXPECT_EQ(L.n_clusters, 0u);
    ClusterPairList l;
    build_cluster_pairs(L, L, 1.0, true, l);
    EXPECT_EQ(l.begin.size(), 1u);
    EXPECT_TRUE(l.j.empty());

    Points few = random_points(5, dim, 1.0, 21);
    L = layout_of(few, 0.0, width);
    expect_layout(few, L);
    build_cluster_pairs(L, L, 2.0, true, l);
    expect_well_formed(L, L, l, true);
    EXPECT_EQ(l.j.size(), L.n_clusters * (L.n_clusters + 1) / 2) << "all within the radius";
    L = layout_of(few, 10.0, width);
    EXPECT_EQ(L.n_clusters, (few.n() + width - 1) / width) << "one column";
    if (width >= 5) {
      build_cluster_pairs(L, L, 0.1, true, l);
      EXPECT_EQ(l.j, std::vector<std::uint32_t>{0});
    }

    Points same = random_points(20, dim, 1.0, 22);
    for (std::size_t i = 0; i < same.n(); ++i) same.x[i] = 0.5, same.y[i] = 0.5, same.z[i] = dim == 3 ? 0.5 : 0;
    L = layout_of(same, 0.0, width);
    expect_layout(same, L);
    build_cluster_pairs(L, L, 0.1, true, l);
    expect_complete(same, L, same, L, l, 0.1, true);

    // A flat wall (3D: a lattice in the plane y = 0.3; 2D: the line y = 0.3): columns of
    // about 8^(1/k) spacings over the k axes it extends along.
    Points wall;
    wall.dim = dim;
    for (int i = 0; i < 30; ++i)
      for (int k = 0; k < (dim == 3 ? 30 : 1); ++k) {
        wall.x.push_back((i + 0.5) / 30);
        wall.y.push_back(0.3);
        wall.z.push_back(dim == 3 ? (k + 0.5) / 30 : 0.0);
      }
    L = layout_of(wall, 0.0, width);
    expect_layout(wall, L);
    EXPECT_NEAR(L.column_side * 30, dim == 3 ? std::sqrt(double(width)) : double(width), 0.5);
    build_cluster_pairs(L, L, 0.1, true, l);
    expect_complete(wall, L, wall, L, l, 0.1, true);

    Points stray = random_points(1000, dim, 1.0, 23);
    stray.x[17] = 1e9, stray.y[17] = -1e9;
    L = layout_of(stray, 0.01, width);
    expect_layout(stray, L);
    EXPECT_LE(L.columns[0] * L.columns[1], 4 * stray.n() + 16);
    build_cluster_pairs(L, L, 0.12, true, l);
    expect_well_formed(L, L, l, true);
    expect_complete(stray, L, stray, L, l, 0.12, true);
  }
}

}  // namespace

// Particles kept in the tiles' slot order (stop 40): cluster_order is a permutation; the
// particles permuted into it give an in-order layout (slot s = particle s, only the last
// cluster padded) whose once lists hold every pair within the radius (j increasing, j >= i),
// whose clusters are compact (about as many cluster pairs as the sorted layout's), and whose
// padded tail (gather_tail, tail_positions, positions_doubled_boxes) holds the last cluster's
// values with its padding far from every particle.
TEST(ClusterPairs, InOrderLayoutsOfTheClusterOrderHoldEveryPair) {
  for (int width : kWidths)
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    SCOPED_TRACE(width);
    std::vector<std::uint32_t> order;
    sphc::cluster_order(order, c.p.x.data(), c.p.y.data(), c.p.zp(), c.p.n(), c.p.dim, c.side, width);
    ASSERT_EQ(order.size(), c.p.n());
    {
      std::vector<std::uint32_t> sorted = order;
      std::sort(sorted.begin(), sorted.end());
      for (std::size_t i = 0; i < sorted.size(); ++i) ASSERT_EQ(sorted[i], i);
    }
    Points q = c.p;
    for (std::size_t i = 0; i < order.size(); ++i)
      q.x[i] = c.p.x[order[i]], q.y[i] = c.p.y[order[i]], q.z[i] = c.p.z[order[i]];
    ClusterLayout L;
    sphc::build_cluster_layout_in_order(L, q.x.data(), q.y.data(), q.zp(), q.n(), q.dim, c.side, width);
    ASSERT_TRUE(L.in_order);
    ASSERT_EQ(L.n_clusters, (q.n() + width - 1) / width);
    for (std::size_t s = 0; s < L.slots(); ++s) ASSERT_EQ(L.slot[s], s < q.n() ? s : kPadSlot);
    for (std::size_t c2 = 0; c2 + 1 < L.n_clusters; ++c2) ASSERT_EQ(L.real_mask[c2], L.full_mask());
    ASSERT_EQ(L.column_cluster.size(), L.n_clusters);
    ClusterPairList l;
    build_cluster_pairs(L, L, c.radius, true, l);
    expect_well_formed(L, L, l, true);
    EXPECT_GT(expect_complete(q, L, q, L, l, c.radius, true), static_cast<long>(4 * q.n()));
    // Compact: the sorted layout's cluster pairs (of more clusters, with padding) x 1.25 at most.
    const ClusterLayout S = layout_of(c.p, c.side, width);
    ClusterPairList ls;
    build_cluster_pairs(S, S, c.radius, true, ls);
    EXPECT_LE(l.pairs(), 1.25 * ls.pairs() + 16);
    // The tail.
    const std::size_t t = sphc::tail_cluster(L);
    if (q.n() % width == 0) {
      EXPECT_EQ(t, L.n_clusters);
      continue;
    }
    ASSERT_EQ(t, L.n_clusters - 1);
    const double pad = 3 * c.radius;
    std::vector<double> tx(width), ty(width), tz(width), tm(width);
    sphc::tail_positions(L, q.x.data(), q.y.data(), q.zp(), tx.data(), ty.data(), tz.data(), pad);
    const double* src[] = {q.y.data()};
    double* dst[] = {tm.data()};
    sphc::gather_tail(L, src, dst, 1);
    const std::size_t s0 = t * width;
    for (int k = 0; k < width; ++k) {
      if (s0 + k < q.n()) {
        EXPECT_EQ(tx[k], q.x[s0 + k]);
        EXPECT_EQ(tm[k], q.y[s0 + k]);
      } else {
        EXPECT_EQ(tm[k], q.y[s0]);
        for (std::size_t i = 0; i < q.n(); ++i) ASSERT_GE(std::fabs(tx[k] - q.x[i]), pad * (1 - 1e-12));
      }
    }
    if (width == 4) {  // the 2xMM tiles' doubled positions: the same values twice
      std::vector<double> x2(2 * L.slots()), y2(2 * L.slots()), z2(2 * L.slots());
      ClusterLayout L2 = L;
      sphc::positions_doubled_boxes(L2, q.x.data(), q.y.data(), q.zp(), x2.data(), y2.data(),
                                    q.dim == 3 ? z2.data() : nullptr, pad);
      EXPECT_EQ(L2.box, L.box);
      for (std::size_t s = 0; s < L.slots(); ++s) {
        const std::size_t cl = s / 4, k = s % 4;
        const double want = s < q.n() ? q.x[s] : tx[k];
        ASSERT_EQ(x2[8 * cl + k], want);
        ASSERT_EQ(x2[8 * cl + 4 + k], want);
      }
      // The doubled copies of an in-order layout: contiguous reads, the same values.
      std::vector<double> d2(2 * L.slots()), d2ref(2 * L.slots());
      const double* s1[] = {q.y.data()};
      double* o1[] = {d2.data()};
      sphc::gather_slots_doubled(L, s1, o1, 1);
      sphc::gather_slots_doubled(L, q.y.data(), d2ref.data());
      EXPECT_EQ(d2, d2ref);
    }
  }
}

// The OpenMP tiles' blocks (stop 41, sphc::tile_block_cuts): contiguous blocks covering every
// i-cluster, clamped to [1, n_clusters]; on the cube's lattice in cluster order each block's
// work (whole tiles 1, a tile across blocks 0.55 in the i's block and 0.85 in the j's, counted
// by brute force) within 2% of the mean, and no block more than the pair cuts' largest.
TEST(ClusterPairs, TileBlockCutsBalanceTheHalfTiles) {
  {
    std::vector<int> cut;
    sphc::tile_block_cuts(ClusterPairList{}, 4, cut);
    EXPECT_EQ(cut, (std::vector<int>{0, 0}));
    ClusterPairList two;
    two.begin = {0, 2, 3};
    two.j = {0, 1, 1};
    sphc::tile_block_cuts(two, 8, cut);
    EXPECT_EQ(cut.size(), 3u);
    EXPECT_EQ(cut.front(), 0);
    EXPECT_EQ(cut.back(), 2);
    sphc::tile_block_cuts(two, 1, cut);
    EXPECT_EQ(cut, (std::vector<int>{0, 2}));
    sphc::tile_block_cuts(two, 0, cut);
    EXPECT_EQ(cut, (std::vector<int>{0, 2}));
  }
  const int nx = 32;
  const Points p0 = lattice(nx, 3, 1.0 / nx, 0.05, 3);
  std::vector<std::uint32_t> order;
  sphc::cluster_order(order, p0.x.data(), p0.y.data(), p0.zp(), p0.n(), 3, 0.0, kClusterSize);
  Points q = p0;
  for (std::size_t i = 0; i < order.size(); ++i)
    q.x[i] = p0.x[order[i]], q.y[i] = p0.y[order[i]], q.z[i] = p0.z[order[i]];
  ClusterLayout L;
  sphc::build_cluster_layout_in_order(L, q.x.data(), q.y.data(), q.zp(), q.n(), 3, 0.0, kClusterSize);
  ClusterPairList l;
  build_cluster_pairs(L, L, 2.0 * 1.5 / nx, true, l);
  const int nc = static_cast<int>(L.n_clusters);
  auto work = [&](const std::vector<int>& cut) {
    const int B = static_cast<int>(cut.size()) - 1;
    std::vector<double> w(B, 0.0);
    auto block = [&](int c) { return static_cast<int>(std::upper_bound(cut.begin() + 1, cut.end() - 1, c) - cut.begin()) - 1; };
    for (int i = 0; i < nc; ++i)
      for (std::uint32_t e = l.begin[i]; e < l.begin[i + 1]; ++e) {
        const int bi = block(i), bj = block(static_cast<int>(l.j[e]));
        if (bi == bj) w[bi] += 1.0;
        else w[bi] += 0.55, w[bj] += 0.85;
      }
    return w;
  };
  for (int B : {2, 3, 4}) {
    SCOPED_TRACE(B);
    std::vector<int> cut;
    sphc::tile_block_cuts(l, B, cut);
    ASSERT_EQ(cut.size(), static_cast<std::size_t>(B) + 1);
    EXPECT_EQ(cut.front(), 0);
    EXPECT_EQ(cut.back(), nc);
    for (int k = 0; k < B; ++k) EXPECT_LT(cut[k], cut[k + 1]);
    const std::vector<double> w = work(cut);
    double mean = 0;
    for (double v : w) mean += v / B;
    for (double v : w) EXPECT_NEAR(v, mean, 0.02 * mean);
    // The cuts by pairs (stop 38-40's printed blocks).
    std::vector<int> by_pairs(B + 1, nc);
    by_pairs[0] = 0;
    for (int k = 1; k < B; ++k)
      by_pairs[k] = static_cast<int>(std::lower_bound(l.begin.begin(), l.begin.end() - 1,
                                                      static_cast<std::uint32_t>(static_cast<std::uint64_t>(l.pairs()) * k / B)) - l.begin.begin());
    const std::vector<double> wp = work(by_pairs);
    EXPECT_LE(*std::max_element(w.begin(), w.end()), *std::max_element(wp.begin(), wp.end()));
  }
}
