// sphc runtime: cluster-pair lists for SIMD tile loops (GROMACS' nbnxm scheme, Pall & Hess
// 2013; docs/performance-log.md, "A cluster-pair SIMD tile kernel, measured by hand (stop 36)" and
// "Cluster-pair lists in the runtime (stop 37)"). Plain data and free functions.
//
// A pair loop in tiles sees one particle array in *cluster order*: the particles sorted into
// columns (3D: squares of side `column_side` in the x-y plane, each column sorted by z; 2D:
// strips of width `column_side` in x, each sorted by y), each column cut into clusters of
// `width` consecutive particles (kClusterSize = 8 by default; 1..8, e.g. 4 for 2D tiles:
// docs/performance-log.md, "SIMD tiles in 2D, measured by hand (stop 38)"), the last cluster of a
// column padded. Slot s = width c + k is lane k of cluster c (ClusterLayout). (Since stop 40 the
// generated code keeps the particles themselves in a slot order where it can: see "Particles
// kept in the tiles' slot order" below; the copies remain with sphc --no-slot-order.)
// Per evaluation the loop copies the properties it reads
// into slot order (gather_slots, gather_positions: contiguous vector loads of a cluster), runs
// its tiles (one i of an i-cluster broadcast x the lanes of a j-cluster, the cut-off a mask)
// over a ClusterPairList, and adds its sums, accumulated in slot order, back (add_slots).
//
// Lists. The *outer* list (build_cluster_pairs) holds, per i-cluster, the j-clusters whose
// bounding boxes lie within the list radius; the *pruned* list (prune_cluster_pairs) those of
// the outer list whose boxes, recomputed from the positions now (update_boxes), lie within the
// support radius. A box holds its cluster's real particles, so two particles at distance r
// have boxes at distance <= r, and
//
//   THE RULE THAT KEEPS THE LISTS COMPLETE (the kept lists' rule, sphc/verlet.h, VerletSkin):
//   build the layout and the outer list when VerletSkin::must_rebuild says yes (and mark),
//   with the list radius  (1 + skin) * radius_scale * h_max,  h_max the largest h of the two
//   arrays (destination and source) at the build. Until must_rebuild next says yes, any pair
//   within its support now (radius_scale * max(h_i, h_j)) was within that radius at the
//   build (its distance shrank by at most 2 d, its radius grew by at most radius_scale g, and
//   2 d + radius_scale g <= skin * radius_scale * h_min), so its clusters' boxes at the build
//   were within it: the pair's cluster pair is in the outer list. Per evaluation prune with
//   the support radius radius_scale * h_max, h_max the largest h of the two arrays NOW: the
//   boxes now hold the positions now, so every pair within its support now is in a cluster
//   pair of the pruned list. A tile still tests each lane's pair with the loop's own cut-off
//   (the lists hold more pairs than the support, never fewer). The box tests keep a pair of
//   boxes at squared distance <= radius^2 (1 + 1e-12) (a margin over the rounding of the
//   squared distances, computed from the same doubles), so they never drop a pair that the
//   tile's test, computed in another order or with fma, would find inside.
//
// Each pair once (`once`, destination = source): a list holds only j-clusters j >= i, the
// diagonal tile (j == i) included; a tile on it takes the lanes with slot j > slot i only (or
// j >= i where the loop keeps the self pair). Two arrays (cross): i-clusters of the
// destination's layout, j-clusters of the source's; every cluster pair within the radius.
//
// Padding: the last cluster of a column holds 1..8 real particles, real slots first
// (real_mask). Padding slots take a real particle's values (gather_slots; so every lane's
// arithmetic stays finite: masked lanes are still computed) and positions at least
// `pad_offset` from every real particle and every other padding slot of the layout
// (gather_positions): with pad_offset beyond the support radius (plus, for a cross loop, how
// far the other array reaches beyond this one in x) no padding lane is within the cut-off of
// another lane; add_slots never reads a padding slot.
//
// Orders: the slot order depends only on the positions at the build (ties in the sort key
// by particle index); the j-clusters of a list are in increasing index per i-cluster. The
// OpenMP runtime (libsphc_runtime_omp) builds and prunes in blocks of i-clusters with the
// same result as the serial one.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#if defined(__AVX512F__)
#include <immintrin.h>  // tile_row_any, the pair queue
#endif

