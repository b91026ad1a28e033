// sphc runtime: support for solvers of --backend=opencl (built as libsphc_runtime_ocl.a, only
// when CMake found OpenCL).
//
// A generated OpenCL solver keeps every particle property in a device buffer (one per
// property and per array constant, `real` = double or float as chosen by sphc --precision).
// Host data (sphc::ParticleArray) stays double: DeviceArray converts at upload and download.
// Context owns the platform/device choice, the program (the scene's kernels plus the runtime
// kernels below, built once with the build log on failure), kernel launches and reductions.
// CellTable is the device neighbour search: a cell key per particle on a dense grid over the
// search domain (the domain from min/max reductions on the device), a counting sort by cell
// (atomic counts, scan, scatter, then each cell's few indices sorted, so the order is
// deterministic), and cell start/end tables; interaction kernels loop over the 3^dim
// cells around a particle and apply r_ij < radius_scale * max(h_i, h_j) themselves.
#pragma once

#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120
#endif
#include <CL/cl.h>

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "sphc/domain.h"
#include "sphc/nnps.h"
#include "sphc/particle_array.h"

namespace sphc {
namespace ocl {

// The name of an OpenCL error code (e.g. "CL_OUT_OF_RESOURCES").
const char* error_name(cl_int err);
// Throws std::runtime_error("OpenCL: <what> failed: <error name>") unless err is CL_SUCCESS.
void check(cl_int err, const char* what);

// Removes `--platform N`, `--device N` and `--list-devices` from the command line (so that
// run_main does not see them); --list-devices prints every platform and device and exits.
// SPHC_OPENCL_PLATFORM / SPHC_OPENCL_DEVICE in the environment give defaults.
struct Selection {
  int platform = -1;  // -1: the first platform with a device that fits
  int device = -1;
};
Selection take_options(int& argc, char** argv);

// The uniform grid of the device neighbour search (dense, cells of side `cell`).
struct Grid {
  double lo[3] = {0.0, 0.0, 0.0};
  double inv_cell = 1.0;
  int ncell[3] = {1, 1, 1};
  std::size_t cells() const { return static_cast<std::size_t>(ncell[0]) * ncell[1] * ncell[2]; }
};

enum class Op { Sum, Min, Max };

class Context;

// The cell table of one source array: particles sorted by cell (a counting sort on the
// device: order = particle indices cell by cell, ascending within a cell, as CellList's),
// start/end per cell of the dense grid.
struct CellTable {
  cl_mem keys = nullptr, order = nullptr, start = nullptr, end = nullptr;
  cl_mem count = nullptr, partial = nullptr;  // scratch of the counting sort
  cl_mem done = nullptr;  // build_tables: work groups done counting (0 between builds)
  std::size_t padded = 0, cells = 0;          // capacity of keys/order, of the cell tables
  static constexpr std::size_t kScanItems = 256;
  // Room for n particles and the grid's cells (the counts zero when allocated).
  void reserve(Context& ctx, const Grid& grid, std::size_t n);
  void build(Context& ctx, const Grid& grid, cl_mem x, cl_mem y, cl_mem z, std::size_t n);
  void release();
  ~CellTable() { release(); }
};

// The cell tables of several sources on one grid in one set of launches: three per two
// tables (cell keys with the scan by the work group that finishes last, scatter, per-cell
// sort) where CellTable::build takes five per table; the same tables. y, z: nullptr beyond
// the dimension.
struct TableBuild {
  CellTable* table;
  cl_mem x, y, z;
  std::size_t n;
};
// Work items per work group of the keys kernel, hence of the scan (at most the kernel's
// work-group size on the device; SPHC_SCAN_GROUP_MAX in the kernel source).
constexpr std::size_t kScanGroup = 64;
void build_tables(Context& ctx, const Grid& grid, const std::vector<TableBuild>& tables);

// Device copies of the properties and constants of one ParticleArray. Each property buffer
// holds `capacity` particles (>= n): room for ghosts after the n real particles.
struct DeviceArray {
  std::vector<cl_mem> props;
  std::vector<cl_mem> constants;
  std::size_t n = 0;
  std::size_t capacity = 0;
  cl_mem prop(int i) const { return props[i]; }
  cl_mem constant(int i) const { return constants[i]; }
  // Allocates (first call, other properties or more particles than the capacity) and copies
  // every property and constant to the device.
  void upload(Context& ctx, const ParticleArray& a);
  // Grows every property buffer to hold at least `count` particles, keeping its contents
  // (reallocation and a device copy; the capacity grows by at least a quarter, so a slowly
  // growing ghost count reallocates rarely).
  void reserve(Context& ctx, const ParticleArray& a, std::size_t count);
  void upload_constant(Context& ctx, const ParticleArray& a, int c);
  // Copies every property (not the constants: the host copy is the reference) back.
  void download(Context& ctx, ParticleArray& a);
  // Only the properties `which` (indices into a.props) of the n particles, down or up (same
  // n; the inlet/outlet step reads positions and writes inlet velocities this way).
  void download(Context& ctx, ParticleArray& a, const std::vector<int>& which);
  void upload(Context& ctx, const ParticleArray& a, const std::vector<int>& which);
  // Reorders the particles on the device into the cell order of `cells` (built on this
  // array): ParticleArray::permute(cell_order) of the CPU backends.
  void permute(Context& ctx, const CellTable& cells, const ParticleArray& a);
  void release();
  ~DeviceArray() { release(); }
};

// Per-array extents for the search domain: device buffers of x, y, z (nullptr beyond dim), h.
struct Extent {
  cl_mem x = nullptr, y = nullptr, z = nullptr, h = nullptr;
  std::size_t n = 0;
};

class Context {
 public:
  // Picks the platform and device (sel, else the first device that fits; double precision
  // needs fp64), creates the context and queue, and builds `scene_source` (OpenCL C, which may
  // use the `real` type and the runtime helpers) together with the runtime kernels. On a build
  // failure the exception holds the compiler log; `#line` directives in the scene source make
  // it name the .sph lines of the bodies.
  void init(const Selection& sel, bool double_precision, const std::string& scene_source,
            const std::string& scene_name);
  ~Context();

