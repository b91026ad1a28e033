// sphc runtime, distributed runs: see sphc/mpi/decomposition.h.
#include "sphc/mpi/decomposition.h"

#include "sphc/global_ids.h"

#include <mpi.h>
#include <zoltan.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>

#include "sphc/mpi/comm.h"

namespace sphc::mpi {

namespace {

std::vector<double> measured_weights(const Decomposition& d, std::size_t arrays);
std::vector<double> pass_scales(const Decomposition& d,
                                const std::vector<ParticleArray*>& arrays);
void rebalance_with(Decomposition& d, const std::vector<ParticleArray*>& arrays,
                    bool per_particle);

// What Zoltan's callbacks see: every particle of every array, numbered in array order.
struct Objects {
  const std::vector<ParticleArray*>* arrays = nullptr;
  const std::vector<double>* weights = nullptr;  // per array; empty: none
  // Measured: each particle's own counted work where its array's counts are of its
  // particles (the passes' order, nothing created or removed since), else weights.
  const Decomposition* counts = nullptr;
  // With counts, per array: the factor on each particle's pass work that makes the array's
  // mean the mean since the last re-balance (pass_scales); < 0: its weight instead.
  std::vector<double> pass_scale;
  int dim = 2;
  unsigned long first = 0;  // global number of this rank's first object
};

std::size_t local_count(const std::vector<ParticleArray*>& arrays) {
  std::size_t n = 0;
  for (const ParticleArray* a : arrays) n += a->n;
  return n;
}

int num_obj(void* data, int* ierr) {
  *ierr = ZOLTAN_OK;
  return static_cast<int>(local_count(*static_cast<Objects*>(data)->arrays));
}

void obj_list(void* data, int, int, ZOLTAN_ID_PTR gids, ZOLTAN_ID_PTR lids, int wdim,
              float* wgts, int* ierr) {
  const Objects& o = *static_cast<Objects*>(data);
  const std::size_t n = local_count(*o.arrays);
  for (std::size_t i = 0; i < n; ++i) {
    gids[i] = static_cast<ZOLTAN_ID_TYPE>(o.first + i);
    lids[i] = static_cast<ZOLTAN_ID_TYPE>(i);
  }
  if (wdim == 1 && wgts && o.weights && !o.weights->empty()) {
    std::size_t i = 0;
    for (std::size_t k = 0; k < o.arrays->size(); ++k) {
      const std::size_t n = (*o.arrays)[k]->n;
      const Decomposition* c = o.counts;
      const double scale = k < o.pass_scale.size() ? o.pass_scale[k] : 1.0;
      if (c && k < c->particle_work.size() && c->pass_n[k] == n &&
          c->particle_work[k].size() >= n && scale >= 0) {
        for (std::size_t j = 0; j < n; ++j)
          wgts[i++] = scale == 1.0
                          ? static_cast<float>(c->particle_cost + c->particle_work[k][j])
                          : static_cast<float>(c->particle_cost + scale * c->particle_work[k][j]);
        continue;
      }
      const float w = static_cast<float>(k < o.weights->size() ? (*o.weights)[k] : 1.0);
      for (std::size_t j = 0; j < n; ++j) wgts[i++] = w;
    }
  }
  *ierr = ZOLTAN_OK;
}

int num_geom(void* data, int* ierr) {
  *ierr = ZOLTAN_OK;
  return static_cast<Objects*>(data)->dim;
}

void geom_multi(void* data, int, int, int num, ZOLTAN_ID_PTR, ZOLTAN_ID_PTR lids, int dim,
                double* out, int* ierr) {
  const Objects& o = *static_cast<Objects*>(data);
  // Local ids run over the arrays in order: find each one's array by its offset.
  for (int k = 0; k < num; ++k) {
    std::size_t i = lids[k];
    for (const ParticleArray* a : *o.arrays) {
      if (i < a->n) {
        static const char* names[3] = {"x", "y", "z"};
        for (int c = 0; c < dim; ++c) {
          const int p = a->find(names[c]);
          out[k * dim + c] = p >= 0 ? a->props[p].f64[i] : 0.0;
        }
        break;
      }
      i -= a->n;
    }
  }
  *ierr = ZOLTAN_OK;
}

void check(int rc, const char* what) {
  if (rc != ZOLTAN_OK && rc != ZOLTAN_WARN)
    abort_job(1, std::string("Zoltan failed in ") + what);
}

// The position of particle i as 3 doubles (0 beyond the array's axes).
void position(const ParticleArray& a, const int pos[3], std::size_t i, double out[3]) {
  for (int c = 0; c < 3; ++c) out[c] = pos[c] >= 0 ? a.props[pos[c]].f64[i] : 0.0;
}

void position_props(const ParticleArray& a, int dim, int pos[3]) {
  static const char* names[3] = {"x", "y", "z"};
  for (int c = 0; c < 3; ++c) pos[c] = c < dim ? a.find(names[c]) : -1;
}

}  // namespace

Decomposition::~Decomposition() {
  // A solver's Scene is static: after MPI_Finalize nothing may be freed through MPI.
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (zz && !finalized) Zoltan_Destroy(&zz);
}

bool inside_region(const Decomposition& d, const double lo[3], const double hi[3]) {
  if (!d.has_region) return false;
  for (int c = 0; c < d.dim; ++c)
    if (!(lo[c] > d.region_lo[c] && hi[c] < d.region_hi[c])) return false;
  return true;
}

void init_decomposition(Decomposition& d, int dim, const std::string& method) {
  if (method != "RCB" && method != "HSFC")
    throw std::invalid_argument("unknown decomposition method '" + method + "' (RCB or HSFC)");
  float version = 0;
  check(Zoltan_Initialize(0, nullptr, &version), "Zoltan_Initialize");
  d.dim = dim;
  d.method = method;
  d.zz = Zoltan_Create(MPI_COMM_WORLD);
  Zoltan_Set_Param(d.zz, "DEBUG_LEVEL", "0");
  Zoltan_Set_Param(d.zz, "LB_METHOD", method.c_str());
  Zoltan_Set_Param(d.zz, "NUM_GID_ENTRIES", "1");
  Zoltan_Set_Param(d.zz, "NUM_LID_ENTRIES", "1");
  Zoltan_Set_Param(d.zz, "OBJ_WEIGHT_DIM", "0");
  Zoltan_Set_Param(d.zz, "RETURN_LISTS", "NONE");  // migration is ours (owner per particle)
  Zoltan_Set_Param(d.zz, "KEEP_CUTS", "1");        // for Point_Assign and Box_Assign
}

void set_weights(Decomposition& d, const std::vector<double>& per_array) {
  // SPHC_MPI_WEIGHTS=measured|estimated|none; SPHC_MPI_UNWEIGHTED=1: none (every particle
  // weighs 1; to measure what the weights change).
  const char* mode = std::getenv("SPHC_MPI_WEIGHTS");
  const std::string m = mode ? mode : "measured";
  if (std::getenv("SPHC_MPI_UNWEIGHTED") || m == "none") d.mode = Weights::None;
  else if (m == "estimated") d.mode = Weights::Estimated;
  else if (m == "measured") d.mode = Weights::Measured;
  else
    abort_job(2, "SPHC_MPI_WEIGHTS must be measured, estimated or none, not '" + m + "'");
  d.estimate = per_array;
  d.weights = d.mode == Weights::None ? std::vector<double>{} : per_array;
  Zoltan_Set_Param(d.zz, "OBJ_WEIGHT_DIM", d.weights.empty() ? "0" : "1");
}

std::size_t packed_size(const ParticleArray& a) {
  std::size_t s = 0;
  for (const Property& p : a.props) s += static_cast<std::size_t>(p.stride);
  return s;
}

void pack_particle(const ParticleArray& a, std::size_t i, std::vector<double>& buf) {
  for (const Property& p : a.props) {
    const std::size_t o = i * static_cast<std::size_t>(p.stride);
    for (int k = 0; k < p.stride; ++k) {
      switch (p.type) {
        case PropType::F64: buf.push_back(p.f64[o + k]); break;
        case PropType::I32: buf.push_back(static_cast<double>(p.i32[o + k])); break;
        case PropType::U32: buf.push_back(static_cast<double>(p.u32[o + k])); break;
      }
    }
  }
}

void unpack_particle(ParticleArray& a, std::size_t j, const double* buf) {
  for (Property& p : a.props) {
    const std::size_t o = j * static_cast<std::size_t>(p.stride);
    for (int k = 0; k < p.stride; ++k, ++buf) {
      switch (p.type) {
        case PropType::F64: p.f64[o + k] = *buf; break;
        case PropType::I32: p.i32[o + k] = static_cast<std::int32_t>(*buf); break;
        case PropType::U32: p.u32[o + k] = static_cast<std::uint32_t>(*buf); break;
      }
    }
  }
}

int owner(const Decomposition& d, const double pos[3]) {
  if (!d.cut || inside_region(d, pos, pos)) return rank();
  double c[3] = {pos[0], pos[1], pos[2]};
  int proc = 0;
  check(Zoltan_LB_Point_Assign(d.zz, c, &proc), "Zoltan_LB_Point_Assign");
  return proc;
}

void ranks_near(const Decomposition& d, const double lo[3], const double hi[3],
                std::vector<int>& ranks) {
  ranks.clear();
  if (!d.cut) {
    ranks.push_back(rank());
    return;
  }
  static thread_local std::vector<int> procs;
  procs.resize(static_cast<std::size_t>(size()));
  int count = 0;
  check(Zoltan_LB_Box_Assign(d.zz, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], procs.data(),
                             &count),
        "Zoltan_LB_Box_Assign");
  ranks.assign(procs.begin(), procs.begin() + count);
  std::sort(ranks.begin(), ranks.end());
}

