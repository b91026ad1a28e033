// sphc::CrossSources and sphc::block_of (sphc/cross_pairs.h): the kept lists of A <- B read
// from B's side, for the OpenMP pass over pairs of two arrays once (codegen/SymmetricPairs.cpp).
#include "sphc/cross_pairs.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "kept_lists_checks.h"

namespace {

// block_of against the blocks the generated loop makes: [n t / nb, n (t + 1) / nb).
TEST(CrossPairs, BlockOfMatchesTheLoopsBlocks) {
  for (long n : {1L, 2L, 7L, 10L, 50L, 101L, 400L, 98415L})
    for (long nb = 1; nb <= 9 && nb <= n; ++nb)
      for (long t = 0; t < nb; ++t) {
        const long begin = n * t / nb, end = n * (t + 1) / nb;
        for (long i = begin; i < end; ++i) ASSERT_EQ(sphc::block_of(i, n, nb), t) << n << " " << nb << " " << i;
      }
}

// Every b's candidates, in increasing a, exactly the a whose list holds b; first and last;
// the spanning b those with candidates in two blocks, recomputed for another block count.
TEST(CrossPairs, ListsFromTheSourcesSide) {
  std::mt19937 rng(7);
  const std::size_t na = 300, nb = 40;
  std::vector<std::vector<std::uint32_t>> lists(na);
  for (std::size_t a = 0; a < na; ++a)
    for (std::uint32_t b = 0; b < nb; ++b)
      // b near a / 10 (a wall next to a fluid sorted along it); b = 39 none.
      if (b != 39 && std::abs(static_cast<long>(b) - static_cast<long>(a / 10)) <= 2 && rng() % 3)
        lists[a].push_back(b);
  sphc::CrossSources cs;
  cs.build(lists, nb);
  ASSERT_EQ(cs.starts.size(), nb + 1);
  for (std::uint32_t b = 0; b < nb; ++b) {
    std::vector<std::uint32_t> want;
    for (std::size_t a = 0; a < na; ++a)
      for (std::uint32_t x : lists[a])
        if (x == b) want.push_back(static_cast<std::uint32_t>(a));
    const std::vector<std::uint32_t> got(cs.dests.begin() + cs.starts[b], cs.dests.begin() + cs.starts[b + 1]);
    EXPECT_EQ(got, want) << b;
    if (want.empty()) {
      EXPECT_GT(cs.first[b], cs.last[b]);
    } else {
      EXPECT_EQ(cs.first[b], want.front());
      EXPECT_EQ(cs.last[b], want.back());
    }
  }
  for (long blocks : {1L, 2L, 3L, 8L, 2L}) {
    std::vector<std::uint32_t> want;
    for (std::uint32_t b = 0; b < nb; ++b)
      if (cs.first[b] <= cs.last[b] &&
          sphc::block_of(cs.first[b], na, blocks) != sphc::block_of(cs.last[b], na, blocks))
        want.push_back(b);
    EXPECT_EQ(cs.spanning_blocks(na, blocks), want) << blocks;
    if (blocks == 1) EXPECT_TRUE(want.empty());
    if (blocks == 8) EXPECT_FALSE(want.empty());
  }
  // A rebuild forgets the spanning list of the old lists.
  lists.assign(na, {});
  lists[0] = {5};
  lists[299] = {5};
  cs.build(lists, nb);
  EXPECT_EQ(cs.spanning_blocks(na, 2), std::vector<std::uint32_t>{5});
}

// The same arrays from the contiguous kept lists (KeptLists) as from a list per particle, in
// one block and in 2, 3 and 7 blocks of A (the counts and fills per block; above 16,384
// candidates, where the build goes in blocks); owner_blocks: per b the block holding all its
// candidates, -1 where they span blocks or there are none.
TEST(CrossPairs, FromContiguousListsAsFromAListPerParticle) {
  for (std::size_t na : {300u, 3000u}) {
    const std::uint32_t nb = 400;
    std::mt19937 rng(11);
    std::vector<std::vector<std::uint32_t>> lists(na);
    for (std::size_t a = 0; a < na; ++a)
      for (std::uint32_t b = 0; b < nb; ++b)  // b near a's position along the wall; 399 none
        if (b != 399 && std::abs(static_cast<long>(b) - static_cast<long>(a * nb / na)) <= 6 && rng() % 4)
          lists[a].push_back(b);
    sphc::KeptLists kl;
    kl.start_build(na, 1);
    for (std::size_t a = 0; a < na; ++a)
      kl.keep(0, static_cast<std::uint32_t>(a), lists[a].data(), lists[a].size());
    kl.finish_build();
    sphc_test::expect_same_lists(kl, lists);
    if (na == 3000u) ASSERT_GT(kl.total(), 16384u);  // built in blocks
    sphc::CrossSources want;
    want.build(lists, nb);
    for (int threads : {1, 2, 3, 7}) {
      sphc::CrossSources got;
      got.build(kl, nb, threads);
      EXPECT_EQ(got.starts, want.starts) << threads;
      EXPECT_EQ(got.dests, want.dests) << threads;
      EXPECT_EQ(got.first, want.first) << threads;
      EXPECT_EQ(got.last, want.last) << threads;
      for (long blocks : {1L, 2L, 5L}) {
        const std::vector<int> owner = got.owner_blocks(static_cast<long>(na), blocks);
        EXPECT_EQ(got.spanning, want.spanning_blocks(static_cast<long>(na), blocks));
        for (std::uint32_t b = 0; b < nb; ++b) {
          const long s = want.starts[b], e = want.starts[b + 1];
          int blk = s == e ? -1 : sphc::block_of(want.dests[s], static_cast<long>(na), blocks);
          for (long k = s; k < e; ++k)
            if (sphc::block_of(want.dests[k], static_cast<long>(na), blocks) != blk) blk = -1;
          ASSERT_EQ(owner[b], blk) << "b " << b << " blocks " << blocks;
        }
      }
    }
  }
}

}  // namespace
