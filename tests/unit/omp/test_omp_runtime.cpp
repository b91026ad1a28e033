// The OpenMP runtime (libsphc_runtime_omp): its parallel parts give exactly the serial
// results, on real threads. CellList::build with 1..4 threads against the serial sort
// (set_sort_chunks(1)), also in a grid with more cells than particles; ParticleArray::permute
// against a plain loop; find_non_finite (the blow-up scan) against a plain loop.
#include <gtest/gtest.h>
#include <omp.h>

#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

#include "../cell_list_checks.h"
#include "../non_finite_checks.h"
#include "sphc/nnps.h"
#include "sphc/particle_array.h"

namespace {

using sphc::CellList;

class OmpThreads : public ::testing::Test {
 protected:
  void TearDown() override { omp_set_num_threads(saved_); }
  int saved_ = omp_get_max_threads();
};

TEST_F(OmpThreads, CellListBuildEqualsSerial) {
  for (int dim : {2, 3}) {
    for (CellList::Mode mode : {CellList::Mode::Dense, CellList::Mode::Hash}) {
      const auto p = sphc_test::clustered_points(60000, dim, 5u);
      // Cells per axis: 48 in 2D, 20 in 3D (fewer cells than particles).
      const auto dom = sphc_test::domain_for(dim, dim == 2 ? 0.21 : 0.5);
      CellList serial;
      serial.set_mode(mode);
      serial.set_sort_chunks(1);
      serial.build(dom, p.x.data(), p.y.data(), p.z.data(), p.size());
      sphc_test::expect_sorted_by_cell(serial);
      for (int threads : {1, 2, 3, 4}) {
        omp_set_num_threads(threads);
        CellList par;
        par.set_mode(mode);
        par.build(dom, p.x.data(), p.y.data(), p.z.data(), p.size());
        SCOPED_TRACE(testing::Message() << "dim " << dim << ", dense " << serial.is_dense()
                                        << ", " << threads << " threads");
        sphc_test::expect_same_build(serial, par);
        EXPECT_EQ(par.last_sort_chunks(), threads);  // the parallel sort ran
      }
    }
  }
}

// More cells than particles, particles in cell order (the 2D dam break at ~100k particles:
// ~1.2 cells per particle), from 4096 particles per thread: the parallel sort runs.
TEST_F(OmpThreads, CellListBuildInCellOrderEqualsSerial) {
  const auto dom = sphc_test::domain_for(2, 0.04);  // 250 x 250 cells
  for (double jitter : {0.0, 0.02}) {
    const auto p = sphc_test::lattice_in_cell_order(180, 300, 0.015, dom, jitter, 9u);
    CellList serial;
    serial.set_sort_chunks(1);
    serial.build(dom, p.x.data(), p.y.data(), nullptr, p.size());
    ASSERT_GT(serial.num_cells(), p.size());
    for (int threads : {1, 2, 3, 4}) {
      omp_set_num_threads(threads);
      CellList par;
      for (int rep = 0; rep < 2; ++rep) {
        par.build(dom, p.x.data(), p.y.data(), nullptr, p.size());
        SCOPED_TRACE(testing::Message() << "jitter " << jitter << ", " << threads
                                        << " threads, build " << rep);
        EXPECT_EQ(par.last_sort_chunks(), threads);
        sphc_test::expect_same_build(serial, par);
      }
    }
  }
}

TEST_F(OmpThreads, PermuteEqualsSerialLoop) {
  const std::size_t n = 50000;
  sphc::ParticleArray pa;
  pa.name = "fluid";
  pa.resize(n);
  pa.add_property("x");
  pa.add_property("tau", sphc::PropType::F64, 3);
  pa.add_property("tag", sphc::PropType::I32);
  pa.add_property("gid", sphc::PropType::U32);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::size_t i = 0; i < n; ++i) {
    pa.f64(0)[i] = u(rng);
    for (int k = 0; k < 3; ++k) pa.f64(1)[3 * i + k] = u(rng);
    pa.i32(2)[i] = static_cast<std::int32_t>(i) - 7;
    pa.u32(3)[i] = static_cast<std::uint32_t>(3 * i);
  }
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::shuffle(order.begin(), order.end(), rng);
  const sphc::ParticleArray before = pa;
  omp_set_num_threads(2);
  pa.permute(order);
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_EQ(pa.f64(0)[i], before.f64(0)[order[i]]);
    for (int k = 0; k < 3; ++k) ASSERT_EQ(pa.f64(1)[3 * i + k], before.f64(1)[3 * order[i] + k]);
    ASSERT_EQ(pa.props[2].i32[i], before.props[2].i32[order[i]]);
    ASSERT_EQ(pa.props[3].u32[i], before.props[3].u32[order[i]]);
  }
  // Not permutations: a duplicate, an index out of range.
  std::vector<std::uint32_t> dup = order;
  dup[n / 2] = dup[n / 3];
  EXPECT_THROW(pa.permute(dup), std::invalid_argument);
  std::vector<std::uint32_t> out = order;
  out[n - 1] = static_cast<std::uint32_t>(n);
  EXPECT_THROW(pa.permute(out), std::invalid_argument);
  EXPECT_TRUE(sphc::is_permutation_of(order, n));
  EXPECT_FALSE(sphc::is_permutation_of(dup, n));
}

TEST_F(OmpThreads, FindNonFiniteEqualsSerialLoop) {
  for (int threads : {1, 2, 3}) {
    omp_set_num_threads(threads);
    for (std::size_t n : {5, 20000}) {  // 20000 x 14 values: the parallel scan
      SCOPED_TRACE(testing::Message() << threads << " threads, " << n << " particles");
      sphc_test::check_find_non_finite(n, 2, 6);  // fewer cases than the serial test
    }
  }
}

}  // namespace