std::size_t migrate(Decomposition& d, const std::vector<ParticleArray*>& arrays) {
  const int P = size(), me = rank();
  if (P == 1) return 0;  // every particle is the only rank's
  std::size_t sent_total = 0;
  for (ParticleArray* a : arrays) {
    int pos[3];
    position_props(*a, d.dim, pos);
    const std::size_t width = packed_size(*a);
    std::vector<std::vector<double>> out(P);
    std::vector<std::uint32_t> keep;
    keep.reserve(a->n);
    for (std::size_t i = 0; i < a->n; ++i) {
      double x[3];
      position(*a, pos, i, x);
      const int r = owner(d, x);
      if (r == me) {
        keep.push_back(static_cast<std::uint32_t>(i));
      } else {
        pack_particle(*a, i, out[r]);
        ++sent_total;
      }
    }
    std::vector<int> send_counts(P), recv_counts(P), sdispl(P), rdispl(P);
    std::vector<double> send;
    for (int r = 0; r < P; ++r) {
      send_counts[r] = static_cast<int>(out[r].size());
      sdispl[r] = static_cast<int>(send.size());
      send.insert(send.end(), out[r].begin(), out[r].end());
    }
    MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
    int total = 0;
    for (int r = 0; r < P; ++r) {
      rdispl[r] = total;
      total += recv_counts[r];
    }
    std::vector<double> recv(static_cast<std::size_t>(total));
    MPI_Alltoallv(send.data(), send_counts.data(), sdispl.data(), MPI_DOUBLE, recv.data(),
                  recv_counts.data(), rdispl.data(), MPI_DOUBLE, MPI_COMM_WORLD);
    // Stayers keep their order (compacted in place), arrivals follow by sending rank.
    if (keep.size() != a->n) {
      for (Property& p : a->props) {
        const std::size_t s = static_cast<std::size_t>(p.stride);
        for (std::size_t k = 0; k < keep.size(); ++k)
          for (std::size_t c = 0; c < s; ++c) {
            const std::size_t to = k * s + c, from = keep[k] * s + c;
            if (p.type == PropType::F64) p.f64[to] = p.f64[from];
            else if (p.type == PropType::I32) p.i32[to] = p.i32[from];
            else p.u32[to] = p.u32[from];
          }
      }
    }
    const std::size_t arrivals = width ? recv.size() / width : 0;
    a->resize(keep.size() + arrivals);
    for (std::size_t k = 0; k < arrivals; ++k) unpack_particle(*a, keep.size() + k, &recv[k * width]);
  }
  d.migrated += static_cast<long>(sent_total);
  return sent_total;
}