namespace sphc {

// The default width of a cluster: one AVX-512 register of doubles (the j-cluster of a tile).
// A layout may have another width (ClusterLayout::width, 1..kMaxClusterSize).
constexpr int kClusterSize = 8;
constexpr int kMaxClusterSize = 8;  // real_mask holds a cluster's slots in 8 bits
// ClusterLayout::slot of a padding slot.
constexpr std::uint32_t kPadSlot = 0xffffffffu;

// One particle array in cluster order (the slot order of a pair loop's copies).
struct ClusterLayout {
  int dim = 3;                         // 2 or 3
  std::size_t n = 0;                   // real particles
  int width = kClusterSize;            // slots per cluster (1..kMaxClusterSize)
  std::size_t n_clusters = 0;          // slots = n_clusters * width
  std::vector<std::uint32_t> slot;     // slot -> particle index, kPadSlot for padding
  std::vector<std::uint32_t> slot_of;  // particle -> its slot
  // Per cluster: bit k set where slot width c + k holds a real particle (its real slots come
  // first: full_mask() (0xff for width 8), or 2^m - 1 for the last cluster of a column with m
  // real particles).
  std::vector<std::uint8_t> real_mask;
  // Per cluster: lo x, lo y, lo z, hi x, hi y, hi z of its real particles (2D: z 0, 0), from
  // the positions given to build_cluster_layout or, since, to update_boxes.
  std::vector<double> box;
  // The grid of columns (build_cluster_pairs searches it): column (cx, cy) covers
  // [origin[0] + cx side, + side) x [origin[1] + cy side, + side) (2D: cy = 0, x only) at
  // the build; column index cy * columns[0] + cx; its clusters are
  // [column_begin[col], column_begin[col + 1]) (an empty column has none).
  double column_side = 0;
  double origin[2] = {0, 0};
  std::size_t columns[2] = {0, 0};
  std::vector<std::uint32_t> column_begin;  // columns[0] * columns[1] + 1
  // In order (build_cluster_layout_in_order, stop 40): slot s IS particle s (the last
  // cluster padded), a cluster in the column of its box's centre; column_cluster[k] for k in
  // [column_begin[col], column_begin[col + 1]) the clusters of column col by the low sort
  // coordinate of their boxes (ties by index). Empty otherwise (the column's clusters are
  // the indices themselves).
  bool in_order = false;
  std::vector<std::uint32_t> column_cluster;

