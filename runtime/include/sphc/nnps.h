// sphc runtime: neighbour search with a cell list.
//
// All arrays of a scene share one SearchDomain (bounding box and cell size); each source array
// gets its own CellList built on it every time step (a static wall, which nothing moves: once,
// on a grid of its own box with that cell size). The generated loop asks for candidates
// of a destination point and applies the neighbour criterion itself:
//
//     j is a neighbour of i  <=>  r_ij < radius_scale * max(h_i, h_j)
//
// This works with fixed and variable h. Because the cell size is radius_scale * (max h over
// all arrays), every neighbour lies at most one cell away along each axis, so the 3^dim cells
// around the point's cell hold every neighbour (candidates are a superset of neighbours).
//
// Robustness: cell coordinates are clamped to the grid, so a point outside the domain (a
// particle that moved since the domain was made, or a query point anywhere) lands in the
// nearest border cell; NaN coordinates land in cell 0. Clamping never moves two points
// further apart in cell units, so the 3^dim stencil stays sufficient for such points too
// (only efficiency suffers if many particles pile up in border cells).
//
// Storage: particle indices sorted by cell (stable counting sort, so ascending index within a
// cell) in one contiguous vector, with cell start offsets. When the grid has at most
// 8 n + 1024 cells it is dense (cell = linear index; the three cells of a row along x are
// contiguous, so a stencil is 3^(dim-1) contiguous ranges). Otherwise (sparse domains) only
// occupied cells are numbered, through an open-addressing hash of the cell coordinates, so
// memory stays O(n). Both build in O(n) and reuse their buffers between builds.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "sphc/particle_array.h"

namespace sphc {

struct SearchDomain {
  int dim = 2;
  double lo[3] = {0.0, 0.0, 0.0};
  double hi[3] = {0.0, 0.0, 0.0};
  double cell_size = 1.0;
};

// Bounding box over the x, y, z of all particles of all arrays (a missing y or z is 0; axes
// beyond `dim` are [0, 0]; non-finite coordinates are ignored), padded by 1e-6 * cell_size,
// and cell_size = radius_scale * max h over all arrays (property "h"; 1.0 when there is no
// positive finite h, e.g. no particles). Throws std::invalid_argument for dim not in 1..3,
// radius_scale <= 0, or a non-empty array without "x" or "h".
SearchDomain make_search_domain(const std::vector<const ParticleArray*>& arrays, int dim,
                                double radius_scale);

// The same from float coordinates (--precision=single): x, y, z, h of each array (y, z
// nullptr where missing, read as 0). The box and h are taken as doubles, exactly.
struct FloatCoords {
  const float* x = nullptr;
  const float* y = nullptr;
  const float* z = nullptr;
  const float* h = nullptr;
  std::size_t n = 0;
};
SearchDomain make_search_domain_float(const std::vector<FloatCoords>& arrays, int dim,
                                      double radius_scale);

// The search domain of a bounding box [lo, hi] of finite coordinates (lo[a] > hi[a]: no
// coordinate along a) and the largest h (cell 1.0 unless hmax is positive and finite): what
// the two above end with, and what the OpenCL backend finishes its device reductions with,
// so that every backend builds the same grid.
SearchDomain search_domain_of_box(const double lo[3], const double hi[3], double hmax, int dim,
                                  double radius_scale);

class CellList {
 public:
  // Auto picks dense or hashed storage by the number of cells; Dense and Hash force one (for
  // tests and benchmarks; Dense still falls back to Hash beyond 2^31 cells).
  enum class Mode { Auto, Dense, Hash };

  // Sorts particles 0..n-1 into cells. y and z may be nullptr (treated as 0). Throws
  // std::invalid_argument if dom.dim is not 1..3 or n >= 2^32 - 1. Float coordinates
  // (--precision=single) are converted to double for the cell computation.
  // In the OpenMP runtime the build runs in parallel from 4096 particles per thread (cell
  // keys, then a counting sort with a histogram per thread over the cells its particles
  // occupy, see counting_sort) and gives exactly the serial result: the same order_ and
  // start_, hence the same candidate order. (Hashed storage numbers the occupied cells
  // serially.)
  void build(const SearchDomain& dom, const double* x, const double* y, const double* z,
             std::size_t n);
  void build(const SearchDomain& dom, const float* x, const float* y, const float* z,
             std::size_t n);

  // Calls f(std::uint32_t j) for every particle j in the 3^dim cells around the cell of
  // (xi, yi, zi). Deterministic order: cells by z, then y, then x, ascending; within a cell by
  // ascending j. Valid (calls nothing) before the first build.
  template <class F>
  inline void for_each_candidate(double xi, double yi, double zi, F&& f) const;
  // The same candidates as ranges [k0, k1) of the cell order: range(k0, k1) per stencil row
  // (dense) or cell (hashed); both traversals are built on it.
  template <class R>
  inline void for_each_candidate_range(double xi, double yi, double zi, R&& range) const;