void rebalance(Decomposition& d, const std::vector<ParticleArray*>& arrays) {
  rebalance_with(d, arrays, false);
}

namespace {

// rebalance; per_particle: the particles are those of the last evaluation's passes, each
// weighs its own counted work (Measured).
void rebalance_with(Decomposition& d, const std::vector<ParticleArray*>& arrays,
                    bool per_particle) {
  // Measured weights: what the particles of each array cost since the last re-balance (none
  // counted yet: the estimate, set_weights); the count starts again. Each particle's own
  // count is of the last evaluation: scaled to the mean since the last re-balance.
  std::vector<double> scale;
  if (d.mode == Weights::Measured && d.evaluations_counted > 0) {
    d.weights = measured_weights(d, arrays.size());
    if (per_particle) scale = pass_scales(d, arrays);
  }
  std::fill(d.work_since.begin(), d.work_since.end(), 0);
  std::fill(d.particles_since.begin(), d.particles_since.end(), 0);
  d.evaluations_counted = 0;
  if (per_particle) d.last_rebalance = d.evaluations;
  Objects o;
  o.arrays = &arrays;
  o.weights = &d.weights;
  if (per_particle && d.mode == Weights::Measured) o.counts = &d;
  o.pass_scale = std::move(scale);
  o.dim = d.dim;
  const unsigned long n = local_count(arrays);
  MPI_Exscan(&n, &o.first, 1, MPI_UNSIGNED_LONG, MPI_SUM, MPI_COMM_WORLD);
  if (rank() == 0) o.first = 0;
  Zoltan_Set_Num_Obj_Fn(d.zz, num_obj, &o);
  Zoltan_Set_Obj_List_Fn(d.zz, obj_list, &o);
  Zoltan_Set_Num_Geom_Fn(d.zz, num_geom, &o);
  Zoltan_Set_Geom_Multi_Fn(d.zz, geom_multi, &o);
  int changes = 0, ngid = 0, nlid = 0, nimp = 0, nexp = 0;
  ZOLTAN_ID_PTR igid = nullptr, ilid = nullptr, egid = nullptr, elid = nullptr;
  int *iproc = nullptr, *ipart = nullptr, *eproc = nullptr, *epart = nullptr;
  check(Zoltan_LB_Partition(d.zz, &changes, &ngid, &nlid, &nimp, &igid, &ilid, &iproc, &ipart,
                            &nexp, &egid, &elid, &eproc, &epart),
        "Zoltan_LB_Partition");
  Zoltan_LB_Free_Part(&igid, &ilid, &iproc, &ipart);
  Zoltan_LB_Free_Part(&egid, &elid, &eproc, &epart);
  d.cut = true;
  ++d.rebalances;
  d.has_region = false;
  if (size() == 1) {
    // One rank owns all space: every position and halo box is inside its region, so
    // migration and the halo take the fast path (no Zoltan query per particle; Zoltan keeps
    // no RCB box for a single part).
    for (int c = 0; c < 3; ++c) {
      d.region_lo[c] = -std::numeric_limits<double>::infinity();
      d.region_hi[c] = std::numeric_limits<double>::infinity();
    }
    d.has_region = true;
  } else if (d.method == "RCB") {
    int ndim = 0;
    double* lo = d.region_lo;
    double* hi = d.region_hi;
    if (Zoltan_RCB_Box(d.zz, rank(), &ndim, &lo[0], &lo[1], &lo[2], &hi[0], &hi[1], &hi[2]) ==
        ZOLTAN_OK)
      d.has_region = true;
  }
  migrate(d, arrays);
}

}  // namespace

