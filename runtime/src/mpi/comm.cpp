// sphc runtime, distributed runs: see sphc/mpi/comm.h.
#include "sphc/mpi/comm.h"

#include <mpi.h>

#include <cstdio>
#include <cstdlib>

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