  // The neighbour list of a point: writes to out[0..count) the candidates j (in the order of
  // for_each_candidate) for which keep(j) is true, and returns count. out grows as needed
  // (never shrinks: one vector per thread, reused from particle to particle; its size is not
  // the count). The generated pair loops filter first, with a keep() that only computes the
  // distance (small, inlined, branch-free: every candidate is written, the count advances
  // only for neighbours), then run the equations over out[0..count) in a plain loop: no
  // unpredictable branch or call per candidate, a third of which are neighbours in 2D.
  template <class Keep>
  inline std::size_t gather_neighbours(double xi, double yi, double zi,
                                       std::vector<std::uint32_t>& out, Keep&& keep) const;

  std::size_t size() const { return n_; }

  // Convenience for tests and tools, not for the hot loop: out = the indices j (in candidate
  // order) with |x_i - x_j| < radius_scale * max(hi, h[j]), distance over x, y, z (nullptr y
  // or z read as 0). A query at a particle's own position includes that particle.
  void neighbors(double xi, double yi, double zi, double hi, const double* x, const double* y,
                 const double* z, const double* h, double radius_scale,
                 std::vector<std::uint32_t>& out) const;

  // Particle indices in cell order (cell by cell, ascending within a cell): the permutation
  // that makes neighbours close in memory (see ParticleArray::permute).
  const std::vector<std::uint32_t>& cell_order() const { return order_; }

  // Particle indices with the cells visited in Z order (Morton order of the cells' grid
  // coordinates: the bits of x, y, z interleaved), ascending within a cell. A sweep over the
  // particles in this order reads its neighbours from a compact block of nearby cells, where
  // cell_order() (x fastest, then y, then z) reads three whole layers of cells: what the
  // particle re-sort uses (ParticleArray::permute), so that the pair loops' working set stays
  // in cache at 1M particles. Written to out (resized; its buffer reused); deterministic.
  void locality_order(std::vector<std::uint32_t>& out) const;

  // Cell c holds cell_order()[cell_start()[c] .. cell_start()[c + 1]) (num_cells() + 1
  // entries).
  const std::vector<std::uint32_t>& cell_start() const { return start_; }

  void set_mode(Mode m) { mode_ = m; }
  // Tests: sort in `chunks` chunks with the parallel algorithm whatever the size and thread
  // count (in a runtime without OpenMP the chunks run one after the other); 0 = automatic.
  void set_sort_chunks(int chunks) { sort_chunks_ = chunks; }
  // Chunks of the last build's sort (1: the serial sort).
  int last_sort_chunks() const { return last_chunks_; }
  bool is_dense() const { return dense_; }
  // Dense: all cells of the grid; hashed: occupied cells.
  std::size_t num_cells() const { return start_.size() - 1; }
  const int* cells_per_axis() const { return ncell_; }

 private:
  static constexpr std::uint32_t kNoCell = 0xffffffffu;
  static constexpr std::uint64_t kEmptyKey = ~std::uint64_t{0};  // never a packed key
  static constexpr int kCellBits = 21;                           // 3 * 21 bits in a key
  static constexpr int kMaxCellsPerAxis = 1 << kCellBits;

  // Cell coordinate along an axis: NaN and values below the grid give 0, values beyond it
  // give the last cell; for values in range truncation is floor.
  static inline int axis_cell(double v, double cmax) {
    v = v >= 0.0 ? v : 0.0;
    v = v <= cmax ? v : cmax;
    return static_cast<int>(v);
  }
  inline void cell_coords(double x, double y, double z, int c[3]) const {
    c[0] = axis_cell((x - lo_[0]) * inv_cell_, cmax_[0]);
    c[1] = axis_cell((y - lo_[1]) * inv_cell_, cmax_[1]);
    c[2] = axis_cell((z - lo_[2]) * inv_cell_, cmax_[2]);
  }
  static inline std::uint64_t pack(int cx, int cy, int cz) {
    return static_cast<std::uint64_t>(cx) | (static_cast<std::uint64_t>(cy) << kCellBits) |
           (static_cast<std::uint64_t>(cz) << (2 * kCellBits));
  }
  inline std::size_t slot_of(std::uint64_t key) const {
    // Fibonacci hashing: the top bits of key * 2^64/phi.
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> hash_shift_);
  }
  // Hashed storage: the cell number of a packed key, kNoCell if unoccupied.
  inline std::uint32_t find_cell(std::uint64_t key) const {
    const std::size_t mask = keys_.size() - 1;
    for (std::size_t s = slot_of(key);; s = (s + 1) & mask) {
      const std::uint64_t k = keys_[s];
      if (k == key) return slot_cell_[s];
      if (k == kEmptyKey) return kNoCell;
    }
  }
  std::uint32_t insert_cell(std::uint64_t key, std::uint32_t& next_cell);
  template <class T>
  void build_impl(const SearchDomain& dom, const T* x, const T* y, const T* z, std::size_t n);
  // Stable counting sort of 0..n_-1 by cell_of_ into order_ and start_; keys(i0, i1) fills
  // cell_of_[i0..i1) first (inside the parallel region: each thread its own chunk).
  template <class KeyFn>
  void counting_sort(std::size_t num_cells, KeyFn&& keys);
  // Chunks (threads) for counting_sort: 1 = the serial sort.
  int sort_threads() const;
  static constexpr std::size_t kParallelMinPerThread = 4096;