void distribute(Decomposition& d, const std::vector<ParticleArray*>& arrays) {
  const std::size_t P = static_cast<std::size_t>(size()), r = static_cast<std::size_t>(rank());
  GlobalIds ids;  // sphc/global_ids.h: unique over all arrays, in set-up order (as --global-ids)
  assign_global_ids(arrays, ids);
  for (ParticleArray* a : arrays) {
    const std::size_t begin = a->n * r / P, end = a->n * (r + 1) / P;
    std::vector<std::uint32_t> order;
    for (std::size_t i = begin; i < end; ++i) order.push_back(static_cast<std::uint32_t>(i));
    for (std::size_t i = 0; i < a->n; ++i)
      if (i < begin || i >= end) order.push_back(static_cast<std::uint32_t>(i));
    a->permute(order);
    a->resize(end - begin);
  }
  rebalance(d, arrays);
}

double imbalance(const std::vector<ParticleArray*>& arrays) {
  const long n = static_cast<long>(local_count(arrays));
  const long total = sum(n), most = max(n);
  const double mean = static_cast<double>(total) / size();
  return mean > 0 ? static_cast<double>(most) / mean : 1.0;
}

double imbalance(const Decomposition& d, const std::vector<ParticleArray*>& arrays) {
  if (d.weights.empty()) return imbalance(arrays);
  double w = 0;
  for (std::size_t k = 0; k < arrays.size(); ++k)
    w += static_cast<double>(arrays[k]->n) * (k < d.weights.size() ? d.weights[k] : 1.0);
  const double total = sum(w), most = max(w);
  const double mean = total / size();
  return mean > 0 ? most / mean : 1.0;
}

