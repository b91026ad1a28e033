// The OpenMP runtime's cluster-pair lists (sphc/cluster_pairs.h): the outer list's build and
// the pruning in blocks of i-clusters, one per thread, give the lists of one thread exactly,
// for 1..4 threads; gathers, adds and boxes too.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "sphc/cluster_pairs.h"

namespace {

class ClusterPairsOmp : public ::testing::Test {
 protected:
  void TearDown() override { omp_set_num_threads(saved_); }
  int saved_ = omp_get_max_threads();
};

struct Lists {
  sphc::ClusterLayout layout;
  sphc::ClusterPairList outer, pruned, cross;
  std::vector<double> gathered, added;
  // Stop 39: the one-call pieces (parallel and not).
  std::vector<double> xs1, gathered3, added3;
  std::vector<double> box1;
  sphc::ClusterPairList pruned_serial;
};

Lists lists_with(int threads, int dim, int width) {
  omp_set_num_threads(threads);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::size_t n = dim == 3 ? 4000 : 3000;
  std::vector<double> x(n), y(n), z(n), v(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = u(rng), y[i] = u(rng), z[i] = dim == 3 ? u(rng) : 0.0, v[i] = u(rng);
  const double radius = dim == 3 ? 0.12 : 0.045;
  Lists l;
  sphc::build_cluster_layout(l.layout, x.data(), y.data(), z.data(), n, dim, 0.0, width);
  sphc::build_cluster_pairs(l.layout, l.layout, radius, true, l.outer);
  for (std::size_t i = 0; i < n; ++i) x[i] += 0.02 * radius * std::sin(3.0 * i), y[i] += 0.02 * radius * std::cos(5.0 * i);
  const std::size_t S = l.layout.slots();
  std::vector<double> xs(S), ys(S), zs(S);
  sphc::gather_positions(l.layout, x.data(), y.data(), z.data(), xs.data(), ys.data(), zs.data(), 10.0);
  sphc::update_boxes(l.layout, xs.data(), ys.data(), zs.data());
  sphc::prune_cluster_pairs(l.layout, l.layout, l.outer, radius / 1.1, l.pruned);
  sphc::build_cluster_pairs(l.layout, l.layout, radius, false, l.cross);
  l.gathered.resize(S);
  sphc::gather_slots(l.layout, v.data(), l.gathered.data());
  l.added.assign(n, 1.0);
  sphc::add_slots(l.layout, l.gathered.data(), l.added.data());
  // The one-call pieces: positions and boxes in one pass, three arrays gathered and added.
  sphc::ClusterLayout L2 = l.layout;
  std::vector<double> xs2(S), ys2(S), zs2(S);
  sphc::gather_positions_boxes(L2, x.data(), y.data(), z.data(), xs2.data(), ys2.data(), zs2.data(), 10.0);
  l.xs1 = xs2;
  l.xs1.insert(l.xs1.end(), ys2.begin(), ys2.end());
  if (dim == 3) l.xs1.insert(l.xs1.end(), zs2.begin(), zs2.end());
  l.box1 = L2.box;
  std::vector<double> v2(n), v3(n);
  for (std::size_t i = 0; i < n; ++i) v2[i] = std::sin(1.0 * i), v3[i] = std::cos(1.0 * i);
  std::vector<double> g1(S), g2(S), g3(S);
  const double* from[3] = {v.data(), v2.data(), v3.data()};
  double* to[3] = {g1.data(), g2.data(), g3.data()};
  sphc::gather_slots(l.layout, from, to, 3);
  l.gathered3 = g1;
  l.gathered3.insert(l.gathered3.end(), g2.begin(), g2.end());
  l.gathered3.insert(l.gathered3.end(), g3.begin(), g3.end());
  std::vector<double> b1(n, 1.0), b2(n, 2.0), b3(n, 3.0);
  const double* sums[3] = {g1.data(), g2.data(), g3.data()};
  double* into[3] = {b1.data(), b2.data(), b3.data()};
  sphc::add_slots(l.layout, sums, into, 3);
  l.added3 = b1;
  l.added3.insert(l.added3.end(), b2.begin(), b2.end());
  l.added3.insert(l.added3.end(), b3.begin(), b3.end());
  sphc::prune_cluster_pairs(l.layout, l.layout, l.outer, radius / 1.1, l.pruned_serial, /*parallel=*/false);
  // The serial calls' values: positions then boxes as gather_positions and update_boxes gave.
  EXPECT_EQ(L2.box, l.layout.box);
  for (std::size_t s2 = 0; s2 < S; ++s2) EXPECT_EQ(xs2[s2], xs[s2]);
  EXPECT_EQ(g1, l.gathered);
  EXPECT_EQ(b1, l.added);
  return l;
}

TEST_F(ClusterPairsOmp, ListsOfAnyThreadCountEqualOneThreads) {
  for (int width : {sphc::kClusterSize, 4})
  for (int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    SCOPED_TRACE(width);
    const Lists one = lists_with(1, dim, width);
    EXPECT_GT(one.pruned.j.size(), 0u);
    EXPECT_LT(one.pruned.j.size(), one.outer.j.size());
    for (int t = 2; t <= 4; ++t) {
      SCOPED_TRACE(t);
      const Lists l = lists_with(t, dim, width);
      EXPECT_EQ(l.layout.slot, one.layout.slot);
      EXPECT_EQ(l.layout.box, one.layout.box);
      EXPECT_EQ(l.outer.begin, one.outer.begin);
      EXPECT_EQ(l.outer.j, one.outer.j);
      EXPECT_EQ(l.pruned.begin, one.pruned.begin);
      EXPECT_EQ(l.pruned.j, one.pruned.j);
      EXPECT_EQ(l.cross.begin, one.cross.begin);
      EXPECT_EQ(l.cross.j, one.cross.j);
      EXPECT_EQ(l.gathered, one.gathered);
      EXPECT_EQ(l.added, one.added);
      EXPECT_EQ(l.xs1, one.xs1);
      EXPECT_EQ(l.box1, one.box1);
      EXPECT_EQ(l.gathered3, one.gathered3);
      EXPECT_EQ(l.added3, one.added3);
      EXPECT_EQ(l.pruned_serial.begin, one.pruned.begin);
      EXPECT_EQ(l.pruned_serial.j, one.pruned.j);
    }
  }
}

// n random particles in the unit square (2D) or cube (3D), with ties in the layouts' sort
// key (every tie_every-th particle at the height tie).
struct Cloud {
  std::vector<double> x, y, z;
};
Cloud random_cloud(int dim, std::size_t n, unsigned seed, std::size_t tie_every, double tie) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Cloud c{std::vector<double>(n), std::vector<double>(n), std::vector<double>(n)};
  for (std::size_t i = 0; i < n; ++i) c.x[i] = u(rng), c.y[i] = u(rng), c.z[i] = dim == 3 ? u(rng) : 0.0;
  for (std::size_t i = 0; i < n; i += tie_every) (dim == 3 ? c.z : c.y)[i] = tie;
  return c;
}

// The fields every layout builder fills, equal between two layouts.
void expect_same_slots(const sphc::ClusterLayout& l, const sphc::ClusterLayout& one) {
  EXPECT_EQ(l.slot, one.slot);
  EXPECT_EQ(l.slot_of, one.slot_of);
  EXPECT_EQ(l.column_begin, one.column_begin);
  EXPECT_EQ(l.box, one.box);
  EXPECT_EQ(l.origin[0], one.origin[0]);
  EXPECT_EQ(l.origin[1], one.origin[1]);
}

// Stop 39: the layout's columns sorted and cut into slots in parallel (from 10,000
// particles): the same layout as one thread's, boxes included.
TEST_F(ClusterPairsOmp, LargeLayoutsOfAnyThreadCountEqualOneThreads) {
  for (int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    const std::size_t n = 30000;
    Cloud c = random_cloud(dim, n, 9, 97, 0.5);
    std::vector<double>&x = c.x, &y = c.y, &z = c.z;
    omp_set_num_threads(1);
    sphc::ClusterLayout one;
    sphc::build_cluster_layout(one, x.data(), y.data(), z.data(), n, dim, 0.0);
    for (int t = 2; t <= 4; ++t) {
      SCOPED_TRACE(t);
      omp_set_num_threads(t);
      sphc::ClusterLayout l;
      sphc::build_cluster_layout(l, x.data(), y.data(), z.data(), n, dim, 0.0);
      expect_same_slots(l, one);
      EXPECT_EQ(l.real_mask, one.real_mask);
      EXPECT_EQ(l.columns[0], one.columns[0]);
      EXPECT_EQ(l.columns[1], one.columns[1]);
    }
  }
}

// Stop 41: the rebuild path of the tiles' slot order in parallel (the extent, the counting
// sort into columns, cluster_order's slots without boxes, the in-order layout's slots): the
// same order and layouts as one thread's, with a NaN coordinate and ties in the sort key.
TEST_F(ClusterPairsOmp, ClusterOrderAndInOrderLayoutsOfAnyThreadCountEqualOneThreads) {
  for (int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    const std::size_t n = 40001;
    Cloud c = random_cloud(dim, n, 11, 89, 0.25);
    std::vector<double>&x = c.x, &y = c.y, &z = c.z;
    x[n / 3] = std::nan("");
    auto run = [&](int t, std::vector<std::uint32_t>& order, sphc::ClusterLayout& in) {
      omp_set_num_threads(t);
      sphc::cluster_order(order, x.data(), y.data(), z.data(), n, dim, 0.0, sphc::kClusterSize);
      std::vector<double> px(n), py(n), pz(n);
      for (std::size_t i = 0; i < n; ++i) px[i] = x[order[i]], py[i] = y[order[i]], pz[i] = z[order[i]];
      sphc::build_cluster_layout_in_order(in, px.data(), py.data(), pz.data(), n, dim, 0.0, sphc::kClusterSize);
    };
    std::vector<std::uint32_t> order1;
    sphc::ClusterLayout in1;
    run(1, order1, in1);
    for (int t = 2; t <= 4; ++t) {
      SCOPED_TRACE(t);
      std::vector<std::uint32_t> order;
      sphc::ClusterLayout in;
      run(t, order, in);
      EXPECT_EQ(order, order1);
      expect_same_slots(in, in1);
      EXPECT_EQ(in.column_cluster, in1.column_cluster);
      EXPECT_EQ(in.column_side, in1.column_side);
    }
  }
}

}  // namespace
