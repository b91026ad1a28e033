// The parallel counting sort of CellList::build (per-chunk histograms, offsets, scatter) run
// chunk after chunk in the serial runtime: for any number of chunks the result must be the
// serial sort's (omp/test_omp_runtime.cpp runs the same checks on real threads). Also: a
// build from float coordinates equals a build from the same values as doubles.
#include <gtest/gtest.h>

#include <vector>

#include "cell_list_checks.h"
#include "sphc/nnps.h"

namespace {

using sphc::CellList;

struct Case {
  int dim;
  CellList::Mode mode;
  std::size_t n;
};

class ChunkedSort : public ::testing::TestWithParam<Case> {};

TEST_P(ChunkedSort, EqualsSerialSort) {
  const Case c = GetParam();
  const auto p = sphc_test::clustered_points(c.n, c.dim, 17u + static_cast<unsigned>(c.dim));
  const auto dom = sphc_test::domain_for(c.dim, 0.37);
  CellList serial;
  serial.set_mode(c.mode);
  serial.set_sort_chunks(1);
  serial.build(dom, p.x.data(), p.y.data(), p.z.data(), p.size());
  sphc_test::expect_sorted_by_cell(serial);
  for (int chunks : {2, 3, 7, 64}) {
    CellList par;
    par.set_mode(c.mode);
    par.set_sort_chunks(chunks);
    // Twice: the second build reuses the buffers of the first.
    for (int rep = 0; rep < 2; ++rep) {
      par.build(dom, p.x.data(), p.y.data(), p.z.data(), p.size());
      SCOPED_TRACE(testing::Message() << chunks << " chunks, build " << rep);
      sphc_test::expect_same_build(serial, par);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, ChunkedSort,
    ::testing::Values(Case{1, CellList::Mode::Dense, 5000}, Case{2, CellList::Mode::Dense, 20000},
                      Case{3, CellList::Mode::Dense, 20000}, Case{2, CellList::Mode::Hash, 20000},
                      Case{3, CellList::Mode::Hash, 3000}, Case{2, CellList::Mode::Dense, 5},
                      Case{2, CellList::Mode::Dense, 0}));

// Points kept in cell order in a grid with more cells than points (the 2D dam break's case):
// each chunk's particles occupy a narrow window of cells, most cells are empty.
TEST(ChunkedSortInCellOrder, EqualsSerialSort) {
  const auto dom = sphc_test::domain_for(2, 0.13);  // 77 x 77 cells
  for (double jitter : {0.0, 0.05, 0.4}) {
    const auto p = sphc_test::lattice_in_cell_order(60, 80, 0.05, dom, jitter, 3u);
    CellList serial;
    serial.set_sort_chunks(1);
    serial.build(dom, p.x.data(), p.y.data(), nullptr, p.size());
    sphc_test::expect_sorted_by_cell(serial);
    ASSERT_GT(serial.num_cells(), p.size());
    for (int chunks : {2, 3, 7, 64}) {
      CellList par;
      par.set_sort_chunks(chunks);
      for (int rep = 0; rep < 2; ++rep) {
        par.build(dom, p.x.data(), p.y.data(), nullptr, p.size());
        SCOPED_TRACE(testing::Message() << "jitter " << jitter << ", " << chunks
                                        << " chunks, build " << rep);
        EXPECT_EQ(par.last_sort_chunks(), chunks);
        sphc_test::expect_same_build(serial, par);
      }
    }
  }
}

TEST(CellListFloat, SameAsDoubleOfTheSameValues) {
  for (int dim : {1, 2, 3}) {
    auto p = sphc_test::clustered_points(4000, dim, 3u);
    std::vector<float> xf(p.size()), yf(p.size()), zf(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
      xf[i] = static_cast<float>(p.x[i]);
      yf[i] = static_cast<float>(p.y[i]);
      zf[i] = static_cast<float>(p.z[i]);
      p.x[i] = xf[i];
      p.y[i] = yf[i];
      p.z[i] = zf[i];
    }
    const auto dom = sphc_test::domain_for(dim, 0.5);
    CellList a, b;
    a.build(dom, p.x.data(), p.y.data(), p.z.data(), p.size());
    b.build(dom, xf.data(), dim > 1 ? yf.data() : nullptr, dim > 2 ? zf.data() : nullptr,
            p.size());
    sphc_test::expect_same_build(a, b);
  }
}

}  // namespace