  bool double_precision() const { return dp_; }
  std::size_t real_size() const { return dp_ ? sizeof(double) : sizeof(float); }
  const std::string& device_name() const { return device_name_; }
  cl_command_queue queue() const { return queue_; }

  cl_mem alloc(std::size_t bytes);
  // A scratch buffer of at least n reals, kept between calls (slot: several at once).
  cl_mem scratch(std::size_t n, int slot = 0);
  cl_kernel kernel(const std::string& name);

  // Sets the arguments in order (cl_mem, int, unsigned, double as real, Grid: 7 arguments,
  // const CellTable&: order, start, end) and runs the kernel on n work items (none if n = 0).
  template <class... A>
  void run(const std::string& name, std::size_t n, const A&... args) {
    if (n == 0) return;
    cl_kernel k = kernel(name);
    cl_uint i = 0;
    (set_arg(k, i, args), ...);
    launch(k, n, name);
  }
  // op over v[0..n) (reals on the device): partial results on the device, finished here.
  // Min and Max ignore NaN (as fmin/fmax); finite_only also ignores infinities.
  double reduce(cl_mem v, std::size_t n, Op op, bool finite_only = false);
  // Several reductions with one wait for the device (as reduce, in order).
  struct Reduction {
    cl_mem v;
    std::size_t n;
    Op op;
    bool finite_only = false;
  };
  std::vector<double> reduce_all(const std::vector<Reduction>& rs);
  // Partial minima computed by a scene kernel itself (one launch of kPartials work items,
  // item g writing partial[columns * g + c]): their minima per column (fmin: NaN ignored).
  static constexpr std::size_t kPartials = 256;
  std::vector<double> minima(cl_mem partial, int columns);
  // The same of `rows` work groups' minima that a scene kernel computed (sphc_group_reduce),
  // column c at partial[c * rows + group].
  std::vector<double> minima_rows(cl_mem partial, std::size_t rows, int columns);
  // The search domain over every array in a neighbour loop (as sphc::make_search_domain:
  // bounding box of finite coordinates, padded, cell_size = radius_scale * max h), from
  // device data.
  SearchDomain search_domain(const std::vector<Extent>& arrays, int dim, double radius_scale);
  // The dense grid of a search domain (as CellList::build; in single precision the cells are
  // 1e-5 larger). Refuses more than 2^28 cells.
  Grid grid_of(const SearchDomain& dom) const;
  Grid make_grid(const std::vector<Extent>& arrays, int dim, double radius_scale) {
    return grid_of(search_domain(arrays, dim, radius_scale));
  }
  // Kernels that reduce within work groups (sphc_extent_group) run in groups of kGroup work
  // items (their reqd_work_group_size, SPHC_GROUP in the runtime's OpenCL C): groups(n) of
  // them for n particles, one row of partial results each.
  static constexpr std::size_t kGroup = 64;
  static std::size_t groups(std::size_t n) { return (n + kGroup - 1) / kGroup; }
  // As run, in work groups of exactly kGroup work items.
  template <class... A>
  void run_grouped(const std::string& name, std::size_t n, const A&... args) {
    if (n == 0) return;
    cl_kernel k = kernel(name);
    cl_uint i = 0;
    (set_arg(k, i, args), ...);
    launch_group(k, n, name);
  }
  // make_grid from extents that scene kernels computed (sphc_extent_group): `rows` rows of 7
  // partial results in `partial`; the same grid as make_grid's over the same particles.
  Grid grid_of_extents(cl_mem partial, std::size_t rows, int dim, double radius_scale);
  // The min or max (Op::Min, Op::Max; fmin/fmax: NaN ignored) of `rows` results of work
  // groups that a scene kernel reduced (sphc_group_reduce), on the host.
  double reduce_groups(cl_mem partial, std::size_t rows, Op op);
  void finish();
  // Copies n reals from the device into doubles (blocking).
  void read_reals(cl_mem m, double* out, std::size_t n);

