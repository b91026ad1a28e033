#include "sphc/opencl.h"
#include "sphc/kernels.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace sphc {
namespace ocl {

namespace {

// Runtime kernels: cell keys, bitonic sort, cell ranges, reductions. `real` is defined by
// the prefix in Context::init.
const char* kRuntimeSource = R"CLC(
#define SPHC_GRID_ARGS const real grid_lox, const real grid_loy, const real grid_loz, \
    const real grid_inv, const int grid_nx, const int grid_ny, const int grid_nz
#define SPHC_CELLS_ARGS(S) __global const uint* S##_order, __global const uint* S##_start, \
    __global const uint* S##_end

// Cell coordinate along an axis: NaN and values below the grid give 0, beyond it the last
// cell (as sphc::CellList).
inline int sphc_axis_cell(real v, int ncell) {
  const real cmax = (real)(ncell - 1);
  v = v >= (real)0 ? v : (real)0;
  v = v <= cmax ? v : cmax;
  return (int)v;
}

// The cell key of particle i, and its cell's count up by one.
inline void sphc_cell_key_of(const uint i, __global const real* x, __global const real* y,
                             __global const real* z, const int has_y, const int has_z,
                             SPHC_GRID_ARGS, __global uint* keys, __global uint* count) {
  const int cx = sphc_axis_cell((x[i] - grid_lox) * grid_inv, grid_nx);
  const int cy = has_y ? sphc_axis_cell((y[i] - grid_loy) * grid_inv, grid_ny) : 0;
  const int cz = has_z ? sphc_axis_cell((z[i] - grid_loz) * grid_inv, grid_nz) : 0;
  const uint key = (uint)((cz * grid_ny + cy) * grid_nx + cx);
  keys[i] = key;
  atomic_inc(&count[key]);
}
#define SPHC_GRID_VALUES grid_lox, grid_loy, grid_loz, grid_inv, grid_nx, grid_ny, grid_nz

__kernel void sphc_cell_keys(const uint n, __global const real* x, __global const real* y,
                             __global const real* z, const int has_y, const int has_z,
                             SPHC_GRID_ARGS, __global uint* keys, __global uint* count) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  sphc_cell_key_of(i, x, y, z, has_y, has_z, SPHC_GRID_VALUES, keys, count);
}

// Exclusive scan of count[0..cells) into start (and end = start + count), in two kernels:
// G work items sum chunks; then each of G work items adds up the sums of the chunks before its
// own (G^2 / 2 reads in all, G = 256: cheaper than a launch) and writes its chunk.
__kernel void sphc_scan_chunks(__global const uint* count, const uint cells,
                               __global uint* partial) {
  const uint g = get_global_id(0), G = get_global_size(0);
  const uint chunk = (cells + G - 1) / G;
  uint sum = 0;
  for (uint c = g * chunk; c < min(cells, (g + 1) * chunk); ++c) sum += count[c];
  partial[g] = sum;
}
__kernel void sphc_scan_apply(__global uint* count, const uint cells,
                              __global const uint* partial, __global uint* start,
                              __global uint* end) {
  const uint g = get_global_id(0), G = get_global_size(0);
  const uint chunk = (cells + G - 1) / G;
  uint acc = 0;
  for (uint k = 0; k < g; ++k) acc += partial[k];
  for (uint c = g * chunk; c < min(cells, (g + 1) * chunk); ++c) {
    start[c] = acc;
    acc += count[c];
    end[c] = acc;
    count[c] = 0;  // the cursor of sphc_scatter
  }
}
__kernel void sphc_scatter(const uint n, __global const uint* keys, __global const uint* start,
                           __global uint* cursor, __global uint* order) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  const uint key = keys[i];
  order[start[key] + atomic_inc(&cursor[key])] = i;
}
// Cell c's indices in ascending order, its count zeroed (sphc_sort_cells' body).
inline void sphc_sort_cell(const uint c, __global const uint* start, __global const uint* end,
                           __global uint* order, __global uint* count) {
  count[c] = 0;
  const uint b = start[c], e = end[c];
  for (uint k = b + 1; k < e; ++k) {
    const uint v = order[k];
    uint m = k;
    while (m > b && order[m - 1] > v) {
      order[m] = order[m - 1];
      --m;
    }
    order[m] = v;
  }
}
// The scatter's order within a cell depends on timing: sort each cell by index (cells hold a
// few particles), so the order is deterministic and the CPU's (ascending index).
// It also zeroes the cell's count (the scatter's cursor): the counts are all zero again for
// the next build, which then needs no fill.
__kernel void sphc_sort_cells(const uint cells, __global const uint* start,
                              __global const uint* end, __global uint* order,
                              __global uint* count) {
  const uint c = get_global_id(0);
  if (c >= cells) return;
  sphc_sort_cell(c, start, end, order, count);
}

// The cell tables of two sources (a, b) on one grid in three launches (build_tables), the
// same tables as the five launches of sphc_cell_keys .. sphc_sort_cells for each:
// sphc_cell_keys_scan2 (the keys and counts of a's na particles then b's nb, and the scan of
// both count tables by the work group that finishes last), sphc_scatter2, sphc_sort_cells2.
// tables = 1: b is unused.
#define SPHC_SCAN_GROUP_MAX 64
// One chunk [lo, hi) of a table: start/end from acc, and the count zeroed (the scatter's
// cursor). The counts are read volatile: other work groups' atomics wrote them.
inline void sphc_scan_chunk(const uint lo, const uint hi, uint acc,
                            volatile __global uint* count, __global uint* start,
                            __global uint* end) {
  for (uint c = lo; c < hi; ++c) {
    const uint k = count[c];
    start[c] = acc;
    acc += k;
    end[c] = acc;
    count[c] = 0;
  }
}
inline uint sphc_chunk_sum(const uint lo, const uint hi, volatile __global uint* count) {
  uint sum = 0;
  for (uint c = lo; c < hi; ++c) sum += count[c];
  return sum;
}
__kernel void sphc_cell_keys_scan2(const uint na, __global const real* xa,
                                   __global const real* ya, __global const real* za,
                                   const uint nb, __global const real* xb,
                                   __global const real* yb, __global const real* zb,
                                   const int has_y, const int has_z, SPHC_GRID_ARGS,
                                   __global uint* keys_a, __global uint* count_a,
                                   __global uint* keys_b, __global uint* count_b,
                                   const uint cells, const int tables, __global uint* start_a,
                                   __global uint* end_a, __global uint* start_b,
                                   __global uint* end_b, __global uint* done) {
  __local uint sums[2 * SPHC_SCAN_GROUP_MAX];
  __local int last;
  const uint i = get_global_id(0);
  if (i < na)
    sphc_cell_key_of(i, xa, ya, za, has_y, has_z, SPHC_GRID_VALUES, keys_a, count_a);
  else if (i - na < nb)
    sphc_cell_key_of(i - na, xb, yb, zb, has_y, has_z, SPHC_GRID_VALUES, keys_b, count_b);
  // The group's counts are done; the group that counts itself last scans (the others' counts
  // are complete then).
  mem_fence(CLK_GLOBAL_MEM_FENCE);
  barrier(CLK_GLOBAL_MEM_FENCE | CLK_LOCAL_MEM_FENCE);
  if (get_local_id(0) == 0) last = atomic_inc(done) == get_num_groups(0) - 1;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (!last) return;
  mem_fence(CLK_GLOBAL_MEM_FENCE);
  const uint g = get_local_id(0), G = get_local_size(0);
  const uint chunk = (cells + G - 1) / G;
  const uint lo = min(cells, g * chunk), hi = min(cells, lo + chunk);
  sums[g] = sphc_chunk_sum(lo, hi, count_a);
  sums[G + g] = tables > 1 ? sphc_chunk_sum(lo, hi, count_b) : 0u;
  barrier(CLK_LOCAL_MEM_FENCE);
  uint acc_a = 0, acc_b = 0;
  for (uint k = 0; k < g; ++k) {
    acc_a += sums[k];
    acc_b += sums[G + k];
  }
  sphc_scan_chunk(lo, hi, acc_a, count_a, start_a, end_a);
  if (tables > 1) sphc_scan_chunk(lo, hi, acc_b, count_b, start_b, end_b);
  if (g == 0) *done = 0;  // for the next build
}
__kernel void sphc_scatter2(const uint na, __global const uint* keys_a,
                            __global const uint* start_a, __global uint* cursor_a,
                            __global uint* order_a, const uint nb, __global const uint* keys_b,
                            __global const uint* start_b, __global uint* cursor_b,
                            __global uint* order_b) {
  const uint i = get_global_id(0);
  if (i < na) {
    const uint key = keys_a[i];
    order_a[start_a[key] + atomic_inc(&cursor_a[key])] = i;
  } else if (i - na < nb) {
    const uint key = keys_b[i - na];
    order_b[start_b[key] + atomic_inc(&cursor_b[key])] = i - na;
  }
}
__kernel void sphc_sort_cells2(const uint cells, const int tables, __global const uint* start_a,
                               __global const uint* end_a, __global uint* order_a,
                               __global uint* count_a, __global const uint* start_b,
                               __global const uint* end_b, __global uint* order_b,
                               __global uint* count_b) {
  const uint c = get_global_id(0);
  if (c < cells)
    sphc_sort_cell(c, start_a, end_a, order_a, count_a);
  else if (tables > 1 && c - cells < cells)
    sphc_sort_cell(c - cells, start_b, end_b, order_b, count_b);
}