  std::size_t slots() const { return n_clusters * static_cast<std::size_t>(width); }
  // real_mask of a cluster without padding.
  std::uint8_t full_mask() const { return static_cast<std::uint8_t>((1u << width) - 1u); }
};

// A column side giving clusters about as wide as tall: spacing * width^(1/dim) (width 8: 2
// spacings in 3D, 2.83 in 2D; width 4 in 2D: 2), spacing the particles' typical distance (dx).
double cluster_column_side(double spacing, int dim, int width = kClusterSize);

// At a list rebuild: the layout of n particles at (x, y, z) (z unused, may be null, in 2D).
// column_side <= 0: (width * V / n)^(1/k), V the volume (2D: area) of the particles'
// bounding box over the k axes along which they extend (2 dx for a filled box on a lattice of
// spacing dx; a flat wall of a 3D scene: its area, 2.83 dx). Where the bounding box
// would need more than 4 n + 16 columns (a stray particle), the columns are made wider.
// Boxes from these positions. width: the slots per cluster (1..kMaxClusterSize).
void build_cluster_layout(ClusterLayout& layout, const double* x, const double* y,
                          const double* z, std::size_t n, int dim, double column_side,
                          int width = kClusterSize);

// Particles kept in the tiles' slot order (stop 40; docs/performance-log.md "Particles in the
// tiles' slot order (stop 40)"). The generated code permutes an array whose tiles' lists are
// due into `cluster_order`'s order (ParticleArray::permute) and builds its layout in that
// order (build_cluster_layout_in_order): slot s is particle s, the tiles read and write the
// particles' arrays themselves; only the last cluster (n % width real particles, if any) is
// padded, its slots copied per evaluation into `width`-value tails (gather_tail,
// tail_positions).
//
// The order: build_cluster_layout's full clusters as they are (a column's clusters aligned
// from its bottom, as in the sorted layout), the columns in boustrophedon order (3D: the rows
// of columns along x alternately forwards and backwards), then the particles of the columns'
// last clusters that are not full, in the same column order (the tops of neighbouring
// columns, cut into clusters of their own).
void cluster_order(std::vector<std::uint32_t>& order, const double* x, const double* y,
                   const double* z, std::size_t n, int dim, double column_side,
                   int width = kClusterSize);
// The layout of the particles as they are: slot s = particle s, cluster c the particles
// [width c, width c + width), the last padded (real slots first); boxes from x, y, z; the
// grid of columns as build_cluster_layout's (column_side <= 0: the same rule).
void build_cluster_layout_in_order(ClusterLayout& layout, const double* x, const double* y,
                                   const double* z, std::size_t n, int dim, double column_side,
                                   int width = kClusterSize);
// The padded cluster of an in-order layout: its index, n_clusters if every cluster is full.
inline std::size_t tail_cluster(const ClusterLayout& L) {
  return L.n_clusters > 0 && L.slots() != L.n ? L.n_clusters - 1 : L.n_clusters;
}
// The 2xMM tiles in order (stop 41; docs/performance-log.md "The 2D tiles' j side from the
// particles' arrays; 2D tiles by default? (stop 41)"): a 4-cluster's values p[0..3] twice into a tile-local
// register, t[k] = t[4 + k] = p[k] (t: 8 doubles, 64-byte aligned), the j side of a register
// of 2 i's x 4 j's read from the particles' own arrays instead of copies doubled per
// evaluation. GCC 12 and clang: one 256-bit load and a lane shuffle (vshuff64x2), the result
// kept in a register where the tile allows; an 8-lane loop over p[l % 4] is stored as two
// 256-bit halves and reloaded as one 512-bit vector (a store-forwarding stall).
inline void load_doubled4(double* t, const double* p) {
#if defined(__clang__) || (defined(__GNUC__) && __GNUC__ >= 12)
  typedef double sphc_v4d __attribute__((vector_size(32)));
  typedef double sphc_v8d __attribute__((vector_size(64)));
  sphc_v4d x;
  std::memcpy(&x, p, sizeof x);
  const sphc_v8d y = __builtin_shufflevector(x, x, 0, 1, 2, 3, 0, 1, 2, 3);
  std::memcpy(t, &y, sizeof y);
#else
  for (int k = 0; k < 4; ++k) t[k] = t[4 + k] = p[k];
#endif
}
#if defined(__AVX512F__)
// The 8 x 8 tiles' row test under AVX-512 (codegen/ClusterPairs.cpp; stop 42, docs/performance-log.md
// "The 3D tiles' rows (stop 42)"): whether any lane l of a tile row, particle i (xi, yi, zi, hi)
// against the j-cluster's 8 slots (xj[l], yj[l], zj[l] (Dim 3), hj[l]), is within the cut-off,
// !(r2 >= radius2 hmax^2) (r2 = dx dx + dy dy (+ dz dz), hmax = hi > hj ? hi : hj, the lanes'
// operations), among the lanes the tile takes, lane[l] > lane_d (lane_d < 0: all of them): one
// compare mask tested at once (kortest), where the lanes' own test reduced a double per lane to a
// branch (a longer chain before it resolves: the branch is data-dependent, ~1.7 of a tile's 8
// rows have no pair). The row is skipped only where this says no; the lanes keep their own cut-off
// (in_cut): the test is theirs, the same operations in the same order (sphc compiles with
// -ffp-contract=off: no fma on either side), so the same rows are skipped and the sums are the
// same bit for bit. (No margin on radius2: in a lattice such as the cube's many pairs lie at the
// support's edge to the last bit, and 1 + 1e-12 let ~10% more rows through to lanes all masked.)
// The r2 of 8 lanes from their i's coordinates (xi, yi, zi: broadcast or per lane) and the
// j's at xj, yj, zj, as the lanes compute R2IJ (zi and zj read only in 3D).
template <int Dim>
inline __attribute__((always_inline)) __m512d tile_r2(__m512d xi, __m512d yi, __m512d zi,
                                                      const double* xj, const double* yj,
                                                      const double* zj) {
  const __m512d dx = _mm512_sub_pd(xi, _mm512_loadu_pd(xj));
  const __m512d dy = _mm512_sub_pd(yi, _mm512_loadu_pd(yj));
  __m512d r2 = _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy));
  if constexpr (Dim == 3) {
    const __m512d dz = _mm512_sub_pd(zi, _mm512_loadu_pd(zj));
    r2 = _mm512_add_pd(r2, _mm512_mul_pd(dz, dz));
  } else {
    (void)zi;
    (void)zj;
  }
  return r2;
}
// The row's r2 in the 8 lanes: one i against 8 j's.
template <int Dim>
inline __attribute__((always_inline)) __m512d tile_row_r2(double xi, double yi, double zi,
                                                          const double* xj, const double* yj,
                                                          const double* zj) {
  return tile_r2<Dim>(_mm512_set1_pd(xi), _mm512_set1_pd(yi),
                      Dim == 3 ? _mm512_set1_pd(zi) : _mm512_setzero_pd(), xj, yj, zj);
}
// The lanes within the cut-off lim (!(r2 >= lim), the lanes' form) and past lane_d.
inline __attribute__((always_inline)) __mmask8 tile_row_in(__m512d r2, __m512d lim,
                                                           const double* lane, double lane_d) {
  return _mm512_cmp_pd_mask(r2, lim, _CMP_NGE_UQ) &
         _mm512_cmp_pd_mask(_mm512_loadu_pd(lane), _mm512_set1_pd(lane_d), _CMP_GT_OQ);
}
template <int Dim>
inline __attribute__((always_inline)) __mmask8 tile_row_mask(double xi, double yi, double zi, double hi,
                                                             const double* xj, const double* yj,
                                                             const double* zj, const double* hj,
                                                             const double* lane, double lane_d,
                                                             double radius2) {
  const __m512d r2 = tile_row_r2<Dim>(xi, yi, zi, xj, yj, zj);
  const __m512d hm = _mm512_max_pd(_mm512_set1_pd(hi), _mm512_loadu_pd(hj));  // hi > hj ? hi : hj
  const __m512d lim = _mm512_mul_pd(_mm512_mul_pd(_mm512_set1_pd(radius2), hm), hm);
  return tile_row_in(r2, lim, lane, lane_d);
}
template <int Dim>
inline __attribute__((always_inline)) bool tile_row_any(double xi, double yi, double zi, double hi,
                                                        const double* xj, const double* yj,
                                                        const double* zj, const double* hj,
                                                        const double* lane, double lane_d,
                                                        double radius2) {
  return tile_row_mask<Dim>(xi, yi, zi, hi, xj, yj, zj, hj, lane, lane_d, radius2) != 0;
}
// tile_row_any where every particle of both clusters has the same h (stop 45; sphc's
// analysis/UniformH.cpp): the cut-off `cut2` = radius2 hmax hmax computed once per pass by the
// caller (the same operations in the same order as tile_row_mask's lim, so the same bits), no
// h loaded.
template <int Dim>
inline __attribute__((always_inline)) bool tile_row_any_cut(double xi, double yi, double zi,
                                                            const double* xj, const double* yj,
                                                            const double* zj, const double* lane,
                                                            double lane_d, double cut2) {
  const __m512d r2 = tile_row_r2<Dim>(xi, yi, zi, xj, yj, zj);
  return tile_row_in(r2, _mm512_set1_pd(cut2), lane, lane_d) != 0;
}
// The 2xMM tiles' register test under AVX-512 (stop 46; codegen/ClusterPairs.cpp): a register
// of 2 i's x 4 j's, lane l's i at xi[l], yi[l], zi[l] (the i-cluster's register ri_NAME[r]) and
// its j at xj[l], ... (the doubled j-cluster): whether any lane is within the cut-off and a pair
// the register takes (jlane[l] > ilane[l] + lane_d), as the lanes' own test computes it (the
// same operations in the same order: the same registers skipped), one compare mask tested at
// once where the lanes' test was reduced by max to a double (a chain of ~8 dependent
// instructions before the branch). hi, hj: every lane's h (hmax = hi > hj ? hi : hj, the cut-off
// radius2 hmax hmax), or cut2 where h is uniform (tile_row_any2_cut).
template <int Dim>
inline __attribute__((always_inline)) __m512d tile_row_r2_lanes(const double* xi, const double* yi,
                                                                const double* zi, const double* xj,
                                                                const double* yj, const double* zj) {
  return tile_r2<Dim>(_mm512_loadu_pd(xi), _mm512_loadu_pd(yi),
                      Dim == 3 ? _mm512_loadu_pd(zi) : _mm512_setzero_pd(), xj, yj, zj);
}
inline __attribute__((always_inline)) bool tile_row_in2(__m512d r2, __m512d lim, const double* jlane,
                                                        const double* ilane, double lane_d) {
  const __m512d il = _mm512_add_pd(_mm512_loadu_pd(ilane), _mm512_set1_pd(lane_d));
  return (_mm512_cmp_pd_mask(r2, lim, _CMP_NGE_UQ) &
          _mm512_cmp_pd_mask(_mm512_loadu_pd(jlane), il, _CMP_GT_OQ)) != 0;
}
template <int Dim>
inline __attribute__((always_inline)) bool tile_row_any2(const double* xi, const double* yi,
                                                         const double* zi, const double* hi,
                                                         const double* xj, const double* yj,
                                                         const double* zj, const double* hj,
                                                         const double* jlane, const double* ilane,
                                                         double lane_d, double radius2) {
  const __m512d r2 = tile_row_r2_lanes<Dim>(xi, yi, zi, xj, yj, zj);
  const __m512d hm = _mm512_max_pd(_mm512_loadu_pd(hi), _mm512_loadu_pd(hj));  // hi > hj ? hi : hj
  const __m512d lim = _mm512_mul_pd(_mm512_mul_pd(_mm512_set1_pd(radius2), hm), hm);
  return tile_row_in2(r2, lim, jlane, ilane, lane_d);
}
template <int Dim>
inline __attribute__((always_inline)) bool tile_row_any2_cut(const double* xi, const double* yi,
                                                             const double* zi, const double* xj,
                                                             const double* yj, const double* zj,
                                                             const double* jlane, const double* ilane,
                                                             double lane_d, double cut2) {
  const __m512d r2 = tile_row_r2_lanes<Dim>(xi, yi, zi, xj, yj, zj);
  return tile_row_in2(r2, _mm512_set1_pd(cut2), jlane, ilane, lane_d);
}
#if defined(__AVX512VBMI2__)
// The pair queue of an 8 x 8 tile (sphc --cluster-queue, codegen/ClusterPairs.cpp; stop 43,
// docs/performance-log.md "The tiles' pairs compacted (stop 43)"): the tile's pairs within the
// support packed 8 to a register, so that the lanes' arithmetic runs on pairs only (the rows
// fill 3.97 of their 8 lanes in the cube).
//
// tile_pair_mask: bit 8 ii + l for row ii (the i-cluster's real i's, the first bits of real_i;
// (xi, yi, zi, hi) its 8 slots) and lane l of the j-cluster, where tile_row_mask says so (the
// lanes' own cut-off, bit for bit; the diagonal tile: l > ii).
template <int Dim>
inline __attribute__((always_inline)) std::uint64_t tile_pair_mask(
    const double* xi, const double* yi, const double* zi, const double* hi, unsigned real_i,
    const double* xj, const double* yj, const double* zj, const double* hj, bool diagonal,
    double radius2) {
  alignas(64) static constexpr double lane[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  std::uint64_t m = 0;
  for (int ii = 0; ii < 8 && (real_i >> ii & 1u); ++ii)
    m |= static_cast<std::uint64_t>(tile_row_mask<Dim>(
             xi[ii], yi[ii], Dim == 3 ? zi[ii] : 0.0, hi[ii], xj, yj, zj, hj, lane,
             diagonal ? static_cast<double>(ii) : -1.0, radius2))
         << (8 * ii);
  return m;
}
// The set bits of m in order as bytes 8 ii + l (idx: 64 bytes; past the count, 0); the count.
inline __attribute__((always_inline)) int tile_pair_list(std::uint64_t m, std::uint8_t* idx) {
  const __m512i iota = _mm512_set_epi8(63, 62, 61, 60, 59, 58, 57, 56, 55, 54, 53, 52, 51, 50, 49,
                                       48, 47, 46, 45, 44, 43, 42, 41, 40, 39, 38, 37, 36, 35, 34,
                                       33, 32, 31, 30, 29, 28, 27, 26, 25, 24, 23, 22, 21, 20, 19,
                                       18, 17, 16, 15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2,
                                       1, 0);
  _mm512_storeu_si512(idx, _mm512_maskz_compress_epi8(m, iota));
  return __builtin_popcountll(m);
}
// A register of 8 queued pairs from idx (8 bytes): its rows ii (i) and its lanes l (j).
struct TileQueueLanes {
  __m512i i, j;
};
inline __attribute__((always_inline)) TileQueueLanes tile_queue_lanes(const std::uint8_t* idx) {
  const __m512i q = _mm512_cvtepu8_epi64(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(idx)));
  return {_mm512_srli_epi64(q, 3), _mm512_and_si512(q, _mm512_set1_epi64(7))};
}
// dst[k] = src[at[k]] (src: the cluster's 8 slots, those outside `real` not read).
inline __attribute__((always_inline)) void tile_queue_take(double* dst, __m512i at,
                                                           const double* src, __mmask8 real) {
  _mm512_store_pd(dst, _mm512_permutexvar_pd(at, _mm512_maskz_loadu_pd(real, src)));
}
// One row's pairs in a register of queued pairs: lanes [k, end) (the rows come in order), row
// ii, `lanes` those lanes as a mask, `jm` the j lanes they hold, inv[l] the register lane that
// holds (ii, l) for l in jm (the row's j's are distinct: the inverse of the compaction).
struct TileQueueSegment {
  int ii, end;
  __mmask8 lanes, jm;
  __m512i inv;
};
inline __attribute__((always_inline)) TileQueueSegment tile_queue_segment(const std::uint8_t* idx,
                                                                          int k, int count) {
  TileQueueSegment s;
  s.ii = idx[k] >> 3;
  unsigned jm = 1u << (idx[k] & 7);
  int e = k + 1;
  while (e < count && (idx[e] >> 3) == s.ii) jm |= 1u << (idx[e++] & 7);
  s.end = e;
  s.lanes = static_cast<__mmask8>(((1u << e) - 1u) & ~((1u << k) - 1u));
  s.jm = static_cast<__mmask8>(jm);
  s.inv = _mm512_maskz_expand_epi64(
      s.jm, _mm512_add_epi64(_mm512_set1_epi64(k), _mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0)));
  return s;
}
// The segment's terms onto a row's lane partial sums (i side: sums[k] += r[k] on its lanes)
// and onto the j-cluster's sums (j side: sums[l] += r[inv[l]] for l in jm).
inline __attribute__((always_inline)) void tile_queue_add_i(double* sums, const TileQueueSegment& s,
                                                            const double* r) {
  const __m512d a = _mm512_load_pd(sums);
  _mm512_store_pd(sums, _mm512_mask_add_pd(a, s.lanes, a, _mm512_load_pd(r)));
}
inline __attribute__((always_inline)) void tile_queue_add_j(double* sums, const TileQueueSegment& s,
                                                            const double* r) {
  const __m512d a = _mm512_load_pd(sums);
  _mm512_store_pd(sums, _mm512_mask_add_pd(a, s.jm, a, _mm512_permutexvar_pd(s.inv, _mm512_load_pd(r))));
}
#endif
#endif
// In order, per evaluation: the padded cluster's values, dst[k][l] = src[k][width t + l]
// for its real lanes l, its first particle's value for the padding (dst: width values
// each; nothing where every cluster is full).
void gather_tail(const ClusterLayout& layout, const double* const* src, double* const* dst,
                 int count);
