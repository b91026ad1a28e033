// sphc runtime: cell-list neighbour search (non-inline parts). See nnps.h.
#include "sphc/nnps.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace sphc {

namespace {

void check_dim(int dim, const char* who) {
  if (dim < 1 || dim > 3) {
    throw std::invalid_argument(std::string(who) + ": dim must be 1, 2 or 3 (got " +
                                std::to_string(dim) + ")");
  }
}

// What a search domain is made from, gathered array by array (make_search_domain and its
// float form): the box of the finite coordinates and the largest finite h.
struct Extent {
  int dim;
  double radius_scale;
  double lo[3], hi[3];
  double hmax = 0.0;

  Extent(int dim_, double radius_scale_) : dim(dim_), radius_scale(radius_scale_) {
    check_dim(dim, "sphc::make_search_domain");
    if (!(radius_scale > 0.0) || !std::isfinite(radius_scale)) {
      throw std::invalid_argument("sphc::make_search_domain: radius_scale must be > 0 (got " +
                                  std::to_string(radius_scale) + ")");
    }
    const double inf = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) lo[a] = inf, hi[a] = -inf;
  }

  // Axis a of n particles, every stride-th value of v; v null: the array has no such
  // coordinate, which reads as 0.
  template <class T>
  void add_axis(int a, const T* v, std::size_t n, std::size_t stride) {
    if (v == nullptr) {
      lo[a] = std::min(lo[a], 0.0);
      hi[a] = std::max(hi[a], 0.0);
      return;
    }
    double l = lo[a], u = hi[a];
    // The OpenMP build of the runtime (libsphc_runtime_omp) runs these loops in parallel
    // (from 16384 values: below, waking the team costs more than the loop; 12 regions a
    // step in the 2D dam break); min and max do not depend on the order, so the result is
    // the serial one.
#pragma omp parallel for reduction(min : l) reduction(max : u) schedule(static) if (n > 16384)
    for (std::size_t i = 0; i < n; ++i) {
      const double w = v[i * stride];
      if (!std::isfinite(w)) continue;
      l = std::min(l, w);
      u = std::max(u, w);
    }
    lo[a] = l;
    hi[a] = u;
  }

  template <class T>
  void add_h(const T* v, std::size_t n, std::size_t stride) {
    double m = hmax;
#pragma omp parallel for reduction(max : m) schedule(static) if (n > 16384)
    for (std::size_t i = 0; i < n; ++i) {
      const double w = v[i * stride];
      if (std::isfinite(w) && w > m) m = w;
    }
    hmax = m;
  }

  SearchDomain domain() const { return search_domain_of_box(lo, hi, hmax, dim, radius_scale); }
};

}  // namespace

SearchDomain make_search_domain(const std::vector<const ParticleArray*>& arrays, int dim,
                                double radius_scale) {
  Extent e(dim, radius_scale);
  static const char* const kAxis[3] = {"x", "y", "z"};
  for (const ParticleArray* pa : arrays) {
    if (pa == nullptr || pa->n == 0) continue;
    for (const char* need : {"x", "h"}) {
      const int idx = pa->find(need);
      if (idx < 0 || pa->props[idx].type != PropType::F64) {
        throw std::invalid_argument("sphc::make_search_domain: array '" + pa->name +
                                    "' has no double property '" + need + "'");
      }
    }
    for (int a = 0; a < dim; ++a) {
      const int idx = pa->find(kAxis[a]);
      if (idx < 0 || pa->props[idx].type != PropType::F64) {
        e.add_axis<double>(a, nullptr, 0, 1);
        continue;
      }
      const Property& p = pa->props[idx];
      e.add_axis(a, p.f64.data(), pa->n, static_cast<std::size_t>(p.stride));
    }
    const Property& h = pa->props[pa->find("h")];
    e.add_h(h.f64.data(), pa->n, static_cast<std::size_t>(h.stride));
  }
  return e.domain();
}

SearchDomain make_search_domain_float(const std::vector<FloatCoords>& arrays, int dim,
                                      double radius_scale) {
  Extent e(dim, radius_scale);
  for (const FloatCoords& c : arrays) {
    if (c.n == 0) continue;
    if (c.x == nullptr || c.h == nullptr)
      throw std::invalid_argument("sphc::make_search_domain: an array has no x or no h");
    const float* axis[3] = {c.x, c.y, c.z};
    for (int a = 0; a < dim; ++a) e.add_axis(a, axis[a], c.n, 1);
    e.add_h(c.h, c.n, 1);
  }
  return e.domain();
}