long counted_work(const Decomposition& d, const std::vector<ParticleArray*>& arrays) {
  long w = 0;
  for (std::size_t k = 0; k < arrays.size(); ++k) w += array_work(d, k, arrays[k]->n);
  return w;
}

namespace {

// MPI_Allreduce of longs (exact: every rank gets the same sums).
void all_reduce(std::vector<long>& v, MPI_Op op) {
  MPI_Allreduce(MPI_IN_PLACE, v.data(), static_cast<int>(v.size()), MPI_LONG, op,
                MPI_COMM_WORLD);
}

// max / mean of one value per rank, exact sums.
double max_over_mean(long x) {
  std::vector<long> s = {x}, m = {x};
  all_reduce(s, MPI_SUM);
  all_reduce(m, MPI_MAX);
  return s[0] > 0 ? static_cast<double>(m[0]) * size() / static_cast<double>(s[0]) : 1.0;
}

// The measured weight of each array: its particles' counted work over every rank since the
// last re-balance over their number (the estimate where an array had no particles).
std::vector<double> measured_weights(const Decomposition& d, std::size_t arrays) {
  std::vector<long> v(2 * arrays, 0);
  for (std::size_t k = 0; k < arrays; ++k) {
    v[k] = k < d.work_since.size() ? d.work_since[k] : 0;
    v[arrays + k] = k < d.particles_since.size() ? d.particles_since[k] : 0;
  }
  all_reduce(v, MPI_SUM);
  std::vector<double> w(arrays);
  for (std::size_t k = 0; k < arrays; ++k)
    w[k] = v[arrays + k] > 0 ? static_cast<double>(v[k]) / static_cast<double>(v[arrays + k])
                             : (k < d.estimate.size() ? d.estimate[k] * d.particle_cost : 1.0);
  return w;
}

// Per array, the factor on each particle's pass work of the last evaluation (particle_work)
// that gives the array's particles the mean pass work per particle since the last re-balance
// (work_since): a group that runs only in some evaluations (every, condition, iterate) then
// weighs as much as it costs on average, not all or nothing as in the last evaluation. 1 when
// the two means agree; -1 where the last evaluation counted no pass work for the array (its
// measured weight, the mean, for every particle). Collective.
std::vector<double> pass_scales(const Decomposition& d,
                                const std::vector<ParticleArray*>& arrays) {
  const std::size_t K = arrays.size();
  std::vector<long> v(4 * K, 0);  // since: pass work, particles; last: pass work, particles
  for (std::size_t k = 0; k < K; ++k) {
    const long since = k < d.work_since.size() ? d.work_since[k] : 0;
    const long n_since = k < d.particles_since.size() ? d.particles_since[k] : 0;
    v[k] = since - d.particle_cost * n_since;
    v[K + k] = n_since;
    const std::size_t n = arrays[k]->n;
    if (k < d.particle_work.size() && d.pass_n[k] == n && d.particle_work[k].size() >= n) {
      for (std::size_t j = 0; j < n; ++j) v[2 * K + k] += d.particle_work[k][j];
      v[3 * K + k] = static_cast<long>(n);
    }
  }
  all_reduce(v, MPI_SUM);
  std::vector<double> scale(K, 1.0);
  for (std::size_t k = 0; k < K; ++k) {
    if (v[3 * K + k] == 0 || v[K + k] == 0) continue;  // no counts: unchanged
    if (v[2 * K + k] == 0) {
      scale[k] = v[k] > 0 ? -1.0 : 1.0;
      continue;
    }
    if (v[k] * v[3 * K + k] == v[2 * K + k] * v[K + k]) continue;  // the same mean: exactly 1
    scale[k] = (static_cast<double>(v[k]) / static_cast<double>(v[K + k])) /
               (static_cast<double>(v[2 * K + k]) / static_cast<double>(v[3 * K + k]));
  }
  return scale;
}

}  // namespace