// In order, per evaluation, after the boxes: the padded cluster's positions (width values
// each; tz unused in 2D), its padding lanes as gather_positions' (x = the largest x of the
// boxes + k pad_offset, y and z the cluster's first particle's).
void tail_positions(const ClusterLayout& layout, const double* x, const double* y,
                    const double* z, double* tx, double* ty, double* tz, double pad_offset);
// In order, per evaluation (the 2xMM tiles, width 4): the boxes from the particles'
// positions and the positions doubled per cluster (x2[2 w c + k] = x2[2 w c + w + k] = x[w c
// + k]), the padding lanes as tail_positions'; z, z2 unused in 2D.
void positions_doubled_boxes(ClusterLayout& layout, const double* x, const double* y,
                             const double* z, double* x2, double* y2, double* z2,
                             double pad_offset, bool parallel = true);

// Per evaluation: dst[s] = src[slot[s]] for every slot (dst: layout.slots() values); a
// padding slot takes the value of the first slot of its cluster (a real particle).
void gather_slots(const ClusterLayout& layout, const double* src, double* dst);
void gather_slots(const ClusterLayout& layout, const float* src, float* dst);

// Per evaluation, for tiles of 2 i's x a cluster's j's per register (codegen/ClusterPairs.cpp's
// 2xMM form, stop 39): gather_slots with each cluster's values twice, dst[2 w c + k] =
// dst[2 w c + w + k] = the value of slot w c + k (dst: 2 layout.slots() values).
void gather_slots_doubled(const ClusterLayout& layout, const double* src, double* dst);

