// sphc runtime: cluster-pair lists for SIMD tile loops (see sphc/cluster_pairs.h).
#include "sphc/cluster_pairs.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace sphc {

namespace {

// The box tests keep squared distances up to radius^2 (1 + kBoxMargin) (sphc/cluster_pairs.h).
constexpr double kBoxMargin = 1e-12;
// build_cluster_layout's parallel parts under OpenMP from this many particles (as
// --omp-min-particles' default: fewer cost more in waking the threads than they save).
constexpr std::size_t kLayoutParallelMin = 10000;

// A coordinate as a sort or column key: NaN as +inf (a total order for the sort; a NaN
// position lands in the last column and cluster, and must_rebuild rebuilds at every step).
inline double key(double v) { return v == v ? v : HUGE_VAL; }

// The column of coordinate v: floor((v - origin) / side) clamped to [0, count).
inline std::size_t column_of(double v, double origin, double side, std::size_t count) {
  const double t = (key(v) - origin) / side;
  if (!(t > 0)) return 0;
  if (t >= static_cast<double>(count)) return count - 1;
  return std::min(static_cast<std::size_t>(t), count - 1);
}

// Blocks of i-clusters for the build and the prune: one per OpenMP thread (1 without OpenMP),
// at most one per 64 clusters.
inline int block_count(std::size_t clusters, bool parallel = true) {
#ifdef _OPENMP
  const std::size_t threads = parallel ? static_cast<std::size_t>(omp_get_max_threads()) : 1;
#else
  (void)parallel;
  const std::size_t threads = 1;
#endif
  return static_cast<int>(std::max<std::size_t>(1, std::min(threads, clusters / 64)));
}

inline double gap(double alo, double ahi, double blo, double bhi) {
  return std::max({0.0, blo - ahi, alo - bhi});
}

// Squared distance between boxes a and b (6 doubles each), in 2D the z gap is 0.
inline double box_distance2(const double* a, const double* b) {
  const double gx = gap(a[0], a[3], b[0], b[3]);
  const double gy = gap(a[1], a[4], b[1], b[4]);
  const double gz = gap(a[2], a[5], b[2], b[5]);
  return gx * gx + gy * gy + gz * gz;
}

// The grid of columns of a layout (build_cluster_layout's rule, see sphc/cluster_pairs.h):
// sets column_side, origin and columns; returns the side.
double layout_grid(ClusterLayout& L, const double* x, const double* y, const double* z,
                   std::size_t n, int dim, double column_side, std::size_t C) {
  const int ncol_axes = dim - 1;  // 3D: x, y; 2D: x
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  const double* axes[3] = {x, y, dim == 3 ? z : nullptr};
  // The extent of the finite coordinates (a NaN fails both comparisons: skipped), under
  // OpenMP per thread then over the threads (stop 41): min and max are exact, so the same
  // extent whatever the threads (but for the sign of a zero bound, which moves no column).
  const bool parallel = n >= kLayoutParallelMin;
  (void)parallel;
  for (int a = 0; a < dim; ++a) {
    const double* v = axes[a];
    double l = HUGE_VAL, h = -HUGE_VAL;
#pragma omp parallel for schedule(static) reduction(min : l) reduction(max : h) if (parallel)
    for (std::size_t p = 0; p < n; ++p) {
      l = v[p] < l ? v[p] : l;
      h = v[p] > h ? v[p] : h;
    }
    lo[a] = l, hi[a] = h;
  }
  for (int a = 0; a < dim; ++a)
    if (!(lo[a] <= hi[a])) lo[a] = hi[a] = 0;  // no finite coordinate
  double side = column_side;
  if (!(side > 0)) {
    // (C V / n)^(1/k) over the k axes along which the particles extend (a flat wall of a 3D
    // scene: its area; a line: its length).
    double volume = 1;
    int k = 0;
    for (int a = 0; a < dim; ++a)
      if (hi[a] > lo[a]) volume *= hi[a] - lo[a], ++k;
    side = n > 0 && k > 0 ? std::pow(static_cast<double>(C) * volume / static_cast<double>(n), 1.0 / k) : 1.0;
    if (!(side > 0) || !std::isfinite(side)) side = 1.0;
  }
  // At most 4 n + 16 columns: wider columns where the extent would need more.
  const double limit = 4.0 * static_cast<double>(n) + 16.0;
  for (;;) {
    double count = 1;
    for (int a = 0; a < ncol_axes; ++a) count *= std::floor((hi[a] - lo[a]) / side) + 1;
    if (count <= limit) break;
    side *= 2;
  }
  L.column_side = side;
  L.columns[0] = L.columns[1] = 1;
  for (int a = 0; a < ncol_axes; ++a) {
    L.origin[a] = lo[a];
    L.columns[a] = static_cast<std::size_t>(std::floor((hi[a] - lo[a]) / side)) + 1;
  }
  if (ncol_axes == 1) L.origin[1] = 0;
  return side;
}

}  // namespace

double cluster_column_side(double spacing, int dim, int width) {
  return spacing * std::pow(static_cast<double>(width), 1.0 / dim);
}