__kernel void sphc_fill_uint(__global uint* v, const uint value, const uint count) {
  const uint i = get_global_id(0);
  if (i < count) v[i] = value;
}

// Particle i of dst = particle order[i] of src (every value of a stride), for 4- and 8-byte
// values (ParticleArray::permute on the device).
__kernel void sphc_gather4(__global uint* dst, __global const uint* src,
                           __global const uint* order, const uint n, const uint stride) {
  const uint i = get_global_id(0);
  if (i >= n * stride) return;
  dst[i] = src[order[i / stride] * stride + i % stride];
}
__kernel void sphc_gather8(__global ulong* dst, __global const ulong* src,
                           __global const uint* order, const uint n, const uint stride) {
  const uint i = get_global_id(0);
  if (i >= n * stride) return;
  dst[i] = src[order[i / stride] * stride + i % stride];
}

// Periodic and mirror domains (sphc/domain.h). sphc_wrap_periodic: sphc::wrap_periodic, with
// contraction off so that it rounds as the host.
__kernel void sphc_wrap_periodic(__global real* x, const uint n, const real lo, const real hi) {
#pragma OPENCL FP_CONTRACT OFF
  const uint i = get_global_id(0);
  if (i >= n) return;
  real v = x[i];
  if (!isfinite(v) || (v >= lo && v < hi)) return;
  const real period = hi - lo;
  v -= floor((v - lo) / period) * period;
  if (v >= hi) v -= period;
  if (v < lo) v = lo;
  x[i] = v;
}
// Ghost k of v (slot n + k) from its source through its image along `axis`: per side a mode
// (sphc::GhostOp: 0: copy, 1: x + t, 2: t - x, 3: -x), as sphc::add_ghosts.
__kernel void sphc_ghost_real(__global real* v, __global const uint* source,
                              __global const uchar* image, const uint n, const uint g,
                              const int axis, const int mode_lo, const real t_lo,
                              const int mode_hi, const real t_hi) {
#pragma OPENCL FP_CONTRACT OFF
  const uint k = get_global_id(0);
  if (k >= g) return;
  const real x = v[source[k]];
  const int code = (image[k] >> (2 * axis)) & 3;
  const int mode = code == 1 ? mode_lo : code == 2 ? mode_hi : 0;
  const real t = code == 1 ? t_lo : t_hi;
  v[n + k] = mode == 1 ? x + t : mode == 2 ? t - x : mode == 3 ? -x : x;
}
// Ghost copies of 4- and 8-byte values (every value of a stride).
__kernel void sphc_ghost_copy4(__global uint* v, __global const uint* source, const uint n,
                               const uint g, const uint stride) {
  const uint i = get_global_id(0);
  if (i >= g * stride) return;
  v[n * stride + i] = v[source[i / stride] * stride + i % stride];
}
__kernel void sphc_ghost_copy8(__global ulong* v, __global const uint* source, const uint n,
                               const uint g, const uint stride) {
  const uint i = get_global_id(0);
  if (i >= g * stride) return;
  v[n * stride + i] = v[source[i / stride] * stride + i % stride];
}

// Partial extents for the search domain, one pass over two arrays (a and b; nb = 0: a only):
// work item g writes min/max of the finite x, y, z (axes beyond dim: +inf/-inf) and the max
// of finite h over a[g], a[g + G], ... and b[g], b[g + G], ...
inline void sphc_extent_of(const uint n, const int dim, __global const real* x,
                           __global const real* y, __global const real* z,
                           __global const real* h, real* lo, real* hi, real* hmax) {
  const uint g = get_global_id(0), G = get_global_size(0);
  for (uint i = g; i < n; i += G) {
    const real v[3] = {x[i], dim > 1 ? y[i] : (real)0, dim > 2 ? z[i] : (real)0};
    for (int a = 0; a < dim; ++a)
      if (isfinite(v[a])) {
        lo[a] = fmin(lo[a], v[a]);
        hi[a] = fmax(hi[a], v[a]);
      }
    if (isfinite(h[i])) *hmax = fmax(*hmax, h[i]);
  }
}
__kernel void sphc_extent(const int dim, const uint na, __global const real* xa,
                          __global const real* ya, __global const real* za,
                          __global const real* ha, const uint nb, __global const real* xb,
                          __global const real* yb, __global const real* zb,
                          __global const real* hb, const uint offset, __global real* partial) {
  const uint g = get_global_id(0);
  real lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  real hmax = -INFINITY;
  sphc_extent_of(na, dim, xa, ya, za, ha, lo, hi, &hmax);
  sphc_extent_of(nb, dim, xb, yb, zb, hb, lo, hi, &hmax);
  partial += offset + 7 * g;
  for (int a = 0; a < 3; ++a) {
    partial[2 * a] = lo[a];
    partial[2 * a + 1] = hi[a];
  }
  partial[6] = hmax;
}

// sphc_extent with the largest squared displacement since the kept cell tables' build
// (KeptTables): 8 values per work item, the 8th the max over the particles of a tracked array
// (track_a, track_b) of |x - x0|^2 (infinity where it is not finite).
inline void sphc_moved_of(const uint n, const int dim, const int track, __global const real* x,
                          __global const real* y, __global const real* z,
                          __global const real* x0, __global const real* y0,
                          __global const real* z0, real* moved) {
  if (!track) return;
  const uint g = get_global_id(0), G = get_global_size(0);
  for (uint i = g; i < n; i += G) {
    const real dx = x[i] - x0[i], dy = dim > 1 ? y[i] - y0[i] : (real)0,
               dz = dim > 2 ? z[i] - z0[i] : (real)0;
    const real d2 = dx * dx + dy * dy + dz * dz;
    *moved = isfinite(d2) ? fmax(*moved, d2) : (real)INFINITY;
  }
}
__kernel void sphc_extent_moved(const int dim, const uint na, __global const real* xa,
                                __global const real* ya, __global const real* za,
                                __global const real* ha, const int track_a,
                                __global const real* x0a, __global const real* y0a,
                                __global const real* z0a, const uint nb,
                                __global const real* xb, __global const real* yb,
                                __global const real* zb, __global const real* hb,
                                const int track_b, __global const real* x0b,
                                __global const real* y0b, __global const real* z0b,
                                const uint offset, __global real* partial) {
  const uint g = get_global_id(0);
  real lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  real hmax = -INFINITY, moved = 0;
  sphc_extent_of(na, dim, xa, ya, za, ha, lo, hi, &hmax);
  sphc_extent_of(nb, dim, xb, yb, zb, hb, lo, hi, &hmax);
  sphc_moved_of(na, dim, track_a, xa, ya, za, x0a, y0a, z0a, &moved);
  sphc_moved_of(nb, dim, track_b, xb, yb, zb, x0b, y0b, z0b, &moved);
  partial += offset + 8 * g;
  for (int a = 0; a < 3; ++a) {
    partial[2 * a] = lo[a];
    partial[2 * a + 1] = hi[a];
  }
  partial[6] = hmax;
  partial[7] = moved;
}