// Per evaluation: the positions in slot order (z, zs unused in 2D, may be null). The k-th
// padding slot of the layout (k = 1, 2, ... in slot order; at most width - 1 per column) sits at
// x = (largest x of the real particles) + k pad_offset, its y and z those of its cluster's
// first particle: at least pad_offset from every real particle of the layout and from every
// other padding slot (so with pad_offset beyond the cut-off no padding lane is within it of
// any lane of the layout: a tile's mask holds real pairs only). Take pad_offset a few support
// radii (plus, for a cross loop, how far the other array reaches beyond this one's largest
// x), not a huge number: the coordinates stay finite and their differences exact enough.
void gather_positions(const ClusterLayout& layout, const double* x, const double* y,
                      const double* z, double* xs, double* ys, double* zs, double pad_offset);

// Per evaluation: dst[p] += sums[slot_of[p]] for every real particle p (padding never read).
void add_slots(const ClusterLayout& layout, const double* sums, double* dst);
void add_slots(const ClusterLayout& layout, const float* sums, float* dst);

// The boxes from positions in slot order (gather_positions' xs, ys, zs; real slots only; zs
// unused in 2D); under OpenMP in a parallel region only where `parallel` (the solvers pass
// n >= OMP_MIN_PARTICLES, as to the other per-evaluation pieces: a small array's pass then
// wakes no team for it, stop 46).
void update_boxes(ClusterLayout& layout, const double* xs, const double* ys, const double* zs,
                  bool parallel = true);