SearchDomain search_domain_of_box(const double lo[3], const double hi[3], double hmax, int dim,
                                  double radius_scale) {
  SearchDomain dom;
  dom.dim = dim;
  dom.cell_size = hmax > 0.0 && std::isfinite(hmax) ? radius_scale * hmax : 1.0;
  const double pad = 1e-6 * dom.cell_size;
  for (int a = 0; a < 3; ++a) {
    if (a < dim && lo[a] <= hi[a]) {
      dom.lo[a] = lo[a] - pad;
      dom.hi[a] = hi[a] + pad;
    } else {
      dom.lo[a] = dom.hi[a] = 0.0;  // axis unused, or no finite coordinate at all
    }
  }
  return dom;
}

std::uint32_t CellList::insert_cell(std::uint64_t key, std::uint32_t& next_cell) {
  const std::size_t mask = keys_.size() - 1;
  for (std::size_t s = slot_of(key);; s = (s + 1) & mask) {
    if (keys_[s] == key) return slot_cell_[s];
    if (keys_[s] == kEmptyKey) {
      keys_[s] = key;
      slot_cell_[s] = next_cell;
      return next_cell++;
    }
  }
}

void CellList::build(const SearchDomain& dom, const double* x, const double* y,
                     const double* z, std::size_t n) {
  build_impl(dom, x, y, z, n);
}

void CellList::build(const SearchDomain& dom, const float* x, const float* y, const float* z,
                     std::size_t n) {
  build_impl(dom, x, y, z, n);
}

template <class T>
void CellList::build_impl(const SearchDomain& dom, const T* x, const T* y, const T* z,
                          std::size_t n) {
  check_dim(dom.dim, "sphc::CellList::build");
  if (n >= kNoCell) {
    throw std::invalid_argument("sphc::CellList::build: too many particles (" +
                                std::to_string(n) + ")");
  }
  n_ = n;

  // Grid geometry. Cells may be made larger than dom.cell_size (never smaller, which keeps
  // the 3^dim stencil sufficient) so that each axis has at most kMaxCellsPerAxis cells; an
  // unusable cell size (0, negative, NaN) degrades to one cell per axis.
  double extent[3] = {0.0, 0.0, 0.0};
  double max_extent = 0.0;
  for (int a = 0; a < dom.dim; ++a) {
    const double e = dom.hi[a] - dom.lo[a];
    extent[a] = std::isfinite(e) && e > 0.0 ? e : 0.0;
    max_extent = std::max(max_extent, extent[a]);
  }
  double cell = dom.cell_size;
  if (!(cell > 0.0) || !std::isfinite(cell)) cell = max_extent > 0.0 ? max_extent : 1.0;
  cell = std::max(cell, max_extent / (kMaxCellsPerAxis - 1));
  inv_cell_ = 1.0 / cell;
  double total_cells = 1.0;
  for (int a = 0; a < 3; ++a) {
    const bool used = a < dom.dim && std::isfinite(dom.lo[a]);
    lo_[a] = used ? dom.lo[a] : 0.0;
    ncell_[a] = used ? static_cast<int>(std::min<double>(std::floor(extent[a] * inv_cell_) + 1.0,
                                                         kMaxCellsPerAxis))
                     : 1;
    cmax_[a] = ncell_[a] - 1;
    total_cells *= ncell_[a];
  }

  constexpr double kMaxDense = 2147483648.0;  // dense cell numbers must fit in uint32
  switch (mode_) {
    case Mode::Auto:
      dense_ = total_cells <= 8.0 * static_cast<double>(n) + 1024.0 && total_cells < kMaxDense;
      break;
    case Mode::Dense: dense_ = total_cells < kMaxDense; break;
    case Mode::Hash: dense_ = false; break;
  }

  // Cell of every particle (coordinates read as double, whatever T is).
  cell_of_.resize(n);
  std::size_t num_cells = 0;
  if (dense_) {
    num_cells = static_cast<std::size_t>(total_cells);
    // Independent per particle: computed by counting_sort, inside its parallel region (one
    // region and no extra barrier per build).
    std::uint32_t* cell_of = cell_of_.data();
    counting_sort(num_cells, [&](std::size_t i0, std::size_t i1) {
      for (std::size_t i = i0; i < i1; ++i) {
        int c[3];
        cell_coords(x[i], y ? static_cast<double>(y[i]) : 0.0,
                    z ? static_cast<double>(z[i]) : 0.0, c);
        cell_of[i] = static_cast<std::uint32_t>(
            c[0] + static_cast<std::size_t>(ncell_[0]) *
                       (c[1] + static_cast<std::size_t>(ncell_[1]) * c[2]));
      }
    });
    return;
  } else {
    // Occupied cells are numbered in order of first appearance (deterministic; serial, since
    // the numbering depends on the order).
    int bits = 4;
    while ((std::size_t{1} << bits) < 2 * n) ++bits;
    keys_.assign(std::size_t{1} << bits, kEmptyKey);
    slot_cell_.resize(keys_.size());
    hash_shift_ = 64 - bits;
    std::uint32_t next_cell = 0;
    for (std::size_t i = 0; i < n; ++i) {
      int c[3];
      cell_coords(x[i], y ? static_cast<double>(y[i]) : 0.0, z ? static_cast<double>(z[i]) : 0.0,
                  c);
      cell_of_[i] = insert_cell(pack(c[0], c[1], c[2]), next_cell);
    }
    num_cells = next_cell;
  }
  counting_sort(num_cells, [](std::size_t, std::size_t) {});
}