  void set_arg(cl_kernel k, cl_uint& i, cl_mem m);
  void set_arg(cl_kernel k, cl_uint& i, int v);
  void set_arg(cl_kernel k, cl_uint& i, unsigned v);
  void set_arg(cl_kernel k, cl_uint& i, double v);
  void set_arg(cl_kernel k, cl_uint& i, const Grid& g);
  void set_arg(cl_kernel k, cl_uint& i, const CellTable& c);
  // SPHC_OPENCL_PROFILE=1 in the environment: every launch waits for its kernel, and the
  // time per kernel name is printed to stderr at exit.
  void launch(cl_kernel k, std::size_t n, const std::string& name = "");
  // As launch, in work groups of `local` work items (fewer where the device allows fewer
  // for k).
  void launch_local(cl_kernel k, std::size_t n, std::size_t local, const std::string& name);
  // As launch, in work groups of exactly kGroup work items.
  void launch_group(cl_kernel k, std::size_t n, const std::string& name);
  bool profiling() const { return profile_; }
  // Kernel launches so far (every launch through `launch`: the scene's kernels, the neighbour
  // search's, reductions), for --timing's launches_per_step.
  long launches() const { return launches_; }
  // Adds host time to the profile printed at exit (under `name`).
  void add_profile(const std::string& name, double seconds);

