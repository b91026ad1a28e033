// sphc runtime, distributed runs: see sphc/mpi/output.h.
#include "sphc/mpi/output.h"

#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cerrno>
#include <cstring>
#include <memory>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "sphc/mpi/comm.h"
#include "sphc/mpi/gather.h"

#ifdef SPHC_PARALLEL_HDF5
#include <hdf5.h>

#include "../hdf5_types.h"  // native_type
#endif

namespace sphc::mpi {

#ifdef SPHC_PARALLEL_HDF5
namespace {

constexpr const char* kPositions[] = {"x", "y", "z"};

// A count or displacement for MPI (an int), or a clear error where it does not fit.
int checked_count(std::size_t count, const std::string& what) {
  if (count > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw std::runtime_error(fmt::format(
        "{}: {} particles to exchange between two ranks, more than MPI's int counts hold "
        "({}); run on more ranks", what, count, std::numeric_limits<int>::max()));
  return static_cast<int>(count);
}

// One dataset of an array's group: a property, or zeros for a position the scene has not.
struct Column {
  std::string name;
  PropType type = PropType::F64;
  int stride = 1;
  const Property* prop = nullptr;  // null: zeros
};

// The datasets write_particles_hdf5 writes for `out`, in its order: x, y, z (those the array
// has), the selected properties (or all), each once; then zeros for the missing positions.
std::vector<Column> columns_of(const OutputArray& out) {
  const ParticleArray& a = *out.array;
  std::vector<Column> cols;
  for (const Property* p : output_properties(out))
    cols.push_back(Column{p->name, p->type, std::max(p->stride, 1), p});
  for (const char* pos : kPositions)
    if (a.find(pos) < 0) cols.push_back(Column{pos, PropType::F64, 1, nullptr});
  return cols;
}

double value_at(const Property& p, std::size_t k) {
  switch (p.type) {
    case PropType::F64: return p.f64[k];
    case PropType::I32: return static_cast<double>(p.i32[k]);
    case PropType::U32: return static_cast<double>(p.u32[k]);
  }
  return 0.0;
}

// HDF5 identifiers closed at scope exit; failures throw naming the file and object (every
// rank fails alike, or the job ends through sphc::mpi::finish).
class Files {
 public:
  explicit Files(std::string path) : path_(std::move(path)) { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }
  ~Files() {
    for (auto it = open_.rbegin(); it != open_.rend(); ++it) it->second(it->first);
  }
  hid_t own(hid_t id, herr_t (*close)(hid_t), const std::string& what) {
    if (id < 0) fail(what);
    open_.emplace_back(id, close);
    return id;
  }
  void check(herr_t status, const std::string& what) const {
    if (status < 0) fail(what);
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error(fmt::format("HDF5 file '{}' (parallel output): {}", path_, what));
  }
  void close_all() {
    for (auto it = open_.rbegin(); it != open_.rend(); ++it)
      check(it->second(it->first), "cannot close");
    open_.clear();
  }

 private:
  std::string path_;
  std::vector<std::pair<hid_t, herr_t (*)(hid_t)>> open_;
};

hid_t ordered_plist(Files& f, hid_t cls) {
  const hid_t p = f.own(H5Pcreate(cls), H5Pclose, "cannot create a property list");
  const unsigned flags = H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED;
  f.check(H5Pset_link_creation_order(p, flags), "cannot set link order");
  f.check(H5Pset_attr_creation_order(p, flags), "cannot set attribute order");
  return p;
}

// Every rank calls it with the same value (attributes are metadata: collective).
void attribute(Files& f, hid_t obj, const char* name, hid_t type, const void* value,
               hsize_t count, bool scalar) {
  const hid_t space = scalar ? f.own(H5Screate(H5S_SCALAR), H5Sclose, "dataspace")
                             : f.own(H5Screate_simple(1, &count, nullptr), H5Sclose, "dataspace");
  const hid_t attr = f.own(H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
                           std::string("cannot create attribute ") + name);
  if (scalar || count > 0) f.check(H5Awrite(attr, type, value), std::string("attribute ") + name);
}

// This rank's slab of one array: `count` particles from global index `start`, each column's
// values in particle order (stride values per particle), as doubles.
struct Slab {
  std::size_t start = 0, count = 0, total = 0;
  std::vector<std::vector<double>> values;  // per column
};

Slab slab_of(const ParticleArray& a, const std::vector<Column>& cols) {
  const int P = size(), me = rank();
  Slab s;
  s.values.resize(cols.size());
  const int g = a.find("gid");
  if (g < 0) throw std::runtime_error("parallel output: array '" + a.name + "' has no gid");
  const auto& gid = a.props[static_cast<std::size_t>(g)].u32;
  long n = static_cast<long>(a.n), N = 0;
  MPI_Allreduce(&n, &N, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  unsigned long lo = std::numeric_limits<unsigned long>::max(), hi = 0;
  for (std::size_t i = 0; i < a.n; ++i) {
    lo = std::min<unsigned long>(lo, gid[i]);
    hi = std::max<unsigned long>(hi, gid[i]);
  }
  unsigned long glo = 0, ghi = 0;
  MPI_Allreduce(&lo, &glo, 1, MPI_UNSIGNED_LONG, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&hi, &ghi, 1, MPI_UNSIGNED_LONG, MPI_MAX, MPI_COMM_WORLD);
  s.total = static_cast<std::size_t>(N);
  std::size_t width = 0;
  for (const Column& c : cols) width += static_cast<std::size_t>(c.stride);
  auto pack = [&](std::size_t i, std::vector<double>& buf) {
    for (const Column& c : cols)
      for (int k = 0; k < c.stride; ++k)
        buf.push_back(c.prop ? value_at(*c.prop, i * static_cast<std::size_t>(c.stride) + k) : 0.0);
  };
  auto unpack = [&](std::size_t j, const double* v) {
    for (std::size_t c = 0; c < cols.size(); ++c)
      for (int k = 0; k < cols[c].stride; ++k)
        s.values[c][j * static_cast<std::size_t>(cols[c].stride) + k] = *v++;
  };
  auto size_columns = [&] {
    for (std::size_t c = 0; c < cols.size(); ++c)
      s.values[c].assign(s.count * static_cast<std::size_t>(cols[c].stride), 0.0);
  };
  // gid order: rank r writes the particles whose gid lies in the r-th of P equal ranges of
  // [glo, ghi]. Where an array's gids are a contiguous range (set-up order, nothing created
  // or removed) these are equal blocks of particles; with inlets and outlets the ranges hold
  // what particles they hold. Either way the file is in gid order whatever the number of ranks.
  const unsigned long span = N == 0 ? 1 : ghi - glo + 1;
  auto range_start = [&](int r) {  // the first gid offset (from glo) of rank r's range
    return static_cast<unsigned long>(
        static_cast<unsigned __int128>(span) * static_cast<unsigned long>(r) /
        static_cast<unsigned long>(P));
  };
  std::vector<std::vector<double>> out(static_cast<std::size_t>(P));
  for (std::size_t i = 0; i < a.n; ++i) {
    const unsigned long pos = gid[i] - glo;
    int r = static_cast<int>(static_cast<unsigned __int128>(pos) * static_cast<unsigned long>(P) / span);
    while (r > 0 && pos < range_start(r)) --r;
    while (r + 1 < P && pos >= range_start(r + 1)) ++r;
    auto& b = out[static_cast<std::size_t>(r)];
    b.push_back(static_cast<double>(gid[i]));
    pack(i, b);
  }
  // Counted in particles (an MPI type of w doubles), not in doubles: MPI's int counts and
  // displacements then hold up to 2^31 - 1 particles per rank and array (any number of
  // values), and past that the output stops with a message instead of overflowing.
  const std::size_t w = width + 1;
  std::vector<int> scount(P), rcount(P), sdisp(P), rdisp(P);
  std::vector<double> send;
  const auto int_count = [&](std::size_t particles) {
    return checked_count(particles, fmt::format("parallel output of array '{}'", a.name));
  };
  for (int r = 0; r < P; ++r) {
    sdisp[r] = int_count(send.size() / w);
    scount[r] = int_count(out[r].size() / w);
    send.insert(send.end(), out[r].begin(), out[r].end());
  }
  MPI_Alltoall(scount.data(), 1, MPI_INT, rcount.data(), 1, MPI_INT, MPI_COMM_WORLD);
  std::size_t total = 0;
  for (int r = 0; r < P; ++r) {
    rdisp[r] = int_count(total);
    total += static_cast<std::size_t>(rcount[r]);
  }
  std::vector<double> recv(total * w);
  MPI_Datatype particle;
  MPI_Type_contiguous(int_count(w), MPI_DOUBLE, &particle);
  MPI_Type_commit(&particle);
  MPI_Alltoallv(send.data(), scount.data(), sdisp.data(), particle, recv.data(), rcount.data(),
                rdisp.data(), particle, MPI_COMM_WORLD);
  MPI_Type_free(&particle);
  // This rank's slab: its range's particles in gid order, after those of the lower ranges.
  s.count = total;
  long mine = static_cast<long>(total), before = 0;
  MPI_Exscan(&mine, &before, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  s.start = me == 0 ? 0 : static_cast<std::size_t>(before);
  size_columns();
  std::vector<std::size_t> order(total);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(),
            [&](std::size_t x, std::size_t y) { return recv[x * w] < recv[y * w]; });
  for (std::size_t j = 0; j < total; ++j) unpack(j, &recv[order[j] * w + 1]);
  return s;
}

void write_column(Files& f, hid_t group, hid_t dxpl, const Column& c, const Slab& s,
                  const std::vector<double>& values) {
  const hsize_t dims[2] = {s.total, static_cast<hsize_t>(c.stride)};
  const int rnk = c.stride == 1 ? 1 : 2;
  const hid_t type = native_type(c.type);
  const hid_t fspace = f.own(H5Screate_simple(rnk, dims, nullptr), H5Sclose, "dataspace of " + c.name);
  const hid_t dset = f.own(H5Dcreate2(group, c.name.c_str(), type, fspace, H5P_DEFAULT, H5P_DEFAULT,
                                      H5P_DEFAULT),
                           H5Dclose, "cannot create dataset " + c.name);
  if (s.total == 0) return;
  const hsize_t start[2] = {s.start, 0}, count[2] = {s.count, static_cast<hsize_t>(c.stride)};
  const hsize_t mdims[2] = {std::max<hsize_t>(s.count, 1), static_cast<hsize_t>(c.stride)};
  const hid_t mspace = f.own(H5Screate_simple(rnk, mdims, nullptr), H5Sclose, "memory space");
  if (s.count > 0) {
    f.check(H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start, nullptr, count, nullptr), "slab");
  } else {
    f.check(H5Sselect_none(fspace), "slab");
    f.check(H5Sselect_none(mspace), "slab");
  }
  // The values in the dataset's own type.
  std::vector<std::int32_t> i32;
  std::vector<std::uint32_t> u32;
  const void* data = values.data();
  if (c.type == PropType::I32) {
    i32.assign(values.begin(), values.end());
    data = i32.data();
  } else if (c.type == PropType::U32) {
    u32.reserve(values.size());
    for (double v : values) u32.push_back(static_cast<std::uint32_t>(v));
    data = u32.data();
  }
  static const double none = 0.0;
  if (values.empty()) data = &none;
  f.check(H5Dwrite(dset, type, mspace, fspace, dxpl, data), "cannot write dataset " + c.name);
}

}  // namespace

bool parallel_output_available() { return true; }

XdmfEntry write_particles_parallel(const std::string& path, const std::string& file,
                                   const std::vector<OutputArray>& arrays,
                                   const OutputMeta& meta) {
  const std::string tmp = path + ".tmp";
  XdmfEntry entry = make_xdmf_entry(file, meta.t, arrays);
  {
    Files f(tmp);
    const hid_t fapl = f.own(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "file access list");
    f.check(H5Pset_fapl_mpio(fapl, MPI_COMM_WORLD, MPI_INFO_NULL), "cannot use MPI-IO");
    const hid_t fcpl = ordered_plist(f, H5P_FILE_CREATE);
    const hid_t h5 = f.own(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, fcpl, fapl), H5Fclose,
                           "cannot create the file");
    const hid_t dxpl = f.own(H5Pcreate(H5P_DATASET_XFER), H5Pclose, "transfer list");
    f.check(H5Pset_dxpl_mpio(dxpl, H5FD_MPIO_COLLECTIVE), "cannot ask for collective writes");
    // Rank 0's values everywhere (they agree; attributes must be written alike by all).
    double t = meta.t, dt = meta.dt;
    MPI_Bcast(&t, 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    MPI_Bcast(&dt, 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    const std::int64_t step = meta.step;
    const std::int32_t dim = meta.dim;
    attribute(f, h5, "t", H5T_NATIVE_DOUBLE, &t, 1, true);
    attribute(f, h5, "step", H5T_NATIVE_INT64, &step, 1, true);
    attribute(f, h5, "dt", H5T_NATIVE_DOUBLE, &dt, 1, true);
    attribute(f, h5, "dim", H5T_NATIVE_INT32, &dim, 1, true);
    const hid_t str = f.own(H5Tcopy(H5T_C_S1), H5Tclose, "string type");
    f.check(H5Tset_size(str, H5T_VARIABLE), "string type");
    f.check(H5Tset_cset(str, H5T_CSET_UTF8), "string type");
    const char* scene = meta.scene.c_str();
    attribute(f, h5, "scene", str, &scene, 1, true);
    for (const auto& [name, value] : meta.state) {  // the run state (--restart), rank 0's
      double v = value;
      MPI_Bcast(&v, 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
      attribute(f, h5, (kRunStatePrefix + name).c_str(), H5T_NATIVE_DOUBLE, &v, 1, true);
    }
    for (std::size_t k = 0; k < arrays.size(); ++k) {
      const ParticleArray& a = *arrays[k].array;
      const std::vector<Column> cols = columns_of(arrays[k]);
      const Slab s = slab_of(a, cols);
      entry.arrays[k].second = s.total;
      const hid_t gcpl = ordered_plist(f, H5P_GROUP_CREATE);
      const hid_t group = f.own(H5Gcreate2(h5, a.name.c_str(), H5P_DEFAULT, gcpl, H5P_DEFAULT),
                                H5Gclose, "cannot create group " + a.name);
      const std::int64_t n = static_cast<std::int64_t>(s.total);
      attribute(f, group, "n", H5T_NATIVE_INT64, &n, 1, true);
      for (std::size_t c = 0; c < cols.size(); ++c) write_column(f, group, dxpl, cols[c], s, s.values[c]);
      if (!a.constants.empty()) {
        const hid_t ccpl = ordered_plist(f, H5P_GROUP_CREATE);
        const hid_t cg = f.own(H5Gcreate2(group, "constants", H5P_DEFAULT, ccpl, H5P_DEFAULT),
                               H5Gclose, "cannot create group " + a.name + "/constants");
        for (const Constant& con : a.constants) {
          std::vector<double> v = con.values;
          MPI_Bcast(v.data(), static_cast<int>(v.size()), MPI_DOUBLE, 0, MPI_COMM_WORLD);
          attribute(f, cg, con.name.c_str(), H5T_NATIVE_DOUBLE, v.data(), v.size(), false);
        }
      }
    }
    f.close_all();
  }
  if (rank() == 0 && std::rename(tmp.c_str(), path.c_str()) != 0)
    throw std::runtime_error(fmt::format("cannot rename '{}' to '{}': {}", tmp, path,
                                         std::strerror(errno)));
  MPI_Barrier(MPI_COMM_WORLD);
  return entry;
}

#else  // without parallel HDF5: the gathered output only

bool parallel_output_available() { return false; }

XdmfEntry write_particles_parallel(const std::string& path, const std::string&,
                                   const std::vector<OutputArray>&, const OutputMeta&) {
  throw std::runtime_error("cannot write '" + path + "' collectively: sphc was built without "
                           "parallel HDF5 (libhdf5-openmpi-dev)");
}

#endif

void set_output(SceneProgram& prog, std::function<std::vector<ParticleArray*>()> arrays) {
  const char* env = std::getenv("SPHC_MPI_OUTPUT");
  const std::string choice = env ? env : "";
  if (!choice.empty() && choice != "gather" && choice != "parallel")
    abort_job(2, "SPHC_MPI_OUTPUT must be 'gather' or 'parallel', not '" + choice + "'");
  if (choice == "parallel" && !parallel_output_available())
    abort_job(2, "SPHC_MPI_OUTPUT=parallel: sphc was built without parallel HDF5");
  if (parallel_output_available() && choice != "gather") {
    prog.write_particles = write_particles_parallel;
    prog.output_arrays = nullptr;
    return;
  }
  // Gathered to rank 0 in gid order (the storage lives as long as the program).
  auto gathered = std::make_shared<std::vector<ParticleArray>>();
  prog.write_particles = nullptr;
  prog.output_arrays = [arrays = std::move(arrays), gathered] {
    gather_arrays(arrays(), *gathered);
    std::vector<ParticleArray*> out;
    for (ParticleArray& a : *gathered) out.push_back(&a);
    return out;
  };
}

void set_removal(SceneProgram& prog, Decomposition& d, std::vector<ParticleArray*> arrays) {
  prog.sum_over_ranks = [](double x) { return sum(x); };
  prog.gather_removed = [&d, arrays = std::move(arrays)](const ParticleArray& a,
                                                         const std::vector<std::uint8_t>& mask,
                                                         ParticleArray& gone) {
    for (std::size_t k = 0; k < arrays.size() && !mask.empty(); ++k)
      if (arrays[k] == &a) forget_particles(d, k, mask);
    std::vector<ParticleArray> all;
    gather_arrays({&gone}, all);
    gone = std::move(all.front());
  };
}

}  // namespace sphc::mpi
