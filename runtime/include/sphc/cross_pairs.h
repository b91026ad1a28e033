// sphc runtime: the pairs of two arrays once for both particles under OpenMP
// (codegen/SymmetricPairs.cpp, emitCrossPass; docs/performance-log.md, "Pairs of two arrays once
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
  // The b whose candidates lie in more than one block, for (n, n_blocks) = spanning_for.
  std::vector<std::uint32_t> spanning;
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

  // Whether the candidates of b (one of a's kept list: it has some) all lie in [begin, end).
  bool within(int b, int begin, int end) const {
    return first[b] >= static_cast<std::uint32_t>(begin) && last[b] < static_cast<std::uint32_t>(end);
  }

  // The b whose candidates lie in more than one of n_blocks blocks of n particles.
  const std::vector<std::uint32_t>& spanning_blocks(long n, long n_blocks) {
    if (spanning_for[0] == n && spanning_for[1] == n_blocks) return spanning;
    spanning.clear();
    for (std::size_t b = 0; b < first.size(); ++b)
      if (first[b] <= last[b] && block_of(first[b], n, n_blocks) != block_of(last[b], n, n_blocks))
        spanning.push_back(static_cast<std::uint32_t>(b));
    spanning_for[0] = n;
    spanning_for[1] = n_blocks;
    return spanning;
  }
};

}  // namespace sphc