namespace {

// build_cluster_layout without the boxes (cluster_order reads the slots only).
void layout_slots(ClusterLayout& L, const double* x, const double* y, const double* z,
                  std::size_t n, int dim, double column_side, int width) {
  assert(dim == 2 || dim == 3);
  assert(width >= 1 && width <= kMaxClusterSize);
  if (width < 1) width = 1;
  if (width > kMaxClusterSize) width = kMaxClusterSize;
  const std::size_t C = static_cast<std::size_t>(width);
  L.dim = dim;
  L.width = width;
  L.n = n;
  const int ncol_axes = dim - 1;  // 3D: x, y; 2D: x
  const double* col_axis[2] = {x, y};
  const double* sort_axis = dim == 3 ? z : y;
  const double side = layout_grid(L, x, y, z, n, dim, column_side, C);
  const std::size_t ncol = L.columns[0] * L.columns[1];
  L.in_order = false;
  L.column_cluster.clear();

  // Counting sort into columns (stable: particle index order within a column). Under OpenMP
  // (stop 41) each thread its static block of particles: their columns, its counts per
  // column, then its block scattered from its own offsets (a column's earlier blocks' first):
  // the serial order exactly.
  const bool parallel = n >= kLayoutParallelMin;
  (void)parallel;
  std::vector<std::uint32_t> col(n);
  std::vector<std::uint32_t> count(ncol + 1, 0);
  std::vector<std::pair<double, std::uint32_t>> order(n);  // (sort key, particle)
  std::vector<std::vector<std::uint32_t>> at;  // per thread: its next slot per column
#pragma omp parallel if (parallel)
  {
#ifdef _OPENMP
    const int nt = omp_get_num_threads(), t = omp_get_thread_num();
#else
    const int nt = 1, t = 0;
#endif
#pragma omp single
    at.assign(static_cast<std::size_t>(nt), std::vector<std::uint32_t>(ncol, 0));
    const std::size_t p0 = n * static_cast<std::size_t>(t) / static_cast<std::size_t>(nt);
    const std::size_t p1 = n * static_cast<std::size_t>(t + 1) / static_cast<std::size_t>(nt);
    std::vector<std::uint32_t>& mine = at[static_cast<std::size_t>(t)];
    for (std::size_t p = p0; p < p1; ++p) {
      std::size_t c = column_of(col_axis[0][p], L.origin[0], side, L.columns[0]);
      if (ncol_axes == 2) c += L.columns[0] * column_of(col_axis[1][p], L.origin[1], side, L.columns[1]);
      col[p] = static_cast<std::uint32_t>(c);
      ++mine[c];
    }
#pragma omp barrier
#pragma omp single
    {  // offsets: column by column, within a column thread by thread
      std::uint32_t sum = 0;
      for (std::size_t c = 0; c < ncol; ++c) {
        count[c] = sum;
        for (int k = 0; k < nt; ++k) {
          const std::uint32_t m = at[static_cast<std::size_t>(k)][c];
          at[static_cast<std::size_t>(k)][c] = sum;
          sum += m;
        }
      }
      count[ncol] = sum;
    }
    for (std::size_t p = p0; p < p1; ++p)
      order[mine[col[p]]++] = {key(sort_axis[p]), static_cast<std::uint32_t>(p)};
  }
  // Each column by its sort key (ties by particle index: a total order, so the same layout
  // whatever the threads), then cut into clusters. Under OpenMP the columns' sorts and their
  // slots in parallel (stop 39) where there are at least kLayoutParallelMin particles.
  const long ncols = static_cast<long>(ncol);
#pragma omp parallel for schedule(dynamic, 16) if (parallel)
  for (long c = 0; c < ncols; ++c)
    std::sort(order.begin() + count[c], order.begin() + count[c + 1]);
  L.column_begin.assign(ncol + 1, 0);
  std::size_t clusters = 0;
  for (std::size_t c = 0; c < ncol; ++c) {
    L.column_begin[c] = static_cast<std::uint32_t>(clusters);
    clusters += (count[c + 1] - count[c] + C - 1) / C;
  }
  L.column_begin[ncol] = static_cast<std::uint32_t>(clusters);
  L.n_clusters = clusters;
  L.slot.assign(clusters * C, kPadSlot);
  L.slot_of.assign(n, 0);
  L.real_mask.assign(clusters, 0);
#pragma omp parallel for schedule(dynamic, 16) if (parallel)
  for (long c = 0; c < ncols; ++c) {  // a column's clusters are its own
    std::size_t s = static_cast<std::size_t>(L.column_begin[c]) * C;
    for (std::size_t k = count[c]; k < count[c + 1]; ++k, ++s) {
      const std::uint32_t p = order[k].second;
      L.slot[s] = p;
      L.slot_of[p] = static_cast<std::uint32_t>(s);
      L.real_mask[s / C] |= static_cast<std::uint8_t>(1u << (s % C));
    }
  }
}

}  // namespace

void build_cluster_layout(ClusterLayout& L, const double* x, const double* y, const double* z,
                          std::size_t n, int dim, double column_side, int width) {
  layout_slots(L, x, y, z, n, dim, column_side, width);
  // Boxes from these positions (of the real slots: the positions' gather with the boxes).
  L.box.assign(L.n_clusters * 6, 0.0);
  std::vector<double> xs(L.slots()), ys(L.slots()), zs(dim == 3 ? L.slots() : 0);
  gather_positions_boxes(L, x, y, z, xs.data(), ys.data(), dim == 3 ? zs.data() : nullptr, 0.0,
                         n >= kLayoutParallelMin);
}

void cluster_order(std::vector<std::uint32_t>& order, const double* x, const double* y,
                   const double* z, std::size_t n, int dim, double column_side, int width) {
  ClusterLayout L;
  layout_slots(L, x, y, z, n, dim, column_side, width);  // (no boxes: stop 41)
  const std::size_t C = static_cast<std::size_t>(L.width);
  order.clear();
  order.reserve(n);
  std::vector<std::uint32_t> rest;  // the columns' last clusters' particles, if not full
  for (std::size_t cy = 0; cy < L.columns[1]; ++cy)
    for (std::size_t k = 0; k < L.columns[0]; ++k) {
      const std::size_t cx = cy % 2 == 0 ? k : L.columns[0] - 1 - k;
      const std::size_t col = cy * L.columns[0] + cx;
      for (std::size_t c = L.column_begin[col]; c < L.column_begin[col + 1]; ++c) {
        std::vector<std::uint32_t>& to = L.real_mask[c] == L.full_mask() ? order : rest;
        for (std::size_t s = c * C; s < (c + 1) * C; ++s)
          if (L.slot[s] != kPadSlot) to.push_back(L.slot[s]);
      }
    }
  order.insert(order.end(), rest.begin(), rest.end());
}