void forget_particles(Decomposition& d, std::size_t k, const std::vector<std::uint8_t>& removed) {
  // Counts of another particle set (the array changed since the passes, or none counted):
  // unused already (pass_n differs from the count), left so.
  if (k >= d.particle_work.size() || d.pass_n[k] != removed.size() ||
      d.particle_work[k].size() < removed.size())
    return;
  std::vector<long>& w = d.particle_work[k];
  std::size_t out = 0;
  for (std::size_t i = 0; i < removed.size(); ++i)
    if (!removed[i]) w[out++] = w[i];
  w.resize(out);  // the halo's counts (after the real particles) are not read
  d.pass_n[k] = out;
}

void update(Decomposition& d, const std::vector<ParticleArray*>& arrays) {
  ++d.evaluations;
  // Close the last evaluation's count (the arrays still hold its particles).
  const std::size_t K = arrays.size();
  d.pairs_now.resize(K, 0);
  d.candidates_now.resize(K, 0);
  d.work_since.resize(K, 0);
  d.particles_since.resize(K, 0);
  const bool counted = d.evaluations > 1;  // the first call precedes every pass
  const long work = counted_work(d, arrays);
  if (counted) {
    for (std::size_t k = 0; k < K; ++k) {
      d.work_since[k] += array_work(d, k, arrays[k]->n);
      d.particles_since[k] += static_cast<long>(arrays[k]->n);
    }
    ++d.evaluations_counted;
  }
  std::fill(d.pairs_now.begin(), d.pairs_now.end(), 0);
  std::fill(d.candidates_now.begin(), d.candidates_now.end(), 0);
  const bool scheduled = d.rebalance_every > 0 && d.evaluations % d.rebalance_every == 0;
  if (d.mode == Weights::Measured) {
    // The counted work of the last evaluation; a re-cut on the particles of that evaluation,
    // each weighing its own count, then the migration is the re-cut's.
    bool unbalanced = false;
    if (counted) {
      d.work_imbalance = max_over_mean(work);
      d.work_imbalance_sum += d.work_imbalance;
      ++d.work_imbalance_count;
      unbalanced = !scheduled && d.work_imbalance > d.imbalance_limit &&
                   d.evaluations - d.last_rebalance >= d.min_rebalance_gap;
    }
    if (unbalanced) ++d.imbalance_rebalances;
    if (scheduled || unbalanced) rebalance_with(d, arrays, true);
    else migrate(d, arrays);
  } else {
    migrate(d, arrays);
    if (scheduled || imbalance(d, arrays) > d.imbalance_limit) rebalance(d, arrays);
  }
  for (std::vector<long>& w : d.particle_work) w.clear();  // the passes count anew
}

}  // namespace sphc::mpi