// The search domain's extents computed by a scene kernel that visits the particles anyway
// (sphc --backend=opencl: a stepper run's kernel before a neighbour update), in work groups
// of SPHC_GROUP items (the kernel's reqd_work_group_size; every item of a group calls this,
// past its own particle's work: it holds barriers): item i (valid: i < n) gives its finite
// coordinates and h, the group's minima and maxima go to partial[7 * group + 0..6] (lo, hi
// per axis, max h: the layout of sphc_extent's partial results), the host takes those of all
// groups (Context::grid_of_extents). Minima and maxima are exact, so the grid is the one of
// sphc_extent, bit for bit.
#define SPHC_GROUP 64
inline void sphc_extent_group(const int valid, const int dim, const int i,
                              __global const real* x, __global const real* y,
                              __global const real* z, __global const real* h,
                              __local real* s, __global real* partial) {
  const int l = get_local_id(0);
  real v[7] = {INFINITY, -INFINITY, INFINITY, -INFINITY, INFINITY, -INFINITY, -INFINITY};
  if (valid) {
    const real c[3] = {x[i], dim > 1 ? y[i] : (real)0, dim > 2 ? z[i] : (real)0};
    for (int a = 0; a < dim; ++a)
      if (isfinite(c[a])) {
        v[2 * a] = c[a];
        v[2 * a + 1] = c[a];
      }
    if (isfinite(h[i])) v[6] = h[i];
  }
  for (int k = 0; k < 7; ++k) s[k * SPHC_GROUP + l] = v[k];
  barrier(CLK_LOCAL_MEM_FENCE);
  for (int w = SPHC_GROUP / 2; w > 0; w >>= 1) {
    if (l < w)
      for (int k = 0; k < 7; ++k) {
        const real a = s[k * SPHC_GROUP + l], b = s[k * SPHC_GROUP + l + w];
        s[k * SPHC_GROUP + l] = k == 0 || k == 2 || k == 4 ? fmin(a, b) : fmax(a, b);
      }
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (l == 0)
    for (int k = 0; k < 7; ++k) partial[7 * get_group_id(0) + k] = s[k * SPHC_GROUP];
}

// A min (op 0) or max (op 1) of v over a work group of SPHC_GROUP items (every item of the
// group calls it; s: SPHC_GROUP reals of local memory, free again when it returns), into
// partial[group] (Context::reduce_groups combines the groups').
inline void sphc_group_reduce(__local real* s, const real v, const int op,
                              __global real* partial) {
  const int l = get_local_id(0);
  barrier(CLK_LOCAL_MEM_FENCE);  // s may still be read by an earlier call
  s[l] = v;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (int w = SPHC_GROUP / 2; w > 0; w >>= 1) {
    if (l < w) s[l] = op ? fmax(s[l], s[l + w]) : fmin(s[l], s[l + w]);
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (l == 0) partial[get_group_id(0)] = s[0];
}

// Partial reductions: work item g combines v[g], v[g + G], ... (G work items).
__kernel void sphc_reduce(__global const real* v, const uint n, const int op,
                          const int finite_only, const uint offset, __global real* partial) {
  const uint g = get_global_id(0), G = get_global_size(0);
  real acc = op == 0 ? (real)0 : op == 1 ? (real)INFINITY : (real)(-INFINITY);
  for (uint i = g; i < n; i += G) {
    const real x = v[i];
    if (finite_only && !isfinite(x)) continue;
    acc = op == 0 ? acc + x : op == 1 ? fmin(acc, x) : fmax(acc, x);
  }
  partial[offset + g] = acc;
}
)CLC";

constexpr std::size_t kReduceItems = 256;

// A string property of a platform or device (get: clGetPlatformInfo or clGetDeviceInfo).
template <class Get, class Obj, class Info>
std::string info_string(Get get, Obj obj, Info what) {
  std::size_t size = 0;
  get(obj, what, 0, nullptr, &size);
  std::string s(size, '\0');
  get(obj, what, size, s.data(), nullptr);
  while (!s.empty() && s.back() == '\0') s.pop_back();
  return s;
}

bool has_fp64(cl_device_id d) {
  cl_device_fp_config cfg = 0;
  clGetDeviceInfo(d, CL_DEVICE_DOUBLE_FP_CONFIG, sizeof cfg, &cfg, nullptr);
  return cfg != 0;
}

struct Found {
  int platform, device;
  cl_platform_id pid;
  cl_device_id did;
  std::string platform_name, device_name;
  bool fp64;
};

std::vector<Found> find_devices() {
  std::vector<Found> all;
  cl_uint np = 0;
  if (clGetPlatformIDs(0, nullptr, &np) != CL_SUCCESS || np == 0) return all;
  std::vector<cl_platform_id> ps(np);
  clGetPlatformIDs(np, ps.data(), nullptr);
  for (cl_uint p = 0; p < np; ++p) {
    cl_uint nd = 0;
    if (clGetDeviceIDs(ps[p], CL_DEVICE_TYPE_ALL, 0, nullptr, &nd) != CL_SUCCESS) continue;
    std::vector<cl_device_id> ds(nd);
    clGetDeviceIDs(ps[p], CL_DEVICE_TYPE_ALL, nd, ds.data(), nullptr);
    for (cl_uint d = 0; d < nd; ++d)
      all.push_back({static_cast<int>(p), static_cast<int>(d), ps[p], ds[d],
                     info_string(clGetPlatformInfo, ps[p], CL_PLATFORM_NAME),
                     info_string(clGetDeviceInfo, ds[d], CL_DEVICE_NAME), has_fp64(ds[d])});
  }
  return all;
}

std::string describe(const std::vector<Found>& all) {
  if (all.empty())
    return "  (no OpenCL platform found: is an ICD installed, e.g. pocl-opencl-icd, and "
           "listed in /etc/OpenCL/vendors?)\n";
  std::string s;
  for (const auto& f : all)
    s += "  --platform " + std::to_string(f.platform) + " --device " + std::to_string(f.device) +
         ": " + f.device_name + " (" + f.platform_name + "; fp64: " + (f.fp64 ? "yes" : "no") +
         ")\n";
  return s;
}

int env_int(const char* name) {
  const char* v = std::getenv(name);
  return v && *v ? std::atoi(v) : -1;
}

// The search domain's extents from the partial results of sphc_extent (stride 7) or
// sphc_extent_moved (stride 8: the 8th the squared displacement, its largest in *moved2, a
// NaN read as infinite): lo, hi over the first dim axes and the largest h.
void combine_extents(const std::vector<double>& values, std::size_t stride, int dim,
                     double lo[3], double hi[3], double& hmax, double* moved2 = nullptr) {
  for (int a = 0; a < 3; ++a) {
    lo[a] = HUGE_VAL;
    hi[a] = -HUGE_VAL;
  }
  hmax = -HUGE_VAL;
  if (moved2) *moved2 = 0.0;
  for (std::size_t j = 0; j < values.size(); j += stride) {
    for (int a = 0; a < dim; ++a) {
      lo[a] = std::fmin(lo[a], values[j + 2 * a]);
      hi[a] = std::fmax(hi[a], values[j + 2 * a + 1]);
    }
    hmax = std::fmax(hmax, values[j + 6]);
    if (moved2) *moved2 = std::isnan(values[j + 7]) ? HUGE_VAL : std::fmax(*moved2, values[j + 7]);
  }
}

}  // namespace