void build_cluster_layout_in_order(ClusterLayout& L, const double* x, const double* y,
                                   const double* z, std::size_t n, int dim, double column_side,
                                   int width) {
  assert(dim == 2 || dim == 3);
  if (width < 1) width = 1;
  if (width > kMaxClusterSize) width = kMaxClusterSize;
  const std::size_t C = static_cast<std::size_t>(width);
  L.dim = dim;
  L.width = width;
  L.n = n;
  L.in_order = true;
  const double side = layout_grid(L, x, y, z, n, dim, column_side, C);
  const std::size_t ncol = L.columns[0] * L.columns[1];
  const std::size_t nc = (n + C - 1) / C;
  L.n_clusters = nc;
  L.slot.resize(nc * C);
  L.slot_of.resize(n);
  {
    const bool parallel = n >= kLayoutParallelMin;
    (void)parallel;
    std::uint32_t* const slot = L.slot.data();
    std::uint32_t* const slot_of = L.slot_of.data();
    const long ns = static_cast<long>(nc * C);
#pragma omp parallel for schedule(static) if (parallel)
    for (long s = 0; s < ns; ++s) {
      const std::size_t u = static_cast<std::size_t>(s);
      slot[u] = u < n ? static_cast<std::uint32_t>(u) : kPadSlot;
      if (u < n) slot_of[u] = static_cast<std::uint32_t>(u);
    }
  }
  L.real_mask.assign(nc, L.full_mask());
  if (nc * C != n) L.real_mask[nc - 1] = static_cast<std::uint8_t>((1u << (n - (nc - 1) * C)) - 1u);
  L.box.assign(nc * 6, 0.0);
  update_boxes(L, x, y, z);  // the real slots are the particles themselves
  // Each cluster in the column of its box's centre; a column's clusters by the low sort
  // coordinate of their boxes (ties by index).
  const int sa = dim == 3 ? 2 : 1;
  std::vector<std::uint32_t> col(nc);
  std::vector<std::uint32_t> count(ncol + 1, 0);
  for (std::size_t c = 0; c < nc; ++c) {
    const double* b = &L.box[6 * c];
    std::size_t k = column_of(0.5 * (b[0] + b[3]), L.origin[0], side, L.columns[0]);
    if (dim == 3) k += L.columns[0] * column_of(0.5 * (b[1] + b[4]), L.origin[1], side, L.columns[1]);
    col[c] = static_cast<std::uint32_t>(k);
    ++count[k + 1];
  }
  for (std::size_t k = 0; k < ncol; ++k) count[k + 1] += count[k];
  L.column_begin.assign(count.begin(), count.end());
  std::vector<std::pair<double, std::uint32_t>> entry(nc);
  {
    std::vector<std::uint32_t> at(count.begin(), count.end() - 1);
    for (std::size_t c = 0; c < nc; ++c)
      entry[at[col[c]]++] = {key(L.box[6 * c + sa]), static_cast<std::uint32_t>(c)};
  }
  for (std::size_t k = 0; k < ncol; ++k)
    std::sort(entry.begin() + count[k], entry.begin() + count[k + 1]);
  L.column_cluster.resize(nc);
  for (std::size_t k = 0; k < nc; ++k) L.column_cluster[k] = entry[k].second;
}

namespace {

// The largest x of the boxes' real particles (the padding's reference).
double boxes_xmax(const ClusterLayout& L) {
  double xmax = -HUGE_VAL;
  for (std::size_t c = 0; c < L.n_clusters; ++c) xmax = std::max(xmax, L.box[6 * c + 3]);
  return xmax;
}

}  // namespace

void gather_tail(const ClusterLayout& L, const double* const* src, double* const* dst,
                 int count) {
  const std::size_t t = tail_cluster(L);
  if (t == L.n_clusters) return;
  const int C = L.width;
  const std::size_t s0 = t * static_cast<std::size_t>(C);
  const int m = static_cast<int>(L.n - s0);
  for (int a = 0; a < count; ++a)
    for (int l = 0; l < C; ++l) dst[a][l] = src[a][s0 + static_cast<std::size_t>(l < m ? l : 0)];
}

void tail_positions(const ClusterLayout& L, const double* x, const double* y, const double* z,
                    double* tx, double* ty, double* tz, double pad_offset) {
  const std::size_t t = tail_cluster(L);
  if (t == L.n_clusters) return;
  const int C = L.width;
  const std::size_t s0 = t * static_cast<std::size_t>(C);
  const int m = static_cast<int>(L.n - s0);
  const double xmax = boxes_xmax(L);
  double k = 0;
  for (int l = 0; l < C; ++l) {
    const std::size_t p = s0 + static_cast<std::size_t>(l < m ? l : 0);
    tx[l] = l < m ? x[p] : xmax + (k += 1) * pad_offset;
    ty[l] = y[p];
    if (L.dim == 3) tz[l] = z[p];
  }
}


namespace {

// W: the layout's width, a constant for the default 8 (the loops unrolled), 0 for another
// (read from the layout).
template <int W, class T>
void gather_slots_w(const ClusterLayout& L, const T* src, T* dst) {
  const int C = W > 0 ? W : L.width;
  const std::uint8_t full = L.full_mask();
  const std::uint32_t* slot = L.slot.data();
  const std::size_t nc = L.n_clusters;
#pragma omp parallel for schedule(static)
  for (std::size_t c = 0; c < nc; ++c) {
    const std::uint32_t* sl = slot + c * C;
    T* d = dst + c * C;
    if (L.real_mask[c] == full) {
      for (int k = 0; k < C; ++k) d[k] = src[sl[k]];
    } else {
      const T first = src[sl[0]];
      for (int k = 0; k < C; ++k) d[k] = sl[k] == kPadSlot ? first : src[sl[k]];
    }
  }
}

template <class T>
void gather_slots_of(const ClusterLayout& L, const T* src, T* dst) {
  if (L.width == kClusterSize)
    gather_slots_w<kClusterSize>(L, src, dst);
  else
    gather_slots_w<0>(L, src, dst);
}

template <class T>
void add_slots_of(const ClusterLayout& L, const T* sums, T* dst) {
  const std::uint32_t* slot_of = L.slot_of.data();
  const std::size_t n = L.n;
#pragma omp parallel for schedule(static)
  for (std::size_t p = 0; p < n; ++p) dst[p] += sums[slot_of[p]];
}

}  // namespace

void gather_slots(const ClusterLayout& L, const double* src, double* dst) {
  gather_slots_of(L, src, dst);
}
void gather_slots(const ClusterLayout& L, const float* src, float* dst) {
  gather_slots_of(L, src, dst);
}
void add_slots(const ClusterLayout& L, const double* sums, double* dst) {
  add_slots_of(L, sums, dst);
}
void add_slots(const ClusterLayout& L, const float* sums, float* dst) {
  add_slots_of(L, sums, dst);
}

void gather_slots_doubled(const ClusterLayout& L, const double* src, double* dst) {
  gather_slots_doubled(L, &src, &dst, 1);  // the arrays' form, one array
}

