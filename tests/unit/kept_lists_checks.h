// Shared by test_verlet.cpp and omp/test_verlet_omp.cpp: candidates per particle, the kept
// lists of the old builder (a std::vector per particle, keep_in_index_order) and a check
// that sphc::KeptLists (one contiguous array) holds the same lists element for element.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "sphc/verlet.h"

namespace sphc_test {

// Per particle distinct candidate indices below `range`, in a shuffled order, of lengths 0
// to ~2 kInsertionSortMax (both sorts of keep_in_index_order); some particles have none.
inline std::vector<std::vector<std::uint32_t>> random_candidates(std::size_t n, std::uint32_t range,
                                                                 unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<std::vector<std::uint32_t>> cand(n);
  std::vector<std::uint32_t> pool(range);
  for (std::uint32_t k = 0; k < range; ++k) pool[k] = k;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t len = rng() % 7 == 0 ? 0 : rng() % (2 * sphc::kInsertionSortMax + 8);
    std::shuffle(pool.begin(), pool.end(), rng);
    cand[i].assign(pool.begin(), pool.begin() + std::min<std::size_t>(len, range));
    if (rng() % 3 == 0) std::sort(cand[i].begin(), cand[i].end());  // as the cells often give
  }
  return cand;
}

// The lists of the builder before KeptLists: per particle keep_in_index_order; a particle
// outside [begin, end) has none.
inline std::vector<std::vector<std::uint32_t>> old_lists(
    const std::vector<std::vector<std::uint32_t>>& cand, std::size_t begin, std::size_t end) {
  std::vector<std::vector<std::uint32_t>> lists(cand.size());
  for (std::size_t i = begin; i < end; ++i)
    sphc::keep_in_index_order(lists[i], cand[i].data(), cand[i].size());
  return lists;
}

// The CSR holds exactly `want`: per particle the same indices, in one array, in particle order.
inline void expect_same_lists(const sphc::KeptLists& kl,
                              const std::vector<std::vector<std::uint32_t>>& want) {
  ASSERT_EQ(kl.size(), want.size());
  std::size_t total = 0;
  for (std::size_t i = 0; i < want.size(); ++i) {
    const sphc::KeptList l = kl[i];
    ASSERT_EQ(std::vector<std::uint32_t>(l.begin(), l.end()), want[i]) << "particle " << i;
    ASSERT_EQ(kl.starts()[i], total);
    total += want[i].size();
  }
  EXPECT_EQ(kl.total(), total);
  EXPECT_EQ(kl.index().size(), total);
}

}  // namespace sphc_test