const char* error_name(cl_int err) {
  switch (err) {
#define SPHC_CL_ERR(e) \
  case e:              \
    return #e;
    SPHC_CL_ERR(CL_SUCCESS)
    SPHC_CL_ERR(CL_DEVICE_NOT_FOUND)
    SPHC_CL_ERR(CL_DEVICE_NOT_AVAILABLE)
    SPHC_CL_ERR(CL_COMPILER_NOT_AVAILABLE)
    SPHC_CL_ERR(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    SPHC_CL_ERR(CL_OUT_OF_RESOURCES)
    SPHC_CL_ERR(CL_OUT_OF_HOST_MEMORY)
    SPHC_CL_ERR(CL_BUILD_PROGRAM_FAILURE)
    SPHC_CL_ERR(CL_INVALID_VALUE)
    SPHC_CL_ERR(CL_INVALID_PLATFORM)
    SPHC_CL_ERR(CL_INVALID_DEVICE)
    SPHC_CL_ERR(CL_INVALID_CONTEXT)
    SPHC_CL_ERR(CL_INVALID_COMMAND_QUEUE)
    SPHC_CL_ERR(CL_INVALID_MEM_OBJECT)
    SPHC_CL_ERR(CL_INVALID_PROGRAM)
    SPHC_CL_ERR(CL_INVALID_PROGRAM_EXECUTABLE)
    SPHC_CL_ERR(CL_INVALID_KERNEL_NAME)
    SPHC_CL_ERR(CL_INVALID_KERNEL)
    SPHC_CL_ERR(CL_INVALID_ARG_INDEX)
    SPHC_CL_ERR(CL_INVALID_ARG_VALUE)
    SPHC_CL_ERR(CL_INVALID_ARG_SIZE)
    SPHC_CL_ERR(CL_INVALID_KERNEL_ARGS)
    SPHC_CL_ERR(CL_INVALID_WORK_GROUP_SIZE)
    SPHC_CL_ERR(CL_INVALID_WORK_ITEM_SIZE)
    SPHC_CL_ERR(CL_INVALID_GLOBAL_WORK_SIZE)
    SPHC_CL_ERR(CL_INVALID_BUFFER_SIZE)
    SPHC_CL_ERR(CL_INVALID_BUILD_OPTIONS)
#undef SPHC_CL_ERR
  }
  return "unknown OpenCL error";
}

void check(cl_int err, const char* what) {
  if (err != CL_SUCCESS)
    throw std::runtime_error(std::string("OpenCL: ") + what + " failed: " + error_name(err) + " (" +
                             std::to_string(err) + ")");
}

Selection take_options(int& argc, char** argv) {
  Selection sel{env_int("SPHC_OPENCL_PLATFORM"), env_int("SPHC_OPENCL_DEVICE")};
  int out = 1;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto number = [&](int& into) {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "error: %s needs a number\n", a.c_str());
        std::exit(2);
      }
      char* end = nullptr;
      long v = std::strtol(argv[++i], &end, 10);
      if (*end || v < 0) {
        std::fprintf(stderr, "error: %s takes a non-negative integer, not '%s'\n", a.c_str(),
                     argv[i]);
        std::exit(2);
      }
      into = static_cast<int>(v);
    };
    if (a == "--platform") {
      number(sel.platform);
    } else if (a == "--device") {
      number(sel.device);
    } else if (a == "--list-devices") {
      std::printf("OpenCL devices:\n%s", describe(find_devices()).c_str());
      std::exit(0);
    } else {
      if (a == "--help" || a == "-h")
        std::printf(
            "OpenCL options (this solver was built with --backend=opencl):\n"
            "  --platform N      use OpenCL platform N (default: the first with a device that "
            "fits)\n"
            "  --device N        use device N of the platform\n"
            "  --list-devices    list the platforms and devices found, and exit\n"
            "  (SPHC_OPENCL_PLATFORM, SPHC_OPENCL_DEVICE: defaults; SPHC_OPENCL_PROFILE=1: time "
            "per kernel)\n\n");
      argv[out++] = argv[i];
    }
  }
  argc = out;
  argv[argc] = nullptr;
  return sel;
}

void Context::init(const Selection& sel, bool double_precision, const std::string& scene_source,
                   const std::string& scene_name) {
  dp_ = double_precision;
  const char* prof = std::getenv("SPHC_OPENCL_PROFILE");
  profile_ = prof && *prof && std::string(prof) != "0";
  auto all = find_devices();
  const Found* pick = nullptr;
  std::string why;
  for (const auto& f : all) {
    if (sel.platform >= 0 && f.platform != sel.platform) continue;
    if (sel.device >= 0 && f.device != sel.device) continue;
    if (dp_ && !f.fp64) {
      why = "device '" + f.device_name + "' (--platform " + std::to_string(f.platform) +
            " --device " + std::to_string(f.device) +
            ") does not support double precision (no fp64); rebuild the scene with sphc "
            "--precision=single or choose another device. ";
      continue;
    }
    pick = &f;
    break;
  }
  if (!pick)
    throw std::runtime_error(
        "OpenCL: no device fits (" + std::string(dp_ ? "double" : "single") + " precision" +
        (sel.platform >= 0 ? ", --platform " + std::to_string(sel.platform) : std::string()) +
        (sel.device >= 0 ? ", --device " + std::to_string(sel.device) : std::string()) + "). " +
        why + "Found:\n" + describe(all));
  device_name_ = pick->device_name;
  cl_int err = CL_SUCCESS;
  cl_context_properties props[] = {CL_CONTEXT_PLATFORM,
                                   reinterpret_cast<cl_context_properties>(pick->pid), 0};
  context_ = clCreateContext(props, 1, &pick->did, nullptr, nullptr, &err);
  check(err, "clCreateContext");
  device_ = pick->did;
  queue_ = clCreateCommandQueue(context_, pick->did, 0, &err);
  check(err, "clCreateCommandQueue");

  // No FMA contraction on the device either (the host solvers are built with
  // -ffp-contract=off): + - * / and sqrt then round as on the host, so a pair at exactly the
  // cut-off is decided alike on both (docs/performance-log.md, "Rounding").
  std::string source = std::string("#pragma OPENCL FP_CONTRACT OFF\n") +
                       std::string(dp_ ? "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n"
                                         "typedef double real;\n"
                                       // Single: the bodies' `double` locals are float too.
                                       : "typedef float real;\n#define double float\n") +
                       "#line 1 \"sphc-runtime.cl\"\n" + kRuntimeSource + scene_source;
  const char* src = source.c_str();
  program_ = clCreateProgramWithSource(context_, 1, &src, nullptr, &err);
  check(err, "clCreateProgramWithSource");
  // Single precision: literals are float.
  const char* options = dp_ ? "" : "-cl-single-precision-constant";
  err = clBuildProgram(program_, 1, &pick->did, options, nullptr, nullptr);
  if (err != CL_SUCCESS) {
    std::size_t size = 0;
    clGetProgramBuildInfo(program_, pick->did, CL_PROGRAM_BUILD_LOG, 0, nullptr, &size);
    std::string log(size, '\0');
    clGetProgramBuildInfo(program_, pick->did, CL_PROGRAM_BUILD_LOG, size, log.data(), nullptr);
    while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
    if (log.size() > 6000) log = log.substr(0, 6000) + "\n... (log truncated)";
    throw std::runtime_error("OpenCL: the kernels of scene '" + scene_name +
                             "' did not build for device '" + device_name_ + "' (" +
                             error_name(err) + "); lines of the .sph bodies are named as " +
                             "file.sph:line, other lines are generated code:\n" + log);
  }
}

Context::~Context() {
  for (const auto& [name, t] : profile_times_)
    std::fprintf(stderr, "opencl profile: %-40s %8ld launches %10.4f s\n", name.c_str(), t.second,
                 t.first);
  for (auto& [n, k] : kernels_) clReleaseKernel(k);
  for (auto& [s, b] : scratch_) clReleaseMemObject(b.first);
  if (program_) clReleaseProgram(program_);
  if (queue_) clReleaseCommandQueue(queue_);
  if (context_) clReleaseContext(context_);
}

cl_mem Context::alloc(std::size_t bytes) {
  cl_int err = CL_SUCCESS;
  cl_mem m = clCreateBuffer(context_, CL_MEM_READ_WRITE, bytes ? bytes : 16, nullptr, &err);
  check(err, "clCreateBuffer");
  return m;
}

cl_mem Context::scratch(std::size_t n, int slot) {
  auto& s = scratch_[slot];
  if (s.second < n || !s.first) {
    if (s.first) clReleaseMemObject(s.first);
    s.first = alloc(n * real_size());
    s.second = n;
  }
  return s.first;
}

cl_kernel Context::kernel(const std::string& name) {
  auto it = kernels_.find(name);
  if (it != kernels_.end()) return it->second;
  cl_int err = CL_SUCCESS;
  cl_kernel k = clCreateKernel(program_, name.c_str(), &err);
  check(err, ("clCreateKernel(" + name + ")").c_str());
  return kernels_[name] = k;
}

void Context::set_arg(cl_kernel k, cl_uint& i, cl_mem m) {
  check(clSetKernelArg(k, i++, sizeof(cl_mem), &m), "clSetKernelArg (buffer)");
}
void Context::set_arg(cl_kernel k, cl_uint& i, int v) {
  cl_int x = v;
  check(clSetKernelArg(k, i++, sizeof x, &x), "clSetKernelArg (int)");
}
void Context::set_arg(cl_kernel k, cl_uint& i, unsigned v) {
  cl_uint x = v;
  check(clSetKernelArg(k, i++, sizeof x, &x), "clSetKernelArg (uint)");
}
void Context::set_arg(cl_kernel k, cl_uint& i, double v) {
  if (dp_) {
    check(clSetKernelArg(k, i++, sizeof v, &v), "clSetKernelArg (real)");
  } else {
    float f = static_cast<float>(v);
    check(clSetKernelArg(k, i++, sizeof f, &f), "clSetKernelArg (real)");
  }
}
void Context::set_arg(cl_kernel k, cl_uint& i, const Grid& g) {
  for (double lo : g.lo) set_arg(k, i, lo);
  set_arg(k, i, g.inv_cell);
  for (int c : g.ncell) set_arg(k, i, c);
}
void Context::set_arg(cl_kernel k, cl_uint& i, const CellTable& c) {
  set_arg(k, i, c.order);
  set_arg(k, i, c.start);
  set_arg(k, i, c.end);
}