void gather_positions(const ClusterLayout& L, const double* x, const double* y, const double* z,
                      double* xs, double* ys, double* zs, double pad_offset) {
  const bool three = L.dim == 3;
  gather_slots_of(L, x, xs);
  gather_slots_of(L, y, ys);
  if (three) gather_slots_of(L, z, zs);
  if (L.slots() == L.n) return;  // no padding
  double xmax = -HUGE_VAL;
  for (std::size_t p = 0; p < L.n; ++p) xmax = std::max(xmax, x[p]);
  const int C = L.width;
  const unsigned full = L.full_mask();
  double k = 0;  // the padding slots numbered 1, 2, ... in slot order
  for (std::size_t c = 0; c < L.n_clusters; ++c) {
    const unsigned m = L.real_mask[c];
    if (m == full) continue;
    for (int lane = 0; lane < C; ++lane)
      if (!(m >> lane & 1u)) xs[c * C + lane] = xmax + (k += 1) * pad_offset;
  }
}

namespace {

template <int W>
void update_boxes_w(ClusterLayout& L, const double* xs, const double* ys, const double* zs,
                    bool parallel) {
  const int C = W > 0 ? W : L.width;
  const std::uint8_t full = L.full_mask();
  const bool three = L.dim == 3;
  const std::size_t nc = L.n_clusters;
  double* box = L.box.data();
  (void)parallel;
#pragma omp parallel for schedule(static) if (parallel)
  for (std::size_t c = 0; c < nc; ++c) {
    const std::size_t s0 = c * C;
    double* b = box + 6 * c;
    if (L.real_mask[c] == full) {
      double lx = xs[s0], hx = xs[s0], ly = ys[s0], hy = ys[s0];
      for (int k = 1; k < C; ++k) {
        lx = std::min(lx, xs[s0 + k]), hx = std::max(hx, xs[s0 + k]);
        ly = std::min(ly, ys[s0 + k]), hy = std::max(hy, ys[s0 + k]);
      }
      double lz = 0, hz = 0;
      if (three) {
        lz = hz = zs[s0];
        for (int k = 1; k < C; ++k) lz = std::min(lz, zs[s0 + k]), hz = std::max(hz, zs[s0 + k]);
      }
      b[0] = lx, b[1] = ly, b[2] = lz, b[3] = hx, b[4] = hy, b[5] = hz;
    } else {
      const int m = __builtin_popcount(L.real_mask[c]);  // the real slots come first
      double lx = xs[s0], hx = xs[s0], ly = ys[s0], hy = ys[s0];
      double lz = three ? zs[s0] : 0, hz = lz;
      for (int k = 1; k < m; ++k) {
        lx = std::min(lx, xs[s0 + k]), hx = std::max(hx, xs[s0 + k]);
        ly = std::min(ly, ys[s0 + k]), hy = std::max(hy, ys[s0 + k]);
        if (three) lz = std::min(lz, zs[s0 + k]), hz = std::max(hz, zs[s0 + k]);
      }
      b[0] = lx, b[1] = ly, b[2] = lz, b[3] = hx, b[4] = hy, b[5] = hz;
    }
  }
}

}  // namespace

void update_boxes(ClusterLayout& L, const double* xs, const double* ys, const double* zs,
                  bool parallel) {
  if (L.width == kClusterSize)
    update_boxes_w<kClusterSize>(L, xs, ys, zs, parallel);
  else
    update_boxes_w<0>(L, xs, ys, zs, parallel);
}

