// sphc runtime, distributed runs: see sphc/mpi/comm.h.
#include "sphc/mpi/comm.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace sphc::mpi {

Session::Session(int* argc, char*** argv) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) MPI_Init(argc, argv);
}

Session::~Session() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized) MPI_Finalize();
}

int rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

int size() {
  int s = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &s);
  return s;
}

namespace {
template <class T>
T reduce(T x, MPI_Datatype type, MPI_Op op) {
  T out{};
  MPI_Allreduce(&x, &out, 1, type, op, MPI_COMM_WORLD);
  return out;
}
}  // namespace

double sum(double x) { return reduce(x, MPI_DOUBLE, MPI_SUM); }
double min(double x) { return reduce(x, MPI_DOUBLE, MPI_MIN); }
double max(double x) { return reduce(x, MPI_DOUBLE, MPI_MAX); }
long sum(long x) { return reduce(x, MPI_LONG, MPI_SUM); }
long max(long x) { return reduce(x, MPI_LONG, MPI_MAX); }
bool all(bool x) { return reduce(x ? 1 : 0, MPI_INT, MPI_MIN) == 1; }

namespace {
// Every rank's `k` doubles, in rank order, on every rank.
std::vector<double> all_gather(const double* mine, int k) {
  std::vector<double> all(static_cast<std::size_t>(k) * static_cast<std::size_t>(size()));
  MPI_Allgather(mine, k, MPI_DOUBLE, all.data(), k, MPI_DOUBLE, MPI_COMM_WORLD);
  return all;
}

double nan_max(double a, double b) {
  return std::isnan(a) || std::isnan(b) ? kNoValue : std::max(a, b);
}
double nan_min(double a, double b) {
  return std::isnan(a) || std::isnan(b) ? kNoValue : std::min(a, b);
}

// Neumaier: adds v to (sum, c).
void add_compensated(double& sum, double& c, double v) {
  const double t = sum + v;
  c += std::fabs(sum) >= std::fabs(v) ? (sum - t) + v : (v - t) + sum;
  sum = t;
}
}  // namespace

void all_reduce(NormSums& s) {
  const double mine[7] = {s.err_abs, s.err_sq, s.err_max, s.ref_abs,
                          s.ref_sq,  s.ref_max, static_cast<double>(s.n)};
  const std::vector<double> all = all_gather(mine, 7);
  NormSums r;
  for (std::size_t k = 0; k + 7 <= all.size(); k += 7) {
    r.err_abs += all[k];
    r.err_sq += all[k + 1];
    r.err_max = nan_max(r.err_max, all[k + 2]);
    r.ref_abs += all[k + 3];
    r.ref_sq += all[k + 4];
    r.ref_max = std::max(r.ref_max, all[k + 5]);
    r.n += static_cast<long>(all[k + 6]);
  }
  s = r;
}

void all_reduce(ScalarSums& s) {
  const double mine[5] = {s.max, s.min, s.sum, s.compensation, static_cast<double>(s.n)};
  const std::vector<double> all = all_gather(mine, 5);
  ScalarSums r;
  for (std::size_t k = 0; k + 5 <= all.size(); k += 5) {
    r.max = nan_max(r.max, all[k]);
    r.min = nan_min(r.min, all[k + 1]);
    add_compensated(r.sum, r.compensation, all[k + 2]);
    add_compensated(r.sum, r.compensation, all[k + 3]);
    r.n += static_cast<long>(all[k + 4]);
  }
  s = r;
}

void all_reduce(ProfileFit& f) {
  const std::size_t n = f.sums.size();
  if (n == 0) return;
  const std::vector<double> all = all_gather(f.sums.data(), static_cast<int>(n));
  std::fill(f.sums.begin(), f.sums.end(), 0.0);
  for (std::size_t k = 0; k + n <= all.size(); k += n)
    for (std::size_t i = 0; i < n; ++i) f.sums[i] += all[k + i];
}

int finish(int rc) {
  if (rc == 0) {
    MPI_Barrier(MPI_COMM_WORLD);
    return 0;
  }
  abort_job(rc, "the solver stopped with exit code " + std::to_string(rc) +
                    " (its message is above); stopping every rank");
}

void abort_job(int code, const std::string& why) {
  std::fprintf(stderr, "error: rank %d of %d: %s\n", rank(), size(), why.c_str());
  std::fflush(stderr);
  MPI_Abort(MPI_COMM_WORLD, code);
  std::abort();  // MPI_Abort does not return; this keeps [[noreturn]] honest
}

}  // namespace sphc::mpi