void Context::launch(cl_kernel k, std::size_t n, const std::string& name) {
  const std::size_t local = 64;
  enqueue(k, (n + local - 1) / local * local, nullptr, name);
}

void Context::enqueue(cl_kernel k, std::size_t global, const std::size_t* local,
                      const std::string& name) {
  ++launches_;
  const auto start =
      profile_ ? std::chrono::steady_clock::now() : std::chrono::steady_clock::time_point{};
  check(clEnqueueNDRangeKernel(queue_, k, 1, nullptr, &global, local, 0, nullptr, nullptr),
        name.empty() ? "clEnqueueNDRangeKernel" : ("clEnqueueNDRangeKernel(" + name + ")").c_str());
  if (profile_) {
    finish();
    auto& slot = profile_times_[name];
    slot.first += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ++slot.second;
  }
}

void Context::launch_local(cl_kernel k, std::size_t n, std::size_t local,
                           const std::string& name) {
  std::size_t most = 0;
  check(clGetKernelWorkGroupInfo(k, device_, CL_KERNEL_WORK_GROUP_SIZE, sizeof most, &most,
                                 nullptr),
        "clGetKernelWorkGroupInfo");
  local = std::max<std::size_t>(1, std::min(local, most));
  enqueue(k, (n + local - 1) / local * local, &local, name);
}

void Context::finish() { check(clFinish(queue_), "clFinish"); }

void Context::add_profile(const std::string& name, double seconds) {
  auto& slot = profile_times_[name];
  slot.first += seconds;
  ++slot.second;
}

std::vector<double> Context::reduce_all(const std::vector<Reduction>& rs) {
  // Every partial reduction first, then one read of all partial results.
  cl_mem partial = scratch(kReduceItems * (rs.empty() ? 1 : rs.size()), -1);
  cl_kernel k = kernel("sphc_reduce");
  for (std::size_t r = 0; r < rs.size(); ++r) {
    cl_uint i = 0;
    set_arg(k, i, rs[r].v);
    set_arg(k, i, static_cast<unsigned>(rs[r].n));
    set_arg(k, i, static_cast<int>(rs[r].op));
    set_arg(k, i, rs[r].finite_only ? 1 : 0);
    set_arg(k, i, static_cast<unsigned>(r * kReduceItems));
    set_arg(k, i, partial);
    launch(k, kReduceItems, "sphc_reduce");
  }
  host_partial_.resize(kReduceItems * rs.size());
  read_reals(partial, host_partial_.data(), host_partial_.size());
  std::vector<double> out;
  for (std::size_t r = 0; r < rs.size(); ++r) {
    const Op op = rs[r].op;
    double acc = op == Op::Sum ? 0.0 : op == Op::Min ? HUGE_VAL : -HUGE_VAL;
    for (std::size_t j = 0; j < kReduceItems; ++j) {
      const double x = host_partial_[r * kReduceItems + j];
      acc = op == Op::Sum ? acc + x : op == Op::Min ? std::fmin(acc, x) : std::fmax(acc, x);
    }
    out.push_back(acc);
  }
  return out;
}

std::vector<double> Context::minima(cl_mem partial, int columns) {
  const std::size_t c = static_cast<std::size_t>(columns);
  host_partial_.resize(kPartials * c);
  read_reals(partial, host_partial_.data(), host_partial_.size());
  std::vector<double> out(c, HUGE_VAL);
  for (std::size_t g = 0; g < kPartials; ++g)
    for (std::size_t k = 0; k < c; ++k) out[k] = std::fmin(out[k], host_partial_[g * c + k]);
  return out;
}

std::vector<double> Context::minima_rows(cl_mem partial, std::size_t rows, int columns) {
  const std::size_t c = static_cast<std::size_t>(columns);
  host_partial_.resize(rows * c);
  if (rows) read_reals(partial, host_partial_.data(), host_partial_.size());
  std::vector<double> out(c, HUGE_VAL);
  for (std::size_t k = 0; k < c; ++k)
    for (std::size_t g = 0; g < rows; ++g) out[k] = std::fmin(out[k], host_partial_[k * rows + g]);
  return out;
}

double Context::reduce(cl_mem v, std::size_t n, Op op, bool finite_only) {
  return reduce_all({{v, n, op, finite_only}})[0];
}

void Context::read_reals(cl_mem m, double* out, std::size_t n) {
  if (dp_) {
    check(clEnqueueReadBuffer(queue_, m, CL_TRUE, 0, n * sizeof(double), out, 0, nullptr, nullptr),
          "clEnqueueReadBuffer (reals)");
    return;
  }
  std::vector<float> f(n);
  check(
      clEnqueueReadBuffer(queue_, m, CL_TRUE, 0, n * sizeof(float), f.data(), 0, nullptr, nullptr),
      "clEnqueueReadBuffer (reals)");
  for (std::size_t j = 0; j < n; ++j) out[j] = f[j];
}

SearchDomain Context::search_domain(const std::vector<Extent>& arrays, int dim,
                                    double radius_scale) {
  // One partial-extent kernel per two arrays, one read of all partial results.
  const std::size_t per = 7 * kReduceItems;
  const std::size_t launches = (arrays.size() + 1) / 2;
  cl_mem partial = scratch(per * (launches ? launches : 1), -2);
  for (std::size_t k = 0; k < launches; ++k) {
    cl_kernel kern = kernel("sphc_extent");
    cl_uint i = 0;
    set_arg(kern, i, dim);
    for (std::size_t j = 2 * k; j < 2 * k + 2; ++j) {
      const Extent& e = arrays[j < arrays.size() ? j : 2 * k];  // none: n = 0
      set_arg(kern, i, static_cast<unsigned>(j < arrays.size() ? e.n : 0));
      set_arg(kern, i, e.x);
      set_arg(kern, i, e.y ? e.y : e.x);
      set_arg(kern, i, e.z ? e.z : e.x);
      set_arg(kern, i, e.h);
    }
    set_arg(kern, i, static_cast<unsigned>(k * per));
    set_arg(kern, i, partial);
    launch(kern, kReduceItems, "sphc_extent");
  }
  std::vector<double> values(per * launches);
  read_reals(partial, values.data(), values.size());
  double lo[3], hi[3], hmax;
  combine_extents(values, 7, dim, lo, hi, hmax);
  // As sphc::make_search_domain, so that in double precision the grid, hence the cell order
  // and the particle order after a reorder, is the CPU one.
  return search_domain_of_box(lo, hi, hmax, dim, radius_scale);
}

void Context::launch_group(cl_kernel k, std::size_t n, const std::string& name) {
  std::size_t local = kGroup;
  enqueue(k, groups(n) * kGroup, &local, name);
}

double Context::reduce_groups(cl_mem partial, std::size_t rows, Op op) {
  host_partial_.resize(rows);
  if (rows) read_reals(partial, host_partial_.data(), rows);
  double acc = op == Op::Min ? HUGE_VAL : -HUGE_VAL;
  for (std::size_t j = 0; j < rows; ++j)
    acc = op == Op::Min ? std::fmin(acc, host_partial_[j]) : std::fmax(acc, host_partial_[j]);
  return acc;
}

Grid Context::grid_of_extents(cl_mem partial, std::size_t rows, int dim, double radius_scale) {
  std::vector<double> values(7 * rows);
  read_reals(partial, values.data(), values.size());
  double lo[3], hi[3], hmax;
  combine_extents(values, 7, dim, lo, hi, hmax);
  return grid_of(search_domain_of_box(lo, hi, hmax, dim, radius_scale));
}

Grid Context::grid_of(const SearchDomain& dom) const {
  // The grid of CellList::build (dense).
  Grid g;
  double extent[3] = {0.0, 0.0, 0.0}, max_extent = 0.0;
  for (int a = 0; a < dom.dim && a < 3; ++a) {
    const double e = dom.hi[a] - dom.lo[a];
    extent[a] = std::isfinite(e) && e > 0.0 ? e : 0.0;
    max_extent = std::fmax(max_extent, extent[a]);
  }
  double cell = dom.cell_size;
  if (!(cell > 0.0) || !std::isfinite(cell)) cell = max_extent > 0.0 ? max_extent : 1.0;
  const double kMaxCellsPerAxis = 1 << 21;
  cell = std::fmax(cell, max_extent / (kMaxCellsPerAxis - 1));
  // In single precision cell coordinates are rounded: slightly larger cells keep every
  // neighbour within one cell (the candidates stay a superset of the neighbours).
  if (!dp_) cell *= 1.0 + 1e-5;
  g.inv_cell = 1.0 / cell;
  std::size_t cells = 1;
  for (int a = 0; a < 3; ++a) {
    const bool used = a < dom.dim && std::isfinite(dom.lo[a]);
    g.lo[a] = used ? dom.lo[a] : 0.0;
    g.ncell[a] = used ? static_cast<int>(std::fmin(std::floor(extent[a] * g.inv_cell) + 1.0,
                                                      kMaxCellsPerAxis))
                      : 1;
    cells *= static_cast<std::size_t>(g.ncell[a]);
  }
  if (cells > (std::size_t{1} << 28))
    throw std::runtime_error(
        "OpenCL: the search domain needs " + std::to_string(cells) +
        " cells; the OpenCL backend uses a dense grid only (sparse domains: use --backend=openmp)");
  return g;
}