namespace {

// The arrays one after another (a pass over the slots each: long streams, measured faster
// than all the arrays per cluster, bench/cluster_lists.cpp `--flush`), under OpenMP in one
// parallel region (each thread the same clusters of every array: no barrier between them).
// The frame of the one-call gathers: `count` arrays one after another, under OpenMP in one
// parallel region, each thread the same clusters of every array (`omp for nowait`);
// `cluster(s, sl, c, da)` writes cluster c of array da from source s, its slots sl.
template <typename PerCluster>
void gather_each_array(const ClusterLayout& L, int C, const double* const* src,
                       double* const* dst, int count, bool parallel, PerCluster cluster) {
  const std::uint32_t* slot = L.slot.data();
  const std::size_t nc = L.n_clusters;
  (void)parallel;
#pragma omp parallel if (parallel)
  for (int a = 0; a < count; ++a) {
    const double* s = src[a];
    double* const da = dst[a];
#pragma omp for schedule(static) nowait
    for (std::size_t c = 0; c < nc; ++c) cluster(s, slot + c * C, c, da);
  }
}

template <int W>
void gather_slots_n_w(const ClusterLayout& L, const double* const* src, double* const* dst,
                      int count, bool parallel) {
  const int C = W > 0 ? W : L.width;
  const std::uint8_t full = L.full_mask();
  const std::uint8_t* real = L.real_mask.data();
  gather_each_array(L, C, src, dst, count, parallel,
                    [=](const double* s, const std::uint32_t* sl, std::size_t c, double* da) {
                      double* d = da + c * C;
                      if (real[c] == full) {
                        for (int k = 0; k < C; ++k) d[k] = s[sl[k]];
                      } else {  // padding: its cluster's first value
                        const double first = s[sl[0]];
                        for (int k = 0; k < C; ++k) d[k] = sl[k] == kPadSlot ? first : s[sl[k]];
                      }
                    });
}

// One cluster's box from its gathered positions (update_boxes_w's arithmetic).
template <int W>
inline void cluster_box(int C, unsigned mask, unsigned full, bool three, const double* xs,
                        const double* ys, const double* zs, double* b) {
  if (mask == full) {
    double lx = xs[0], hx = xs[0], ly = ys[0], hy = ys[0];
    for (int k = 1; k < C; ++k) {
      lx = std::min(lx, xs[k]), hx = std::max(hx, xs[k]);
      ly = std::min(ly, ys[k]), hy = std::max(hy, ys[k]);
    }
    double lz = 0, hz = 0;
    if (three) {
      lz = hz = zs[0];
      for (int k = 1; k < C; ++k) lz = std::min(lz, zs[k]), hz = std::max(hz, zs[k]);
    }
    b[0] = lx, b[1] = ly, b[2] = lz, b[3] = hx, b[4] = hy, b[5] = hz;
  } else {
    const int m = __builtin_popcount(mask);  // the real slots come first
    double lx = xs[0], hx = xs[0], ly = ys[0], hy = ys[0];
    double lz = three ? zs[0] : 0, hz = lz;
    for (int k = 1; k < m; ++k) {
      lx = std::min(lx, xs[k]), hx = std::max(hx, xs[k]);
      ly = std::min(ly, ys[k]), hy = std::max(hy, ys[k]);
      if (three) lz = std::min(lz, zs[k]), hz = std::max(hz, zs[k]);
    }
    b[0] = lx, b[1] = ly, b[2] = lz, b[3] = hx, b[4] = hy, b[5] = hz;
  }
}

template <int W>
void gather_positions_boxes_w(ClusterLayout& L, const double* x, const double* y,
                              const double* z, double* xs, double* ys, double* zs,
                              double pad_offset, bool parallel) {
  const int C = W > 0 ? W : L.width;
  const unsigned full = L.full_mask();
  const bool three = L.dim == 3;
  const std::uint32_t* slot = L.slot.data();
  const std::uint8_t* real = L.real_mask.data();
  double* box = L.box.data();
  const std::size_t nc = L.n_clusters;
  // The largest x of the real particles: per thread, then over the threads (max is exact and
  // std::max skips a NaN second argument, so the value of gather_positions' scan in particle
  // order, whatever the order; a +-0 makes no difference to the padding's x).
  double xmax = -HUGE_VAL;
  (void)parallel;
#pragma omp parallel if (parallel)
  {
    double xm = -HUGE_VAL;
#pragma omp for schedule(static) nowait
    for (std::size_t c = 0; c < nc; ++c) {
      const std::uint32_t* sl = slot + c * C;
      const unsigned mask = real[c];
      double* dx = xs + c * C;
      double* dy = ys + c * C;
      double* dz = three ? zs + c * C : nullptr;
      if (mask == full) {
        for (int k = 0; k < C; ++k) dx[k] = x[sl[k]], dy[k] = y[sl[k]];
        if (three)
          for (int k = 0; k < C; ++k) dz[k] = z[sl[k]];
        for (int k = 0; k < C; ++k) xm = std::max(xm, dx[k]);
      } else {
        const std::uint32_t p0 = sl[0];
        for (int k = 0; k < C; ++k) {
          const std::uint32_t p = sl[k] == kPadSlot ? p0 : sl[k];
          dx[k] = x[p], dy[k] = y[p];
          if (three) dz[k] = z[p];
        }
        const int m = __builtin_popcount(mask);
        for (int k = 0; k < m; ++k) xm = std::max(xm, dx[k]);
      }
      cluster_box<W>(C, mask, full, three, dx, dy, dz, box + 6 * c);
    }
#pragma omp critical(sphc_cluster_xmax)
    xmax = std::max(xmax, xm);
  }
  if (L.slots() == L.n) return;  // no padding
  double k = 0;  // the padding slots numbered 1, 2, ... in slot order
  for (std::size_t c = 0; c < nc; ++c) {
    const unsigned m = real[c];
    if (m == full) continue;
    for (int lane = 0; lane < C; ++lane)
      if (!(m >> lane & 1u)) xs[c * C + lane] = xmax + (k += 1) * pad_offset;
  }
}

// One cluster's C values written twice into d (the 2xMM j side: d[k] = d[C + k]); value(k) is
// the cluster's k-th value, read only for a real slot (a padding slot takes the first value).
template <class Value>
inline void write_doubled(double* d, int C, bool whole, const std::uint32_t* sl, Value value) {
  if (C == 4 && whole) {  // the 2xMM width: unrolled
    const double v0 = value(0), v1 = value(1), v2 = value(2), v3 = value(3);
    d[0] = d[4] = v0;
    d[1] = d[5] = v1;
    d[2] = d[6] = v2;
    d[3] = d[7] = v3;
  } else {
    const double first = value(0);
    for (int k = 0; k < C; ++k) d[k] = d[C + k] = sl[k] == kPadSlot ? first : value(k);
  }
}

// gather_slots_doubled's values for `count` arrays, as gather_slots_n_w: one parallel region.
void gather_slots_doubled_n(const ClusterLayout& L, const double* const* src,
                            double* const* dst, int count, bool parallel) {
  const int C = L.width;
  const std::uint8_t full = L.full_mask();
  const std::uint8_t* real = L.real_mask.data();
  if (L.in_order && C == 4) {  // slot s is particle s: contiguous reads (stop 40)
    gather_each_array(L, C, src, dst, count, parallel,
                      [=](const double* s, const std::uint32_t* sl, std::size_t c, double* d2) {
                        const double* v = s + 4 * c;
                        write_doubled(d2 + 8 * c, 4, real[c] == full, sl,
                                      [v](int k) { return v[k]; });
                      });
    return;
  }
  gather_each_array(L, C, src, dst, count, parallel,
                    [=](const double* s, const std::uint32_t* sl, std::size_t c, double* da) {
                      write_doubled(da + 2 * c * C, C, real[c] == full, sl,
                                    [s, sl](int k) { return s[sl[k]]; });
                    });
}

// As gather_slots_n_w: a pass per array, one parallel region.
void add_slots_n(const ClusterLayout& L, const double* const* sums, double* const* dst,
                 int count, bool parallel) {
  const std::uint32_t* slot_of = L.slot_of.data();
  const std::size_t n = L.n;
  (void)parallel;
#pragma omp parallel if (parallel)
  for (int a = 0; a < count; ++a) {
    const double* s = sums[a];
    double* const d = dst[a];
#pragma omp for schedule(static) nowait
    for (std::size_t p = 0; p < n; ++p) d[p] += s[slot_of[p]];
  }
}

}  // namespace

void gather_slots_doubled(const ClusterLayout& L, const double* const* src,
                          double* const* dst, int count, bool parallel) {
  if (count > 0) gather_slots_doubled_n(L, src, dst, count, parallel);
}

void gather_slots(const ClusterLayout& L, const double* const* src, double* const* dst,
                  int count, bool parallel) {
  if (count <= 0) return;
  if (L.width == kClusterSize)
    gather_slots_n_w<kClusterSize>(L, src, dst, count, parallel);
  else
    gather_slots_n_w<0>(L, src, dst, count, parallel);
}

void add_slots(const ClusterLayout& L, const double* const* sums, double* const* dst, int count,
               bool parallel) {
  if (count <= 0) return;
  add_slots_n(L, sums, dst, count, parallel);
}