int CellList::sort_threads() const {
  if (sort_chunks_ > 0) return sort_chunks_;
#ifdef _OPENMP
  // Below this many particles per thread the parallel region costs more than it saves.
  int t = omp_in_parallel() ? 1 : omp_get_max_threads();
  if (n_ < static_cast<std::size_t>(t) * kParallelMinPerThread) t = 1;
  return std::max(t, 1);
#else
  return 1;
#endif
}

template <class KeyFn>
void CellList::counting_sort(std::size_t num_cells, KeyFn&& keys) {
  const std::size_t n = n_;
  const std::uint32_t* cell_of = cell_of_.data();
  start_.resize(num_cells + 1);
  order_.resize(n);
  const int threads = sort_threads();
  last_chunks_ = threads;
  if (threads <= 1) {
    keys(0, n);
    // Stable counting sort by cell: count, inclusive prefix sum (start_[c] = end of cell c),
    // then place particles from last to first, decrementing, which leaves start_[c] = begin.
    std::fill(start_.begin(), start_.end(), 0u);
    for (std::size_t i = 0; i < n; ++i) ++start_[cell_of[i]];
    std::uint32_t running = 0;
    for (std::size_t c = 0; c < num_cells; ++c) {
      running += start_[c];
      start_[c] = running;
    }
    start_[num_cells] = static_cast<std::uint32_t>(n);
    for (std::size_t i = n; i-- > 0;) order_[--start_[cell_of[i]]] = static_cast<std::uint32_t>(i);
    return;
  }

  // The same sort in parallel, with the same result. Chunk k of the particles (contiguous,
  // ascending) belongs to one thread, and so does range k of the cells.
  //  1. Chunk k: the cells of its particles (keys), their smallest and largest cell (the
  //     chunk's window: particles are kept in cell order, so a chunk's cells are mostly a
  //     narrow range) and the chunk's count per cell of the window.
  //  2. Cell range k: the number of particles in it (from the windows that overlap it).
  //  3. Cell range k: its first position (the particles of ranges 0..k-1), then per cell c
  //     start[c] and, for every chunk j in order, j's first position in c (the particles of
  //     chunks 0..j-1 in c), in place of j's count: within a cell the order is ascending by
  //     index, as in the serial sort.
  //  4. Chunk k: its particles to their positions.
  // Work per thread O(n / T + C / T + the windows' sizes), C the cells; three barriers.
  const std::size_t T = static_cast<std::size_t>(threads);
  const std::size_t C = num_cells;
  if (chunk_hist_.size() < T) chunk_hist_.resize(T);
  chunk_lo_.resize(T);
  range_count_.resize(T);
  std::vector<std::uint32_t>* hist = chunk_hist_.data();
  std::uint32_t* lo = chunk_lo_.data();
  std::uint32_t* range_count = range_count_.data();
  std::uint32_t* start = start_.data();
  std::uint32_t* order = order_.data();
  auto range = [](std::size_t total, std::size_t parts, std::size_t k) {
    return std::pair<std::size_t, std::size_t>(total * k / parts, total * (k + 1) / parts);
  };
#pragma omp parallel num_threads(threads)
  {
#ifdef _OPENMP
    const std::size_t t = static_cast<std::size_t>(omp_get_thread_num());
    const std::size_t nt = static_cast<std::size_t>(omp_get_num_threads());
#else
    const std::size_t t = 0, nt = 1;
#endif
    // (An OpenMP implementation may give fewer threads than asked: then each thread does
    // the chunks and ranges k = t, t + nt, ...)
    for (std::size_t k = t; k < T; k += nt) {
      const auto [i0, i1] = range(n, T, k);
      keys(i0, i1);
      std::uint32_t cmin = 0xffffffffu, cmax = 0;
      for (std::size_t i = i0; i < i1; ++i) {
        cmin = std::min(cmin, cell_of[i]);
        cmax = std::max(cmax, cell_of[i]);
      }
      std::vector<std::uint32_t>& h = hist[k];
      if (i0 == i1) {
        lo[k] = 0;
        h.clear();
        continue;
      }
      lo[k] = cmin;
      h.assign(static_cast<std::size_t>(cmax - cmin) + 1, 0u);
      std::uint32_t* hk = h.data();
      for (std::size_t i = i0; i < i1; ++i) ++hk[cell_of[i] - cmin];
    }
#pragma omp barrier
    for (std::size_t k = t; k < T; k += nt) {
      const auto [c0, c1] = range(C, T, k);
      std::uint32_t count = 0;
      for (std::size_t j = 0; j < T; ++j) {
        const std::size_t w0 = std::max<std::size_t>(c0, lo[j]);
        const std::size_t w1 = std::min<std::size_t>(c1, lo[j] + hist[j].size());
        const std::uint32_t* hj = hist[j].data();
        for (std::size_t c = w0; c < w1; ++c) count += hj[c - lo[j]];
      }
      range_count[k] = count;
    }
#pragma omp barrier
    for (std::size_t k = t; k < T; k += nt) {
      const auto [c0, c1] = range(C, T, k);
      std::uint32_t running = 0;
      for (std::size_t j = 0; j < k; ++j) running += range_count[j];
      for (std::size_t c = c0; c < c1; ++c) {
        start[c] = running;
        for (std::size_t j = 0; j < T; ++j) {
          const std::size_t w = c - lo[j];  // wraps around below the window
          if (c >= lo[j] && w < hist[j].size()) {
            std::uint32_t& e = hist[j][w];
            const std::uint32_t count = e;
            e = running;
            running += count;
          }
        }
      }
    }
#pragma omp barrier
    for (std::size_t k = t; k < T; k += nt) {
      const auto [i0, i1] = range(n, T, k);
      std::uint32_t* hk = hist[k].data();
      const std::uint32_t cmin = lo[k];
      for (std::size_t i = i0; i < i1; ++i)
        order[hk[cell_of[i] - cmin]++] = static_cast<std::uint32_t>(i);
    }
  }
  start_[num_cells] = static_cast<std::uint32_t>(n);
}

