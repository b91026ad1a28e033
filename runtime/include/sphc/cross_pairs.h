// sphc runtime: the pairs of two arrays once for both particles under OpenMP
// (codegen/SymmetricPairs.cpp, emitCrossPass; docs/performance.md, "Pairs of two arrays once
// under OpenMP").
//
// The pass takes the particles a of array A in contiguous blocks, one per thread, and for each
// a the particles b of its kept list of B (increasing index): a's sums, then b's. b must
// receive its contributions in increasing a, as when it gathers over its own list. Where all
// of b's candidates in A lie in one block, that block's thread gives them in that order at
// its turns; the other b (candidates in two or more blocks) are left out of the blocked pass
// and gather afterwards over their candidates in increasing a. Both need the kept lists of
// A <- B read from B's side: CrossSources, built from them at every rebuild.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "sphc/verlet.h"

namespace sphc {

// The block (of n_blocks contiguous blocks [n t / n_blocks, n (t + 1) / n_blocks)) holding
// particle i of n.
inline int block_of(long i, long n, long n_blocks) {
  return static_cast<int>(((i + 1) * n_blocks - 1) / n);
}

struct CrossSources {
  // The candidates of b: a = dests[starts[b] .. starts[b + 1]), in increasing a.
  std::vector<std::uint32_t> starts, dests;
  // Per b its first and last candidate (first > last where it has none).
  std::vector<std::uint32_t> first, last;
  // The b whose candidates lie in more than one block, for (n, n_blocks) = spanning_for;
  // per b the block holding all its candidates, -1 where they span blocks or it has none.
  std::vector<std::uint32_t> spanning;
  std::vector<int> owner;
  long spanning_for[2] = {-1, -1};

  // Emptied at every build of the lists (by whichever loop builds them), built again by the
  // pass that reads it.
  void clear() { starts.clear(); }
  bool empty() const { return starts.empty(); }

  // From the kept lists of A <- B (lists[a], increasing b), with nb particles in B.
  void build(const std::vector<std::vector<std::uint32_t>>& lists, std::size_t nb) {
    starts.assign(nb + 1, 0);
    for (const auto& l : lists)
      for (std::uint32_t b : l) ++starts[b + 1];
    for (std::size_t b = 0; b < nb; ++b) starts[b + 1] += starts[b];
    dests.resize(starts[nb]);
    std::vector<std::uint32_t> fill(starts.begin(), starts.end() - 1);
    for (std::size_t a = 0; a < lists.size(); ++a)  // a ascending: each b's list in increasing a
      for (std::uint32_t b : lists[a]) dests[fill[b]++] = static_cast<std::uint32_t>(a);
    first.assign(nb, 1);
    last.assign(nb, 0);
    for (std::size_t b = 0; b < nb; ++b)
      if (starts[b] != starts[b + 1]) {
        first[b] = dests[starts[b]];
        last[b] = dests[starts[b + 1] - 1];
      }
    spanning_for[0] = spanning_for[1] = -1;
  }

  // The same from the contiguous kept lists (sphc/verlet.h KeptLists), in `threads` blocks
  // of A's particles, in parallel under OpenMP (from 16,384 candidates): each block counts
  // its candidates per b, and fills them from where the blocks before it end, so each b's
  // list is in increasing a whatever the blocks: the arrays are those of the build above.
  void build(const KeptLists& lists, std::size_t nb, int threads = 1) {
    const long na = static_cast<long>(lists.size());
    const long nt = lists.total() > 16384 && threads > 1 ? threads : 1;
    const std::size_t* at = lists.starts().data();
    const std::uint32_t* idx = lists.index().data();
    counts_.assign(static_cast<std::size_t>(nt) * nb, 0);  // per block, per b
    std::uint32_t* const cnt = counts_.data();
#pragma omp parallel for schedule(static) if (nt > 1)
    for (long t = 0; t < nt; ++t) {
      std::uint32_t* c = cnt + t * nb;
      for (std::size_t k = at[na * t / nt]; k < at[na * (t + 1) / nt]; ++k) ++c[idx[k]];
    }
    starts.assign(nb + 1, 0);
    first.assign(nb, 1);
    last.assign(nb, 0);
    const long nbl = static_cast<long>(nb);
#pragma omp parallel for schedule(static) if (nt > 1 && nbl > 16384)
    for (long b = 0; b < nbl; ++b) {  // the counts, then where each block's b start within b
      std::uint32_t sum = 0;
      for (long t = 0; t < nt; ++t) {
        const std::uint32_t c = cnt[t * nb + b];
        cnt[t * nb + b] = sum;
        sum += c;
      }
      starts[b + 1] = sum;
    }
    for (std::size_t b = 0; b < nb; ++b) starts[b + 1] += starts[b];
    dests.resize(starts[nb]);
    std::uint32_t* const out = dests.data();
    const std::uint32_t* const st = starts.data();
#pragma omp parallel for schedule(static) if (nt > 1)
    for (long t = 0; t < nt; ++t) {
      std::uint32_t* fill = cnt + t * nb;
      for (long a = na * t / nt; a < na * (t + 1) / nt; ++a)  // a ascending in the block
        for (std::size_t k = at[a]; k < at[a + 1]; ++k) {
          const std::uint32_t b = idx[k];
          out[st[b] + fill[b]++] = static_cast<std::uint32_t>(a);
        }
    }
#pragma omp parallel for schedule(static) if (nt > 1 && nbl > 16384)
    for (long b = 0; b < nbl; ++b)
      if (st[b] != st[b + 1]) {
        first[b] = out[st[b]];
        last[b] = out[st[b + 1] - 1];
      }
    spanning_for[0] = spanning_for[1] = -1;
  }

  // Whether the candidates of b (one of a's kept list: it has some) all lie in [begin, end).
  bool within(int b, int begin, int end) const {
    return first[b] >= static_cast<std::uint32_t>(begin) && last[b] < static_cast<std::uint32_t>(end);
  }

  // The b whose candidates lie in more than one of n_blocks blocks of n particles (and
  // `owner`, for the same blocks: a test of one integer per pair in the blocked pass).
  const std::vector<std::uint32_t>& spanning_blocks(long n, long n_blocks) {
    if (spanning_for[0] == n && spanning_for[1] == n_blocks) return spanning;
    spanning.clear();
    owner.assign(first.size(), -1);
    for (std::size_t b = 0; b < first.size(); ++b) {
      if (first[b] > last[b]) continue;  // no candidates
      const int bf = block_of(first[b], n, n_blocks);
      if (bf != block_of(last[b], n, n_blocks))
        spanning.push_back(static_cast<std::uint32_t>(b));
      else
        owner[b] = bf;
    }
    spanning_for[0] = n;
    spanning_for[1] = n_blocks;
    return spanning;
  }
  // Per b the block holding all its candidates (-1: spanning or none), for n_blocks blocks.
  const std::vector<int>& owner_blocks(long n, long n_blocks) {
    spanning_blocks(n, n_blocks);
    return owner;
  }

 private:
  std::vector<std::uint32_t> counts_;  // scratch of the build from KeptLists
};

}  // namespace sphc