void gather_positions_boxes(ClusterLayout& L, const double* x, const double* y, const double* z,
                            double* xs, double* ys, double* zs, double pad_offset,
                            bool parallel) {
  if (L.width == kClusterSize)
    gather_positions_boxes_w<kClusterSize>(L, x, y, z, xs, ys, zs, pad_offset, parallel);
  else
    gather_positions_boxes_w<0>(L, x, y, z, xs, ys, zs, pad_offset, parallel);
}

void positions_doubled_boxes(ClusterLayout& L, const double* x, const double* y,
                             const double* z, double* x2, double* y2, double* z2,
                             double pad_offset, bool parallel) {
  const int C = L.width;
  const bool three = L.dim == 3;
  const unsigned full = L.full_mask();
  const std::size_t nc = L.n_clusters;
  const std::uint8_t* real = L.real_mask.data();
  double* box = L.box.data();
  (void)parallel;
#pragma omp parallel for schedule(static) if (parallel)
  for (std::size_t c = 0; c < nc; ++c) {
    const std::size_t s0 = c * C;
    double* dx = x2 + 2 * s0;
    double* dy = y2 + 2 * s0;
    double* dz = three ? z2 + 2 * s0 : nullptr;
    if (real[c] == full) {
      for (int k = 0; k < C; ++k) {
        dx[k] = dx[C + k] = x[s0 + k];
        dy[k] = dy[C + k] = y[s0 + k];
        if (three) dz[k] = dz[C + k] = z[s0 + k];
      }
    }
    cluster_box<0>(C, real[c], full, three, x + s0, y + s0, three ? z + s0 : nullptr, box + 6 * c);
  }
  const std::size_t t = tail_cluster(L);
  if (t == nc) return;
  double tx[kMaxClusterSize], ty[kMaxClusterSize], tz[kMaxClusterSize];
  tail_positions(L, x, y, z, tx, ty, tz, pad_offset);
  const std::size_t s0 = t * C;
  for (int k = 0; k < C; ++k) {
    x2[2 * s0 + k] = x2[2 * s0 + C + k] = tx[k];
    y2[2 * s0 + k] = y2[2 * s0 + C + k] = ty[k];
    if (three) z2[2 * s0 + k] = z2[2 * s0 + C + k] = tz[k];
  }
}