void CellList::neighbors(double xi, double yi, double zi, double hi, const double* x,
                         const double* y, const double* z, const double* h, double radius_scale,
                         std::vector<std::uint32_t>& out) const {
  out.clear();
  for_each_candidate(xi, yi, zi, [&](std::uint32_t j) {
    const double dx = xi - x[j];
    const double dy = yi - (y ? y[j] : 0.0);
    const double dz = zi - (z ? z[j] : 0.0);
    const double rmax = radius_scale * std::max(hi, h[j]);
    if (dx * dx + dy * dy + dz * dz < rmax * rmax) out.push_back(j);
  });
}

// The bits of v (21 used) spread to every third bit: bit k of v at bit 3k.
static inline std::uint64_t spread3(std::uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffull;
  v = (v | v << 16) & 0x1f0000ff0000ffull;
  v = (v | v << 8) & 0x100f00f00f00f00full;
  v = (v | v << 4) & 0x10c30c30c30c30c3ull;
  v = (v | v << 2) & 0x1249249249249249ull;
  return v;
}

void CellList::locality_order(std::vector<std::uint32_t>& out) const {
  out.resize(n_);
  zcells_.clear();
  const auto z_key = [](std::uint64_t cx, std::uint64_t cy, std::uint64_t cz) {
    return spread3(cx) | spread3(cy) << 1 | spread3(cz) << 2;
  };
  if (dense_) {
    const std::size_t nx = static_cast<std::size_t>(ncell_[0]);
    const std::size_t nxy = nx * static_cast<std::size_t>(ncell_[1]);
    for (std::size_t c = 0; c + 1 < start_.size(); ++c) {
      if (start_[c + 1] == start_[c]) continue;  // empty
      zcells_.emplace_back(z_key(c % nx, (c % nxy) / nx, c / nxy), static_cast<std::uint32_t>(c));
    }
  } else {
    const std::uint64_t mask = (std::uint64_t{1} << kCellBits) - 1;
    for (std::size_t s = 0; s < keys_.size(); ++s) {
      const std::uint64_t k = keys_[s];
      if (k == kEmptyKey) continue;
      zcells_.emplace_back(z_key(k & mask, (k >> kCellBits) & mask, k >> (2 * kCellBits)),
                           slot_cell_[s]);
    }
  }
  // The keys are distinct (one per cell): the order is a function of the cells alone.
  std::sort(zcells_.begin(), zcells_.end());
  std::size_t k = 0;
  for (const auto& zc : zcells_)
    for (std::uint32_t i = start_[zc.second]; i < start_[zc.second + 1]; ++i) out[k++] = order_[i];
}

}  // namespace sphc