void CellTable::reserve(Context& ctx, const Grid& grid, std::size_t n) {
  if (n > padded || !keys) {
    if (keys) clReleaseMemObject(keys);
    if (order) clReleaseMemObject(order);
    keys = ctx.alloc(n * sizeof(cl_uint));
    order = ctx.alloc(n * sizeof(cl_uint));
    padded = n;
  }
  if (grid.cells() > cells || !start) {
    for (cl_mem m : {start, end, count})
      if (m) clReleaseMemObject(m);
    cells = grid.cells();
    start = ctx.alloc(cells * sizeof(cl_uint));
    end = ctx.alloc(cells * sizeof(cl_uint));
    count = ctx.alloc(cells * sizeof(cl_uint));
    const unsigned all = static_cast<unsigned>(cells);
    ctx.run("sphc_fill_uint", all, count, 0u, all);
  }
}

void CellTable::build(Context& ctx, const Grid& grid, cl_mem x, cl_mem y, cl_mem z, std::size_t n) {
  // A counting sort by cell: keys and counts, a scan into start/end, a scatter, and a sort of
  // each cell's few indices (deterministic order). Five launches, O(n + cells) work. The
  // counts are zero between builds (sphc_sort_cells zeroes them): filled once, when
  // allocated.
  reserve(ctx, grid, n);
  if (!partial) partial = ctx.alloc(kScanItems * sizeof(cl_uint));
  const unsigned nc = static_cast<unsigned>(grid.cells());
  const unsigned un = static_cast<unsigned>(n);
  ctx.run("sphc_cell_keys", n, un, x, y ? y : x, z ? z : x, y ? 1 : 0, z ? 1 : 0, grid, keys,
          count);
  ctx.run("sphc_scan_chunks", kScanItems, count, nc, partial);
  ctx.run("sphc_scan_apply", kScanItems, count, nc, partial, start, end);
  ctx.run("sphc_scatter", n, un, keys, start, count, order);
  ctx.run("sphc_sort_cells", nc, nc, start, end, order, count);
}

void build_tables(Context& ctx, const Grid& grid, const std::vector<TableBuild>& tables) {
  // Two tables per launch (a lone last one with an empty second), three launches per pair:
  // cell keys with the scan by the last work group, the scatter, the per-cell sorts. The
  // tables are those of CellTable::build (the same counting sort, the same per-cell order).
  const unsigned nc = static_cast<unsigned>(grid.cells());
  for (const TableBuild& b : tables) b.table->reserve(ctx, grid, b.n);
  for (std::size_t k = 0; k < tables.size(); k += 2) {
    const TableBuild& a = tables[k];
    const bool pair = k + 1 < tables.size();
    const TableBuild& b = tables[pair ? k + 1 : k];
    const unsigned na = static_cast<unsigned>(a.n), nb = pair ? static_cast<unsigned>(b.n) : 0u;
    CellTable &ta = *a.table, &tb = *b.table;
    if (!ta.done) {
      ta.done = ctx.alloc(sizeof(cl_uint));
      ctx.run("sphc_fill_uint", 1, ta.done, 0u, 1u);
    }
    cl_kernel keys = ctx.kernel("sphc_cell_keys_scan2");
    cl_uint i = 0;
    ctx.set_arg(keys, i, na);
    for (cl_mem m : {a.x, a.y ? a.y : a.x, a.z ? a.z : a.x}) ctx.set_arg(keys, i, m);
    ctx.set_arg(keys, i, nb);
    for (cl_mem m : {b.x, b.y ? b.y : b.x, b.z ? b.z : b.x}) ctx.set_arg(keys, i, m);
    ctx.set_arg(keys, i, a.y ? 1 : 0);
    ctx.set_arg(keys, i, a.z ? 1 : 0);
    ctx.set_arg(keys, i, grid);
    for (cl_mem m : {ta.keys, ta.count, tb.keys, tb.count}) ctx.set_arg(keys, i, m);
    ctx.set_arg(keys, i, nc);
    ctx.set_arg(keys, i, pair ? 2 : 1);
    for (cl_mem m : {ta.start, ta.end, tb.start, tb.end, ta.done}) ctx.set_arg(keys, i, m);
    // At least one work group, which then scans.
    ctx.launch_local(keys, std::max<std::size_t>(1, std::size_t{na} + nb), kScanGroup,
                     "sphc_cell_keys_scan2");
    ctx.run("sphc_scatter2", std::size_t{na} + nb, na, ta.keys, ta.start, ta.count, ta.order, nb,
            tb.keys, tb.start, tb.count, tb.order);
    ctx.run("sphc_sort_cells2", std::size_t{nc} * (pair ? 2 : 1), nc, pair ? 2 : 1, ta.start,
            ta.end, ta.order, ta.count, tb.start, tb.end, tb.order, tb.count);
  }
}

void CellTable::release() {
  for (cl_mem* m : {&keys, &order, &start, &end, &count, &partial, &done})
    if (*m) {
      clReleaseMemObject(*m);
      *m = nullptr;
    }
}

namespace {
// Bytes per value of a property on the device.
std::size_t value_size(const Context& ctx, const Property& p) {
  return p.type == PropType::F64 ? ctx.real_size() : 4;
}

// The host side of a transfer of count values of p: p's own storage, or tmp (floats) for
// doubles on a single-precision device (staged: the caller converts into or out of tmp).
struct HostSide {
  void* data;
  std::size_t bytes;
  bool staged;
};

HostSide host_side(Context& ctx, Property& p, std::size_t count, std::vector<float>& tmp) {
  if (p.type != PropType::F64)
    return {p.type == PropType::I32 ? static_cast<void*>(p.i32.data()) : p.u32.data(),
            count * 4, false};
  if (ctx.double_precision()) return {p.f64.data(), count * sizeof(double), false};
  tmp.resize(count);
  return {tmp.data(), count * sizeof(float), true};
}

// Writes the values of the first n particles of p into buf, doubles as floats on a
// single-precision device (through tmp).
void write_property(Context& ctx, cl_mem buf, const Property& p, std::size_t n,
                    std::vector<float>& tmp) {
  const std::size_t count = n * static_cast<std::size_t>(p.stride);
  if (count == 0) return;
  // host_side only locates the values: nothing is written through it here.
  const HostSide h = host_side(ctx, const_cast<Property&>(p), count, tmp);
  if (h.staged) std::copy(p.f64.begin(), p.f64.begin() + count, tmp.begin());
  check(clEnqueueWriteBuffer(ctx.queue(), buf, CL_TRUE, 0, h.bytes, h.data, 0, nullptr, nullptr),
        "clEnqueueWriteBuffer (property)");
}
}  // namespace

void DeviceArray::upload(Context& ctx, const ParticleArray& a) {
  const bool realloc = props.size() != a.props.size() || a.n > capacity || props.empty();
  if (realloc) {
    // Arrays that grow between steps (inlets): room for a quarter more, as reserve() gives,
    // so that a growing array reallocates rarely.
    const std::size_t grown = props.size() == a.props.size() && !props.empty()
                                  ? std::max(a.n, capacity + capacity / 4)
                                  : a.n;
    release();
    capacity = grown;
  }
  n = a.n;
  std::vector<float> tmp;
  for (std::size_t i = 0; i < a.props.size(); ++i) {
    const Property& p = a.props[i];
    if (realloc) props.push_back(ctx.alloc(capacity * p.stride * value_size(ctx, p)));
    write_property(ctx, props[i], p, n, tmp);
  }
  if (constants.size() != a.constants.size()) {
    for (cl_mem m : constants) clReleaseMemObject(m);
    constants.clear();
    for (const auto& c : a.constants) constants.push_back(ctx.alloc(c.values.size() * 8));
  }
  for (std::size_t c = 0; c < a.constants.size(); ++c) upload_constant(ctx, a, static_cast<int>(c));
}