// The per-evaluation pieces in fewer passes (docs/performance-log.md, "The tiles' per-evaluation
// pieces (stop 39)"); each gives exactly the values of the calls it replaces. `parallel`:
// under OpenMP (libsphc_runtime_omp) the pass is one parallel region when true (the
// generated code passes n >= OMP_MIN_PARTICLES), on the calling thread when false; without
// OpenMP it is ignored.
//
// gather_slots for `count` arrays in one pass over the slots: dst[k][s] = src[k][slot[s]].
void gather_slots(const ClusterLayout& layout, const double* const* src, double* const* dst,
                  int count, bool parallel = true);
// gather_slots_doubled for `count` arrays in one parallel region (the 2xMM form's copies).
void gather_slots_doubled(const ClusterLayout& layout, const double* const* src,
                          double* const* dst, int count, bool parallel = true);
// add_slots for `count` arrays in one pass over the particles: dst[k][p] += sums[k][slot_of[p]].
void add_slots(const ClusterLayout& layout, const double* const* sums, double* const* dst,
               int count, bool parallel = true);
// gather_positions and then update_boxes, in one pass over the clusters (each cluster's box
// from the positions as they are gathered; the largest x in the same pass).
void gather_positions_boxes(ClusterLayout& layout, const double* x, const double* y,
                            const double* z, double* xs, double* ys, double* zs,
                            double pad_offset, bool parallel = true);

