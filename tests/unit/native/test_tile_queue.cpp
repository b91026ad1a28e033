// The 8 x 8 tiles' pair queue (sphc --cluster-queue, runtime sphc/cluster_pairs.h; stop 43,
// docs/performance-log.md "The tiles' pairs compacted (stop 43)"): on random tiles, the mask
// holds exactly the pairs the rows' lanes take (the lanes' cut-off, the diagonal's l > ii, the
// real i's), the list packs them in order, the permutes give each lane its pair's values, and
// the sums come back to the right i and j: every pair's term once (integer-valued terms, so
// the sums are exact whatever their order). The helpers need AVX-512 VBMI2: this file is built
// -march=native (tests/unit/CMakeLists.txt, sphc_native_unit_tests) and skips without it.
#include "sphc/cluster_pairs.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>

#if defined(__AVX512VBMI2__)
namespace {

struct Tile {
  alignas(64) double xi[8], yi[8], zi[8], hi[8], xj[8], yj[8], zj[8], hj[8];
};

// Returns the number of failures.
int check_tile(
    const Tile& t, unsigned real_i, bool diagonal, double radius2, int& pairs) {
  int bad = 0;
  const std::uint64_t m = sphc::tile_pair_mask<3>(t.xi, t.yi, t.zi, t.hi, real_i, t.xj, t.yj, t.zj,
                                                  t.hj, diagonal, radius2);
  // the mask: the lanes' test, bit for bit
  alignas(64) double want_i[8] = {}, want_j[8] = {};
  for (int ii = 0; ii < 8; ++ii)
    for (int l = 0; l < 8; ++l) {
      const double dx = t.xi[ii] - t.xj[l], dy = t.yi[ii] - t.yj[l], dz = t.zi[ii] - t.zj[l];
      const double r2 = dx * dx + dy * dy + dz * dz;
      const double hm = t.hi[ii] > t.hj[l] ? t.hi[ii] : t.hj[l];
      const bool in = (real_i >> ii & 1u) && !(r2 >= radius2 * hm * hm) && (!diagonal || l > ii);
      bad += in != ((m >> (8 * ii + l) & 1u) != 0);
      if (in) {
        want_i[ii] += 16.0 * ii + l + 1.0;   // the i side's term of pair (ii, l)
        want_j[l] += 1000.0 * (ii + 1) + l;  // the j side's
      }
    }
  alignas(64) std::uint8_t idx[64];
  const int n = m ? sphc::tile_pair_list(m, idx) : 0;
  pairs += n;
  bad += n != __builtin_popcountll(m);
  for (int k = 1; k < n; ++k) bad += !(idx[k - 1] < idx[k]);  // in order, each once
  for (int k = 0; k < n; ++k) bad += !(m >> idx[k] & 1u);
  alignas(64) double ti[8][8] = {}, tj[8] = {};
  for (int v = 0; v < n; v += 8) {
    const int cnt = n - v < 8 ? n - v : 8;
    const sphc::TileQueueLanes at = sphc::tile_queue_lanes(idx + v);
    alignas(64) double ix[8], jx[8], ri[8], rj[8];
    sphc::tile_queue_take(ix, at.i, t.xi, static_cast<__mmask8>(real_i));
    sphc::tile_queue_take(jx, at.j, t.xj, 0xff);
    for (int k = 0; k < 8; ++k) {
      const int ii = idx[v + k] >> 3, l = idx[v + k] & 7;
      if (k < cnt) bad += ix[k] != t.xi[ii] || jx[k] != t.xj[l];
      ri[k] = k < cnt ? 16.0 * ii + l + 1.0 : 0.0;
      rj[k] = k < cnt ? 1000.0 * (ii + 1) + l : 0.0;
    }
    for (int k = 0; k < cnt;) {
      const sphc::TileQueueSegment s = sphc::tile_queue_segment(idx + v, k, cnt);
      bad += !(s.end > k && s.end <= cnt);
      sphc::tile_queue_add_i(ti[s.ii], s, ri);
      sphc::tile_queue_add_j(tj, s, rj);
      k = s.end;
    }
  }
  for (int ii = 0; ii < 8; ++ii) {
    double sum = 0.0;
    for (int k = 0; k < 8; ++k) sum += ti[ii][k];
    bad += sum != want_i[ii];
  }
  for (int l = 0; l < 8; ++l) bad += tj[l] != want_j[l];
  return bad;
}

}  // namespace
#endif

TEST(TileQueue, EveryPairOnceOnItsIAndJ) {
#if defined(__AVX512VBMI2__)
  std::mt19937 rng(43);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int bad = 0, pairs = 0, tiles = 0;
  for (int rep = 0; rep < 2000; ++rep) {
    Tile t;
    const double spread = 0.5 + 2.0 * u(rng);  // from every pair within the support to few
    for (int k = 0; k < 8; ++k) {
      t.xi[k] = spread * u(rng); t.yi[k] = spread * u(rng); t.zi[k] = spread * u(rng);
      t.hi[k] = 0.4 + 0.2 * u(rng);
      t.xj[k] = spread * u(rng); t.yj[k] = spread * u(rng); t.zj[k] = spread * u(rng);
      t.hj[k] = 0.4 + 0.2 * u(rng);
    }
    const bool diagonal = rep % 3 == 0;
    if (diagonal)
      for (int k = 0; k < 8; ++k) {
        t.xj[k] = t.xi[k]; t.yj[k] = t.yi[k]; t.zj[k] = t.zi[k]; t.hj[k] = t.hi[k];
      }
    const unsigned real_i = rep % 5 == 0 ? (1u << (1 + rep % 7)) - 1u : 0xffu;  // a padded cluster
    bad += check_tile(t, real_i, diagonal, 4.0, pairs);
    ++tiles;
  }
  EXPECT_EQ(bad, 0);
  EXPECT_GT(pairs, 8 * tiles);  // registers of 8 and partial ones both met
  EXPECT_LT(pairs, 56 * tiles);
#else
  GTEST_SKIP() << "built without AVX-512 VBMI2 (-march=native on a CPU without it)";
#endif
}