void DeviceArray::upload_constant(Context& ctx, const ParticleArray& a, int c) {
  const auto& v = a.constants[c].values;
  if (v.empty()) return;
  std::vector<float> f(v.begin(), v.end());
  const void* data = ctx.double_precision() ? static_cast<const void*>(v.data()) : f.data();
  check(clEnqueueWriteBuffer(ctx.queue(), constants[c], CL_TRUE, 0, v.size() * ctx.real_size(),
                             data, 0, nullptr, nullptr),
        "clEnqueueWriteBuffer (constant)");
}

void DeviceArray::download(Context& ctx, ParticleArray& a) {
  std::vector<int> all;
  for (std::size_t i = 0; i < a.props.size() && i < props.size(); ++i)
    all.push_back(static_cast<int>(i));
  download(ctx, a, all);
}

void DeviceArray::upload(Context& ctx, const ParticleArray& a, const std::vector<int>& which) {
  std::vector<float> tmp;
  for (int i : which) write_property(ctx, props[i], a.props[i], n, tmp);
}

void DeviceArray::download(Context& ctx, ParticleArray& a, const std::vector<int>& which) {
  std::vector<float> tmp;
  for (int i : which) {
    Property& p = a.props[i];
    const std::size_t count = n * static_cast<std::size_t>(p.stride);
    if (count == 0) continue;
    const HostSide h = host_side(ctx, p, count, tmp);
    check(clEnqueueReadBuffer(ctx.queue(), props[i], CL_TRUE, 0, h.bytes, h.data, 0, nullptr,
                              nullptr),
          "clEnqueueReadBuffer (property)");
    if (h.staged) std::copy(tmp.begin(), tmp.begin() + count, p.f64.begin());
  }
}

void DeviceArray::reserve(Context& ctx, const ParticleArray& a, std::size_t count) {
  if (count <= capacity) return;
  const std::size_t cap = std::max(count, capacity + capacity / 4 + 64);
  for (std::size_t i = 0; i < a.props.size() && i < props.size(); ++i) {
    const Property& p = a.props[i];
    const std::size_t per = p.stride * value_size(ctx, p);
    cl_mem m = ctx.alloc(cap * per);
    if (capacity * per > 0)
      check(clEnqueueCopyBuffer(ctx.queue(), props[i], m, 0, 0, capacity * per, 0, nullptr,
                                nullptr),
            "clEnqueueCopyBuffer (property)");
    clReleaseMemObject(props[i]);
    props[i] = m;
  }
  capacity = cap;
}

void DeviceArray::permute(Context& ctx, const CellTable& cells, const ParticleArray& a) {
  for (std::size_t i = 0; i < a.props.size() && i < props.size(); ++i) {
    const Property& p = a.props[i];
    const bool wide = p.type == PropType::F64 && ctx.double_precision();
    const std::size_t count = n * static_cast<std::size_t>(p.stride);
    if (count == 0) continue;
    cl_mem dst = ctx.alloc(capacity * static_cast<std::size_t>(p.stride) * (wide ? 8 : 4));
    ctx.run(wide ? "sphc_gather8" : "sphc_gather4", count, dst, props[i], cells.order,
            static_cast<unsigned>(n), static_cast<unsigned>(p.stride));
    clReleaseMemObject(props[i]);
    props[i] = dst;
  }
}

void DeviceArray::release() {
  for (cl_mem m : props) clReleaseMemObject(m);
  for (cl_mem m : constants) clReleaseMemObject(m);
  props.clear();
  constants.clear();
  capacity = 0;
}

namespace {
const char* const kAxisName[3] = {"x", "y", "z"};

// The index of the double property `name` of a, or -1.
int real_prop(const ParticleArray& a, const char* name) {
  const int i = a.find(name);
  return i >= 0 && a.props[i].type == PropType::F64 && a.props[i].stride == 1 ? i : -1;
}
}  // namespace

// ---- KeptTables ----------------------------------------------------------------------------

bool KeptTables::update(Context& ctx, const std::vector<Extent>& arrays,
                        const std::vector<bool>& sources, int dim, double radius_scale) {
  ++updates;
  dim_ = dim;
  radius_scale_ = radius_scale;
  if (pos_.size() != arrays.size()) {
    release();
    pos_.resize(arrays.size());
    valid_ = false;
  }
  // One kernel per two arrays (as Context::search_domain), one read of all partial results.
  const std::size_t per = 8 * Context::kPartials;
  const std::size_t launches = (arrays.size() + 1) / 2;
  cl_mem partial = ctx.scratch(per * (launches ? launches : 1), -3);
  for (std::size_t k = 0; k < launches; ++k) {
    cl_kernel kern = ctx.kernel("sphc_extent_moved");
    cl_uint i = 0;
    ctx.set_arg(kern, i, dim);
    for (std::size_t j = 2 * k; j < 2 * k + 2; ++j) {
      const bool real = j < arrays.size();
      const Extent& e = arrays[real ? j : 2 * k];  // none: n = 0
      // Tracked: a source whose positions were recorded at the last build (same count).
      const bool track = real && valid_ && j < sources.size() && sources[j] && pos_[j].x0;
      const Positions& p = pos_[real ? j : 2 * k];
      ctx.set_arg(kern, i, static_cast<unsigned>(real ? e.n : 0));
      for (cl_mem m : {e.x, e.y ? e.y : e.x, e.z ? e.z : e.x, e.h}) ctx.set_arg(kern, i, m);
      ctx.set_arg(kern, i, track ? 1 : 0);
      for (cl_mem m : {p.x0, p.y0, p.z0}) ctx.set_arg(kern, i, m ? m : e.x);
    }
    ctx.set_arg(kern, i, static_cast<unsigned>(k * per));
    ctx.set_arg(kern, i, partial);
    ctx.launch(kern, Context::kPartials, "sphc_extent_moved");
  }
  std::vector<double> values(per * launches);
  ctx.read_reals(partial, values.data(), values.size());
  double moved2 = 0.0;
  combine_extents(values, 8, dim, lo_, hi_, hmax_, &moved2);
  if (!valid_) return true;
  for (std::size_t j = 0; j < arrays.size(); ++j)
    if (arrays[j].n != pos_[j].n) return true;  // particles added or removed
  // A source particle within the support of a destination now was within support + moved of
  // it at the build: within one cell of it while that is at most the cell side. A small
  // margin for the rounding of the cell coordinates.
  const double support = radius_scale * hmax_;
  const double margin = ctx.double_precision() ? 1e-9 : 1e-4;
  return !(std::sqrt(moved2) + support <= cell_ * (1.0 - margin));
}

Grid KeptTables::grid(const Context& ctx, double cell_skin) const {
  return ctx.grid_of(search_domain_of_box(lo_, hi_, hmax_, dim_, radius_scale_ * (1.0 + cell_skin)));
}

void KeptTables::built(Context& ctx, const std::vector<Extent>& arrays,
                       const std::vector<bool>& sources) {
  ++builds;
  const std::size_t rs = ctx.real_size();
  const SearchDomain dom = search_domain_of_box(lo_, hi_, hmax_, dim_, radius_scale_ * (1.0 + skin));
  cell_ = dom.cell_size;
  for (std::size_t j = 0; j < arrays.size() && j < pos_.size(); ++j) {
    const Extent& e = arrays[j];
    Positions& p = pos_[j];
    p.n = e.n;
    if (j >= sources.size() || !sources[j] || e.n == 0) continue;
    if (p.capacity < e.n) {
      p.release();
      p.capacity = e.n;
      p.x0 = ctx.alloc(e.n * rs);
      if (e.y) p.y0 = ctx.alloc(e.n * rs);
      if (e.z) p.z0 = ctx.alloc(e.n * rs);
    }
    const cl_mem from[3] = {e.x, e.y, e.z}, to[3] = {p.x0, p.y0, p.z0};
    for (int a = 0; a < 3; ++a)
      if (from[a])
        check(clEnqueueCopyBuffer(ctx.queue(), from[a], to[a], 0, 0, e.n * rs, 0, nullptr,
                                  nullptr),
              "clEnqueueCopyBuffer (kept positions)");
  }
  valid_ = true;
}

void KeptTables::Positions::release() {
  for (cl_mem* m : {&x0, &y0, &z0})
    if (*m) {
      clReleaseMemObject(*m);
      *m = nullptr;
    }
  capacity = 0;
}

void KeptTables::release() {
  for (Positions& p : pos_) p.release();
  pos_.clear();
  valid_ = false;
}