namespace {

// Per column of b, running bounds along the sort axis: lo_up[k] = max of the clusters'
// high sort coordinate up to k (from the column's first), lo_down[k] = min of their low sort
// coordinate from k to the column's last. Both increase with k, so the j-clusters within
// reach of [zlo, zhi] along the sort axis are within [first k with up[k] >= zlo, first k
// with down[k] > zhi): exact for any boxes (the layout's own are sorted already).
struct ColumnBounds {
  std::vector<double> up, down;
  double overhang = 0;  // the most a box sticks out of its column's x-y square (+ slack)
  double slack = 0;     // absolute slack of the reach along the sort axis
  // In order (stop 40): per column the x and y bounds of its clusters' boxes (lo x, hi x, lo
  // y, hi y; empty: inverted), which the search tests in place of the widened square (a
  // cluster of the columns' tops may reach over several columns: the overhang is large).
  std::vector<double> ext;
};

ColumnBounds column_bounds(const ClusterLayout& b) {
  ColumnBounds cb;
  const int sa = b.dim == 3 ? 2 : 1;
  cb.up.resize(b.n_clusters);
  cb.down.resize(b.n_clusters);
  if (b.in_order) cb.ext.assign(4 * b.columns[0] * b.columns[1], 0.0);
  const std::size_t ncol = b.columns[0] * b.columns[1];
  double over = 0;
  for (std::size_t col = 0; col < ncol; ++col) {
    const std::size_t c0 = b.column_begin[col], c1 = b.column_begin[col + 1];
    if (c0 == c1) continue;
    // (entries k of the column: cluster k, or column_cluster[k] in order)
    const std::uint32_t* cc = b.in_order ? b.column_cluster.data() : nullptr;
    auto cl = [&](std::size_t k) { return cc ? static_cast<std::size_t>(cc[k]) : k; };
    double run = -HUGE_VAL;
    for (std::size_t c = c0; c < c1; ++c) run = std::max(run, b.box[6 * cl(c) + 3 + sa]), cb.up[c] = run;
    run = HUGE_VAL;
    for (std::size_t c = c1; c-- > c0;) run = std::min(run, b.box[6 * cl(c) + sa]), cb.down[c] = run;
    if (cc) {
      double e[4] = {HUGE_VAL, -HUGE_VAL, HUGE_VAL, -HUGE_VAL};
      for (std::size_t c = c0; c < c1; ++c) {
        const double* bx = &b.box[6 * cl(c)];
        e[0] = std::min(e[0], bx[0]), e[1] = std::max(e[1], bx[3]);
        e[2] = std::min(e[2], bx[1]), e[3] = std::max(e[3], bx[4]);
      }
      std::copy(e, e + 4, cb.ext.begin() + 4 * static_cast<std::ptrdiff_t>(col));
    }
    const std::size_t cx = col % b.columns[0], cy = col / b.columns[0];
    const double x0 = b.origin[0] + static_cast<double>(cx) * b.column_side, x1 = x0 + b.column_side;
    const double y0 = b.origin[1] + static_cast<double>(cy) * b.column_side, y1 = y0 + b.column_side;
    for (std::size_t c = c0; c < c1; ++c) {
      const double* bx = &b.box[6 * cl(c)];
      over = std::max({over, x0 - bx[0], bx[3] - x1});
      if (b.dim == 3) over = std::max({over, y0 - bx[1], bx[4] - y1});
    }
  }
  // Slack over the rounding of the column bounds and the reach (which the box tests, exact
  // for the same doubles, do not need): 1e-9 of a column plus a few ulps of the coordinates.
  double extent = std::fabs(b.origin[0]) + std::fabs(b.origin[1]) +
                  static_cast<double>(b.columns[0] + b.columns[1]) * b.column_side;
  for (std::size_t c = 0; c < b.n_clusters; ++c)
    extent = std::max(extent, std::fabs(b.box[6 * c + sa]) + std::fabs(b.box[6 * c + 3 + sa]));
  cb.slack = 1e-9 * b.column_side + 1e-14 * extent;
  cb.overhang = over == over ? over + cb.slack : HUGE_VAL;
  return cb;
}

// The column range [lo, hi] of b along axis a that may hold boxes reaching [vlo, vhi].
inline void column_range(const ClusterLayout& b, int a, double vlo, double vhi, double reach,
                         std::size_t& lo, std::size_t& hi) {
  const double count = static_cast<double>(b.columns[a]);
  // A box in column k lies within [origin + k side - overhang, origin + (k + 1) side +
  // overhang]; 1e-9 columns of slack over the rounding of these bounds.
  double t0 = std::floor((vlo - reach - b.origin[a]) / b.column_side - 1e-9);
  double t1 = std::floor((vhi + reach - b.origin[a]) / b.column_side + 1e-9);
  if (!(t0 > 0)) t0 = 0;
  if (!(t1 < count)) t1 = count - 1;
  if (!(t0 <= t1)) {  // none
    lo = 1, hi = 0;
    return;
  }
  lo = static_cast<std::size_t>(t0);
  hi = static_cast<std::size_t>(t1);
}

// The j-clusters of b for i box `ib` (i-cluster ci of a; once: j >= ci), appended to out in
// increasing order.
void find_pairs(const ClusterLayout& b, const ColumnBounds& cb, const double* ib, double radius,
                double r2, bool once, std::size_t ci, std::vector<std::uint32_t>& out) {
  const int sa = b.dim == 3 ? 2 : 1;
  const double reach = radius * (1 + 1e-9) + cb.overhang;
  std::size_t x0, x1, y0 = 0, y1 = 0;
  column_range(b, 0, ib[0], ib[3], reach, x0, x1);
  if (b.dim == 3) column_range(b, 1, ib[1], ib[4], reach, y0, y1);
  if (x0 > x1 || y0 > y1) return;
  const std::uint32_t* cc = b.in_order ? b.column_cluster.data() : nullptr;
  const std::size_t first = out.size();
  for (std::size_t cy = y0; cy <= y1; ++cy) {
    // The column's x-y square widened by the overhang: its distance to the i box.
    double gy2 = 0;
    if (b.dim == 3) {
      const double c0 = b.origin[1] + static_cast<double>(cy) * b.column_side - cb.overhang;
      const double g = gap(ib[1], ib[4], c0, c0 + b.column_side + 2 * cb.overhang);
      gy2 = g * g;
    }
    for (std::size_t cx = x0; cx <= x1; ++cx) {
      const double c0 = b.origin[0] + static_cast<double>(cx) * b.column_side - cb.overhang;
      double gx = gap(ib[0], ib[3], c0, c0 + b.column_side + 2 * cb.overhang);
      double gyc2 = gy2;
      if (cc) {  // in order: the column's own bounds (a box's gaps are at least these)
        const std::size_t col = cy * b.columns[0] + cx;
        if (b.column_begin[col] == b.column_begin[col + 1]) continue;
        const double* e = &cb.ext[4 * col];
        gx = gap(ib[0], ib[3], e[0], e[1]);
        if (b.dim == 3) {
          const double gy = gap(ib[1], ib[4], e[2], e[3]);
          gyc2 = gy * gy;
        }
      }
      const double gxy2 = gx * gx + gyc2;
      if (gxy2 > r2) continue;
      // Along the sort axis a box of this column within r2 is within sqrt(r2 - gxy2).
      const double reach_z = std::sqrt(r2 - gxy2) * (1 + 1e-9) + cb.slack;
      const double zlo = ib[sa] - reach_z, zhi = ib[3 + sa] + reach_z;
      const std::size_t col = cy * b.columns[0] + cx;
      std::size_t k = b.column_begin[col];
      const std::size_t end = b.column_begin[col + 1];
      if (!cc && once && end <= ci) continue;
      // First cluster whose running high bound reaches zlo.
      k = static_cast<std::size_t>(
          std::lower_bound(cb.up.begin() + k, cb.up.begin() + end, zlo) - cb.up.begin());
      if (cc) {  // in order: the entries' clusters, any index
        for (; k < end && !(cb.down[k] > zhi); ++k) {
          const std::size_t j = cc[k];
          if ((!once || j >= ci) && box_distance2(ib, &b.box[6 * j]) <= r2)
            out.push_back(static_cast<std::uint32_t>(j));
        }
        continue;
      }
      if (once && k < ci) k = ci;
      for (; k < end && !(cb.down[k] > zhi); ++k)
        if (box_distance2(ib, &b.box[6 * k]) <= r2) out.push_back(static_cast<std::uint32_t>(k));
    }
  }
  if (cc) std::sort(out.begin() + static_cast<std::ptrdiff_t>(first), out.end());  // increasing j
}

}  // namespace

void build_cluster_pairs(const ClusterLayout& a, const ClusterLayout& b, double radius,
                         bool once, ClusterPairList& out, bool parallel) {
  assert(!once || &a == &b);
  assert(a.dim == b.dim);
  const ColumnBounds cb = column_bounds(b);
  const double r2 = radius * radius * (1 + kBoxMargin);
  const std::size_t nci = a.n_clusters;
  out.begin.assign(nci + 1, 0);
  out.j.clear();
  if (b.n_clusters == 0) return;
  // Blocks of i-clusters (one per thread under OpenMP), concatenated in order.
  const int nblocks = block_count(nci, parallel);
  std::vector<std::vector<std::uint32_t>> part(nblocks);
  part[0].swap(out.j);  // the first block writes into out.j's storage (kept across rebuilds)
  part[0].clear();
#pragma omp parallel for schedule(static, 1) if (nblocks > 1)
  for (int blk = 0; blk < nblocks; ++blk) {
    const std::size_t c0 = nci * blk / nblocks, c1 = nci * (blk + 1) / nblocks;
    std::vector<std::uint32_t>& o = part[blk];
    o.reserve((c1 - c0) * 32);
    for (std::size_t ci = c0; ci < c1; ++ci) {
      find_pairs(b, cb, &a.box[6 * ci], radius, r2, once, ci, o);
      out.begin[ci + 1] = static_cast<std::uint32_t>(o.size());
    }
  }
  std::size_t total = part[0].size();
  for (int blk = 1; blk < nblocks; ++blk) {
    const std::size_t c0 = nci * blk / nblocks, c1 = nci * (blk + 1) / nblocks;
    for (std::size_t ci = c0; ci < c1; ++ci) out.begin[ci + 1] += static_cast<std::uint32_t>(total);
    total += part[blk].size();
  }
  out.j.swap(part[0]);
  out.j.resize(total);
  for (int blk = 1; blk < nblocks; ++blk) {
    const std::size_t c0 = nci * blk / nblocks;
    std::copy(part[blk].begin(), part[blk].end(), out.j.begin() + out.begin[c0]);
  }
}