// A list of cluster pairs: CSR over the i-clusters.
struct ClusterPairList {
  std::vector<std::uint32_t> begin;  // n_clusters of the i layout + 1
  std::vector<std::uint32_t> j;      // j-cluster indices, increasing per i-cluster
  std::size_t pairs() const { return j.size(); }
};

// The outer list: per i-cluster of `a`, the j-clusters of `b` whose boxes (as they are now)
// lie within `radius` (box-to-box distance). once = true: a and b the same layout (&a == &b),
// only j >= i. From the grid of b's columns (the columns within reach of each i box),
// correct for boxes moved since the layout was built too.
// parallel = false: one block on the calling thread (the same list).
void build_cluster_pairs(const ClusterLayout& a, const ClusterLayout& b, double radius,
                         bool once, ClusterPairList& out, bool parallel = true);

// Per evaluation: the pairs of `outer` whose boxes (as updated now) lie within `radius`.
// parallel = false: one block on the calling thread (the same list).
void prune_cluster_pairs(const ClusterLayout& a, const ClusterLayout& b,
                         const ClusterPairList& outer, double radius, ClusterPairList& out,
                         bool parallel = true);

// The OpenMP tiles' blocks (codegen/ClusterPairs.cpp; stop 41): cut[0..blocks] cuts the
// i-clusters of `list` (a once list) into `blocks` contiguous blocks [cut[k], cut[k + 1]) of
// about the same work, counting a tile whose j-cluster lies in a later block as the two half
// tiles the blocks compute (an i-side half in its i's block, a j-side half in its j's block,
// each weighed by its measured cost against a whole tile). Any cuts give the same sums (the
// tiles' OpenMP scheme), so this only balances the threads. blocks is clamped to
// [1, n_clusters] (1 with no clusters).
void tile_block_cuts(const ClusterPairList& list, int blocks, std::vector<int>& cut);

}  // namespace sphc