void check_neighbour_lists(Context& ctx, cl_mem counts, std::size_t n, int capacity,
                           const char* what) {
  if (n == 0) return;
  const double most = ctx.reduce(counts, n, Op::Max);
  if (most <= capacity) return;
  throw std::runtime_error(
      "loop_all (" + std::string(what) + "): a particle has " +
      std::to_string(static_cast<long>(most)) + " neighbours, more than the " +
      std::to_string(capacity) +
      " an OpenCL neighbour list holds; run this scene on the CPU backends (serial, openmp), "
      "or with a smaller h / dx ratio");
}

void wrap_periodic(Context& ctx, const Domain& d, DeviceArray& dev, const ParticleArray& a) {
  for (int ax = 0; ax < d.dim && ax < 3; ++ax) {
    if (!d.periodic(ax)) continue;
    const int idx = real_prop(a, kAxisName[ax]);
    if (idx < 0 || static_cast<std::size_t>(idx) >= dev.props.size()) continue;
    ctx.run("sphc_wrap_periodic", a.n, dev.prop(idx), static_cast<unsigned>(a.n), d.lo[ax],
            d.hi[ax]);
  }
}

std::size_t DeviceGhosts::add(Context& ctx, const Domain& d, const ParticleArray& a,
                              DeviceArray& dev, double cutoff, const std::vector<int>& carried) {
  const auto t0 = std::chrono::steady_clock::now();
  // The real positions of the axes that make images, then the list as on the CPU.
  const double* p[3] = {nullptr, nullptr, nullptr};
  for (int ax = 0; ax < d.dim && ax < 3; ++ax) {
    if (d.lo_kind[ax] == Boundary::Open && d.hi_kind[ax] == Boundary::Open) continue;
    const int idx = real_prop(a, kAxisName[ax]);
    if (idx < 0) continue;  // find_ghosts names the missing position
    pos[ax].resize(a.n);
    if (a.n) ctx.read_reals(dev.prop(idx), pos[ax].data(), a.n);
    p[ax] = pos[ax].data();
  }
  find_ghosts(d, p, a.n, cutoff, list, a.name);
  const std::size_t g = list.size();
  dev.reserve(ctx, a, a.n + g);
  if (g > capacity || !source) {
    if (source) clReleaseMemObject(source);
    if (image) clReleaseMemObject(image);
    capacity = std::max(g, capacity + capacity / 4 + 64);
    source = ctx.alloc(capacity * sizeof(cl_uint));
    image = ctx.alloc(capacity);
  }
  if (g) {
    check(clEnqueueWriteBuffer(ctx.queue(), source, CL_TRUE, 0, g * sizeof(cl_uint),
                               list.source.data(), 0, nullptr, nullptr),
          "clEnqueueWriteBuffer (ghost sources)");
    check(clEnqueueWriteBuffer(ctx.queue(), image, CL_TRUE, 0, g, list.image.data(), 0, nullptr,
                               nullptr),
          "clEnqueueWriteBuffer (ghost images)");
  }
  if (ctx.profiling())
    ctx.add_profile("host: ghost list (read x, find, write)",
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  refresh(ctx, d, a, dev, carried);
  return g;
}

void DeviceGhosts::refresh(Context& ctx, const Domain& d, const ParticleArray& a,
                           DeviceArray& dev, const std::vector<int>& props) {
  const std::size_t g = list.size();
  if (g == 0) return;
  const unsigned un = static_cast<unsigned>(a.n), ug = static_cast<unsigned>(g);
  for (int idx : props) {
    if (idx < 0 || static_cast<std::size_t>(idx) >= a.props.size() ||
        static_cast<std::size_t>(idx) >= dev.props.size())
      throw std::out_of_range("ghosts of array '" + a.name + "': no property number " +
                              std::to_string(idx));
    const Property& p = a.props[idx];
    bool position = false;
    const int ax = ghost_axis(p, position);
    if (ax >= 0) {
      // Per side the op (sphc_ghost_real's mode) and constant of the CPU's transform.
      const GhostTransform lo = ghost_transform(d, ax, 0, position);
      const GhostTransform hi = ghost_transform(d, ax, 1, position);
      ctx.run("sphc_ghost_real", g, dev.prop(idx), source, image, un, ug, ax,
              static_cast<int>(lo.op), lo.t, static_cast<int>(hi.op), hi.t);
      continue;
    }
    const bool wide = p.type == PropType::F64 && ctx.double_precision();
    const std::size_t count = g * static_cast<std::size_t>(p.stride);
    ctx.run(wide ? "sphc_ghost_copy8" : "sphc_ghost_copy4", count, dev.prop(idx), source, un, ug,
            static_cast<unsigned>(p.stride));
  }
}

void DeviceGhosts::release() {
  for (cl_mem* m : {&source, &image})
    if (*m) {
      clReleaseMemObject(*m);
      *m = nullptr;
    }
  capacity = 0;
}

namespace {

// The shape functions of every kernel as OpenCL C: the text of sphc/kernel_shapes.h, which
// the CPU backends compile as C++ (kernels.h).
#define SPHC_KERNEL_SHAPES(...) #__VA_ARGS__
const char* const kKernelShapesSource =
#include "sphc/kernel_shapes.h"
    ;
#undef SPHC_KERNEL_SHAPES

}  // namespace

std::string kernel_function_source(const std::string& kernel, int dim) {
  // sigma and the radius scale from sphc/kernels.h, f(q) and df(q) from sphc/kernel_shapes.h:
  // the CPU kernels' numbers and text.
  KernelKind kind;
  if (!parse_kernel_kind(kernel, kind)) {
    throw std::invalid_argument("sphc::ocl: unknown kernel '" + kernel + "'");
  }
  const AnyKernel any{kind, dim};
  char buf[64];
  auto num = [&](double v) {
    std::snprintf(buf, sizeof buf, "%.17g", v);
    std::string s = buf;
    if (s.find_first_of(".e") == std::string::npos) s += ".0";
    return s;
  };
  const std::string sigma = num(any.sigma()), rs = num(any.radius_scale());
  // The shape functions of this kernel and dimension (kernels.h's Shape<Dim>::f, df).
  std::string fn, fargs = "q", dfargs = "q";
  switch (kind) {
    case KernelKind::CubicSpline: fn = "sphc_cubic"; break;
    case KernelKind::QuinticSpline: fn = "sphc_quintic"; break;
    case KernelKind::WendlandQuintic: fn = dim == 1 ? "sphc_wendland_c2_1d" : "sphc_wendland_c2"; break;
    case KernelKind::Gaussian: fn = "sphc_gaussian"; break;
    case KernelKind::WendlandQuinticC4: fn = dim == 1 ? "sphc_wendland_c4_1d" : "sphc_wendland_c4"; break;
    case KernelKind::WendlandQuinticC6: fn = dim == 1 ? "sphc_wendland_c6_1d" : "sphc_wendland_c6"; break;
    case KernelKind::SuperGaussian:
      fn = "sphc_super_gaussian";
      fargs = "q, " + num(1 + 0.5 * dim);
      dfargs = "q, " + num(dim + 4.0);
      break;
  }
  const std::string f = "  return " + fn + "_f(" + fargs + ");\n";
  const std::string df = "  return " + fn + "_df(" + dfargs + ");\n";
  const std::string shapes = std::string("#define SPHC_SHAPE_FN inline real\n"
                                         "#define SPHC_R(x) ((real)(x))\n"
                                         "#define SPHC_EXP(x) exp(x)\n") +
                             kKernelShapesSource + "\n";
  std::string ih = dim == 1 ? "ih" : dim == 2 ? "(ih * ih)" : "(ih * ih * ih)";
  return "#line 1 \"sphc-kernel.cl\"\n" + shapes + "#define RADIUS_SCALE " + rs +
         "\n#define RADIUS2 (RADIUS_SCALE * RADIUS_SCALE)\n"
         "inline real kernel_f(real q) {\n" +
         f + "}\n" + "inline real kernel_df(real q) {\n" + df + "}\n" +
         "inline real kernel_w(real rij, real h) {\n  const real ih = 1.0 / h;\n  return " + sigma +
         " * " + ih + " * kernel_f(rij / h);\n}\n" +
         "inline void kernel_gradient(const real* xij, real rij, real h, real* grad) {\n"
         "  const real ih = 1.0 / h;\n"
         "  const real s = rij > 1e-12 ? " +
         sigma + " * " + ih +
         " * kernel_df(rij / h) / (h * rij) : 0.0;\n"
         "  grad[0] = s * xij[0];\n  grad[1] = s * xij[1];\n  grad[2] = s * xij[2];\n}\n";
}

}  // namespace ocl
}  // namespace sphc