 private:
  void enqueue(cl_kernel k, std::size_t global, const std::size_t* local,
               const std::string& name);
  bool dp_ = true;
  std::string device_name_;
  cl_context context_ = nullptr;
  cl_device_id device_ = nullptr;
  cl_command_queue queue_ = nullptr;
  cl_program program_ = nullptr;
  std::map<std::string, cl_kernel> kernels_;
  std::map<int, std::pair<cl_mem, std::size_t>> scratch_;
  std::vector<double> host_partial_;
  bool profile_ = false;
  long launches_ = 0;
  std::map<std::string, std::pair<double, long>> profile_times_;
};

// Cell tables kept across neighbour updates (the update_neighbours of --backend=opencl without
// periodic or mirror sides; sphc --no-kept-cells rebuilds at every update): the tables are
// built on cells of (1 + skin) times the support and kept while no source particle has moved
// farther than the cell side minus the support since the build. The pair kernels keep their
// exact test r < support, so the 3^dim cells around a destination's current cell still hold
// every neighbour. The check is one kernel per two arrays (the search domain's extents, max h
// and the sources' largest displacement) and one read, as Context::search_domain.
struct KeptTables {
  explicit KeptTables(double skin_ = 0.1) : skin(skin_) {}
  double skin;  // as a fraction of the support (sphc --kept-cells=F)
  long updates = 0, builds = 0;
  // Whether the tables must be built again: the first update, a count changed, a source
  // particle moved too far (or to a non-finite position), or the support grew past the cells.
  // `sources`: per array of `arrays`, whether it is a source (its positions are tracked).
  bool update(Context& ctx, const std::vector<Extent>& arrays, const std::vector<bool>& sources,
              int dim, double radius_scale);
  // The grid of the last update's extents with cells of (1 + cell_skin) times the support
  // (0: Context::make_grid's grid, the cell order of a re-sort).
  Grid grid(const Context& ctx, double cell_skin) const;
  // After the tables were built on grid(ctx, skin) (and the particles re-sorted): records the
  // positions of the sources (a device copy per axis) and the cell side.
  void built(Context& ctx, const std::vector<Extent>& arrays, const std::vector<bool>& sources);
  void release();
  ~KeptTables() { release(); }

 private:
  struct Positions {
    cl_mem x0 = nullptr, y0 = nullptr, z0 = nullptr;
    std::size_t capacity = 0, n = 0;
    void release();
  };
  std::vector<Positions> pos_;
  bool valid_ = false;
  int dim_ = 1;
  double radius_scale_ = 1.0, cell_ = 0.0, hmax_ = 0.0;
  double lo_[3] = {0.0, 0.0, 0.0}, hi_[3] = {0.0, 0.0, 0.0};
};

// loop_all on the device: each work item gathers its neighbour list in private memory of
// `capacity` entries and writes how many neighbours it found to `counts` (n reals). Throws
// std::runtime_error naming the pass (`what`: "fluid <- fluid") and the largest count when
// a list overflowed (the bodies then saw a truncated list: the evaluation is wrong).
void check_neighbour_lists(Context& ctx, cl_mem counts, std::size_t n, int capacity,
                           const char* what);

// Periodic and mirror domains on the device (sphc/domain.h, the same ghosts in the same
// order as the CPU backends).
//
// wrap_periodic: sphc::wrap_periodic on the device (the same arithmetic, no contraction).
void wrap_periodic(Context& ctx, const Domain& d, DeviceArray& dev, const ParticleArray& a);

// The ghosts of one source array during an evaluation: particle n + g of every device buffer
// is ghost g. The list (source particle, image bits) is found on the host by
// sphc::find_ghosts from the real positions (downloaded: only the axes with a periodic or
// mirror side), uploaded, and a device kernel per carried property fills the ghost slots
// with the CPU's transforms (positions shifted or reflected, the normal velocity negated
// under a mirror, everything else copied). The host ParticleArray never holds ghosts.
struct DeviceGhosts {
  Ghosts list;
  cl_mem source = nullptr, image = nullptr;
  std::size_t capacity = 0;
  std::vector<double> pos[3];
  std::size_t size() const { return list.size(); }
  // add_ghosts: finds the ghosts of the n real particles, grows dev to n + ghosts and fills
  // the properties `carried` (indices into a.props). Returns the number of ghosts.
  std::size_t add(Context& ctx, const Domain& d, const ParticleArray& a, DeviceArray& dev,
                  double cutoff, const std::vector<int>& carried);
  // refresh_ghosts: fills the properties `props` of the ghosts from their sources again.
  void refresh(Context& ctx, const Domain& d, const ParticleArray& a, DeviceArray& dev,
               const std::vector<int>& props);
  // remove_ghosts: the count back to 0 (the buffers keep their capacity).
  void remove() {
    list.source.clear();
    list.image.clear();
  }
  void release();
  ~DeviceGhosts() { release(); }
};

// OpenCL C of the kernel functions `kernel_w(r, h)` and `kernel_gradient(xij, r, h, grad)` and
// RADIUS_SCALE for one smoothing kernel of sphc/kernels.h ("CubicSpline", ...) and dimension.
std::string kernel_function_source(const std::string& kernel, int dim);

}  // namespace ocl
}  // namespace sphc