  Mode mode_ = Mode::Auto;
  bool dense_ = true;
  std::size_t n_ = 0;
  double lo_[3] = {0.0, 0.0, 0.0};
  double inv_cell_ = 0.0;
  double cmax_[3] = {0.0, 0.0, 0.0};  // ncell_ - 1, as doubles for clamping
  int ncell_[3] = {1, 1, 1};
  // Cell c holds order_[start_[c] .. start_[c + 1]).
  std::vector<std::uint32_t> start_ = {0, 0};
  std::vector<std::uint32_t> order_;
  std::vector<std::uint32_t> cell_of_;  // build scratch: cell of each particle
  // locality_order's scratch: (Z key, cell) of the occupied cells.
  mutable std::vector<std::pair<std::uint64_t, std::uint32_t>> zcells_;
  // Parallel sort scratch, per chunk: the counts, then write positions, of the cells
  // chunk_lo_[k] .. chunk_lo_[k] + chunk_hist_[k].size() - 1 (the chunk's window); the
  // particles of each of the chunks' cell ranges.
  std::vector<std::vector<std::uint32_t>> chunk_hist_;
  std::vector<std::uint32_t> chunk_lo_;
  std::vector<std::uint32_t> range_count_;
  int sort_chunks_ = 0;
  int last_chunks_ = 1;
  // Hashed storage: open addressing with linear probing, size a power of two >= 2 n.
  std::vector<std::uint64_t> keys_;
  std::vector<std::uint32_t> slot_cell_;
  int hash_shift_ = 64;
};

// The candidates' stencil (the particle's cell and its neighbours, clipped to the grid) as
// ranges [k0, k1) of order_, in the order both traversals below visit them.
template <class R>
inline void CellList::for_each_candidate_range(double xi, double yi, double zi, R&& range) const {
  int c[3];
  cell_coords(xi, yi, zi, c);
  // Stencil bounds, clipped to the grid (axes beyond dim have one cell, so they give 0..0).
  int lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = c[a] > 0 ? c[a] - 1 : 0;
    hi[a] = c[a] + 1 < ncell_[a] ? c[a] + 1 : c[a];
  }
  const std::uint32_t* start = start_.data();
  if (dense_) {
    for (int cz = lo[2]; cz <= hi[2]; ++cz) {
      for (int cy = lo[1]; cy <= hi[1]; ++cy) {
        // Cells lo[0]..hi[0] of a row are consecutive: one contiguous range of order_.
        const std::size_t row =
            (static_cast<std::size_t>(cz) * ncell_[1] + static_cast<std::size_t>(cy)) *
            ncell_[0];
        range(start[row + lo[0]], start[row + hi[0] + 1]);
      }
    }
  } else {
    for (int cz = lo[2]; cz <= hi[2]; ++cz) {
      for (int cy = lo[1]; cy <= hi[1]; ++cy) {
        for (int cx = lo[0]; cx <= hi[0]; ++cx) {
          const std::uint32_t cell = find_cell(pack(cx, cy, cz));
          if (cell != kNoCell) range(start[cell], start[cell + 1]);
        }
      }
    }
  }
}

// The particle order of CellList::locality_order, returned (for the generated re-sorts).
inline std::vector<std::uint32_t> locality_order(const CellList& cells) {
  std::vector<std::uint32_t> out;
  cells.locality_order(out);
  return out;
}

template <class F>
inline void CellList::for_each_candidate(double xi, double yi, double zi, F&& f) const {
  const std::uint32_t* order = order_.data();
  for_each_candidate_range(xi, yi, zi, [&](std::uint32_t k0, std::uint32_t k1) {
    for (std::uint32_t k = k0; k < k1; ++k) f(order[k]);
  });
}

template <class Keep>
inline std::size_t CellList::gather_neighbours(double xi, double yi, double zi,
                                               std::vector<std::uint32_t>& out,
                                               Keep&& keep) const {
  const std::uint32_t* order = order_.data();
  std::size_t count = 0;
  for_each_candidate_range(xi, yi, zi, [&](std::uint32_t k0, std::uint32_t k1) {
    if (out.size() < count + (k1 - k0)) out.resize(2 * (count + (k1 - k0)) + 64);
    std::uint32_t* o = out.data();
    for (std::uint32_t k = k0; k < k1; ++k) {
      const std::uint32_t j = order[k];
      o[count] = j;
      count += keep(j) ? 1 : 0;
    }
  });
  return count;
}

}  // namespace sphc