void prune_cluster_pairs(const ClusterLayout& a, const ClusterLayout& b,
                         const ClusterPairList& outer, double radius, ClusterPairList& out,
                         bool parallel) {
  assert(&out != &outer);
  const double r2 = radius * radius * (1 + kBoxMargin);
  const std::size_t nci = a.n_clusters;
  out.begin.assign(nci + 1, 0);
  out.j.resize(outer.j.size());
  const double* abox = a.box.data();
  const double* bbox = b.box.data();
  // Blocks of i-clusters (one per thread under OpenMP): each compacts its kept pairs within
  // its own part of out.j (the outer list's range), then the parts are moved together in
  // order: the serial result.
  const int nblocks = block_count(nci, parallel);
  std::vector<std::size_t> kept(nblocks, 0);
#pragma omp parallel for schedule(static, 1) if (nblocks > 1)
  for (int blk = 0; blk < nblocks; ++blk) {
    const std::size_t c0 = nci * blk / nblocks, c1 = nci * (blk + 1) / nblocks;
    const std::size_t first = outer.begin[c0];
    std::uint32_t* oj = out.j.data();
    const std::uint32_t* ij = outer.j.data();
    std::size_t at = first;
    for (std::size_t ci = c0; ci < c1; ++ci) {
      const double* ib = abox + 6 * ci;
      const double ilx = ib[0], ily = ib[1], ilz = ib[2], ihx = ib[3], ihy = ib[4], ihz = ib[5];
      for (std::uint32_t e = outer.begin[ci]; e < outer.begin[ci + 1]; ++e) {
        const std::uint32_t cj = ij[e];
        const double* jb = bbox + 6 * static_cast<std::size_t>(cj);
        const double gx = std::max({0.0, jb[0] - ihx, ilx - jb[3]});
        const double gy = std::max({0.0, jb[1] - ihy, ily - jb[4]});
        const double gz = std::max({0.0, jb[2] - ihz, ilz - jb[5]});
        oj[at] = cj;  // branch-free: written always, kept by advancing
        at += gx * gx + gy * gy + gz * gz <= r2 ? 1 : 0;
      }
      out.begin[ci + 1] = static_cast<std::uint32_t>(at - first);  // within the block, for now
    }
    kept[blk] = at - first;
  }
  std::size_t total = 0;
  for (int blk = 0; blk < nblocks; ++blk) {
    const std::size_t c0 = nci * blk / nblocks, c1 = nci * (blk + 1) / nblocks;
    const std::size_t first = outer.begin[c0];
    if (total != first)  // to the left: memmove's order is safe
      std::copy(out.j.begin() + first, out.j.begin() + first + kept[blk], out.j.begin() + total);
    for (std::size_t ci = c0; ci < c1; ++ci) out.begin[ci + 1] += static_cast<std::uint32_t>(total);
    total += kept[blk];
  }
  out.j.resize(total);
}

namespace {

// The CPU time of a half tile against a whole one in the OpenMP tiles (each pair once, 8 x 8,
// the cube's bodies; the two blocks' thread CPU at 2 threads, their (1) part timed apart, in a
// hand-instrumented cube solver, stop 41: docs/performance-log.md): the i side (the calls for
// the i's, their lane sums) 0.55, the j side (the mirrored calls, the j sums and their fold)
// 0.85: a tile across two blocks costs 1.4 tiles, more of it in the later block.
constexpr double kHalfTileI = 0.55;
constexpr double kHalfTileJ = 0.85;

}  // namespace

void tile_block_cuts(const ClusterPairList& list, int blocks, std::vector<int>& cut) {
  const std::size_t nc = list.begin.empty() ? 0 : list.begin.size() - 1;
  blocks = static_cast<int>(std::max<std::size_t>(1, std::min<std::size_t>(static_cast<std::size_t>(std::max(blocks, 1)), nc)));
  cut.assign(static_cast<std::size_t>(blocks) + 1, static_cast<int>(nc));
  cut[0] = 0;
  if (blocks == 1) return;
  const std::uint32_t* b = list.begin.data();
  const std::uint32_t* j = list.j.data();
  const double total = static_cast<double>(b[nc]);
  // The first i-cluster whose list starts at or after q pairs.
  auto at = [&](double q) {
    const double c = std::min(std::max(q, 0.0), total);
    return static_cast<int>(std::lower_bound(b, b + nc, static_cast<std::uint32_t>(c)) - b);
  };
  // The cuts by pairs, and the tiles across each (i before the cut, j at or after it).
  std::vector<double> across(static_cast<std::size_t>(blocks) + 1, 0.0);
  for (int k = 1; k < blocks; ++k) cut[k] = at(total * k / blocks);
  const std::size_t last = static_cast<std::size_t>(cut[blocks - 1]);
  for (std::size_t i = 0; i < last; ++i) {
    const std::uint32_t e0 = b[i], e1 = b[i + 1];
    if (e0 == e1) continue;
    for (int k = 1; k < blocks; ++k) {
      const std::uint32_t c = static_cast<std::uint32_t>(cut[k]);
      if (i < c && j[e1 - 1] >= c)
        across[k] += static_cast<double>(j + e1 - std::lower_bound(j + e0, j + e1, c));
    }
  }
  // Block k's work: its i-clusters' pairs, less (1 - kHalfTileI) of those across its end
  // (computed as i-side halves), plus kHalfTileJ of those across its start (j-side halves):
  // the same for every block where the cuts are at these prefix sums of the pairs.
  double sum = 0;
  for (int k = 1; k < blocks; ++k) sum += across[k];
  const double each = (total + (kHalfTileI + kHalfTileJ - 1.0) * sum) / blocks;
  double q = 0;
  for (int k = 1; k < blocks; ++k) {
    q += each + (1.0 - kHalfTileI) * across[k] - kHalfTileJ * across[k - 1];
    cut[k] = std::max(cut[k - 1], at(q));
  }
}

}  // namespace sphc
