// Shared by the unit tests of the serial runtime (test_nnps_parallel.cpp) and of the OpenMP
// runtime (omp/test_omp_runtime.cpp): particle sets that exercise the cell-list sort, and the
// comparison of two builds (same cells, same order, same cell tables: the candidate order of
// every query is then the same, so every sum over neighbours is bitwise the same).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "sphc/nnps.h"

namespace sphc_test {

struct Points {
  std::vector<double> x, y, z;
  std::size_t size() const { return x.size(); }
};

// n points in [0, 10]^dim, half of them in a few dense clusters (cells with many particles,
// many empty cells), plus points outside the domain and NaN coordinates (clamped cells).
inline Points clustered_points(std::size_t n, int dim, unsigned seed) {
  Points p;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 10.0), near(-0.3, 0.3);
  const double centres[3][3] = {{2, 2, 2}, {7, 3, 5}, {5, 8, 1}};
  for (std::size_t i = 0; i < n; ++i) {
    double c[3];
    for (int a = 0; a < 3; ++a) c[a] = i % 2 ? u(rng) : centres[i % 3][a] + near(rng);
    if (i % 997 == 5) c[0] = 25.0;  // beyond the domain
    if (i % 1009 == 7) c[dim - 1] = std::numeric_limits<double>::quiet_NaN();
    p.x.push_back(c[0]);
    p.y.push_back(dim >= 2 ? c[1] : 0.0);
    p.z.push_back(dim == 3 ? c[2] : 0.0);
  }
  return p;
}

inline sphc::SearchDomain domain_for(int dim, double cell) {
  sphc::SearchDomain d;
  d.dim = dim;
  for (int a = 0; a < 3; ++a) {
    d.lo[a] = a < dim ? 0.0 : 0.0;
    d.hi[a] = a < dim ? 10.0 : 0.0;
  }
  d.cell_size = cell;
  return d;
}

// Both lists must hold the same cells, order and cell tables.
inline void expect_same_build(const sphc::CellList& a, const sphc::CellList& b) {
  EXPECT_EQ(a.is_dense(), b.is_dense());
  EXPECT_EQ(a.num_cells(), b.num_cells());
  EXPECT_TRUE(a.cell_order() == b.cell_order()) << "cell order differs";
  EXPECT_TRUE(a.cell_start() == b.cell_start()) << "cell start table differs";
}

// The serial sort's result, checked from its definition: cell by cell, ascending index within
// a cell; start is the exclusive prefix sum of the counts.
inline void expect_sorted_by_cell(const sphc::CellList& cl) {
  const auto& order = cl.cell_order();
  const auto& start = cl.cell_start();
  ASSERT_EQ(start.size(), cl.num_cells() + 1);
  ASSERT_EQ(start.back(), order.size());
  for (std::size_t c = 0; c < cl.num_cells(); ++c) {
    ASSERT_LE(start[c], start[c + 1]);
    for (std::uint32_t k = start[c] + 1; k < start[c + 1]; ++k)
      ASSERT_LT(order[k - 1], order[k]) << "cell " << c;
  }
  std::vector<char> seen(order.size(), 0);
  for (std::uint32_t i : order) {
    ASSERT_LT(i, order.size());
    ASSERT_FALSE(seen[i]);
    seen[i] = 1;
  }
}

// As a simulation keeps its particles: a lattice block (spacing `spacing`, nx x ny points
// from the origin) in a larger domain (many empty cells: more cells than points, as the 2D
// dam break's tank), sorted in cell order by a serial build, then each point moved by up to
// `jitter` (so that chunks of the order cover narrow, slightly overlapping cell ranges).
inline Points lattice_in_cell_order(std::size_t nx, std::size_t ny, double spacing,
                                    const sphc::SearchDomain& dom, double jitter,
                                    unsigned seed) {
  Points p;
  for (std::size_t j = 0; j < ny; ++j) {
    for (std::size_t i = 0; i < nx; ++i) {
      p.x.push_back((static_cast<double>(i) + 0.5) * spacing);
      p.y.push_back((static_cast<double>(j) + 0.5) * spacing);
      p.z.push_back(0.0);
    }
  }
  sphc::CellList cl;
  cl.set_sort_chunks(1);
  cl.build(dom, p.x.data(), p.y.data(), nullptr, p.size());
  Points q;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-jitter, jitter);
  for (std::uint32_t k : cl.cell_order()) {
    q.x.push_back(p.x[k] + u(rng));
    q.y.push_back(p.y[k] + u(rng));
    q.z.push_back(0.0);
  }
  return q;
}

}  // namespace sphc_test
