// sphc runtime, distributed runs (--mpi): the MPI session, global reductions and stopping the
// whole job.
//
// A solver built with `sphc --mpi` runs as one process per rank (`mpirun -np P ./scene`). Every
// rank runs the same time loop (sphc/solver.h) on its own particles; what must agree between
// ranks goes through these functions:
//   - reductions of the scene (`reduce` sum, mean, max, min), the adaptive time step (a min)
//     and the convergence of iterated groups (converged on every rank) are MPI_Allreduce, so
//     every rank takes the same dt and the same number of iterations;
//   - a rank that stops with an error (an exception, a blow-up, bad usage) ends the whole job
//     with MPI_Abort after printing its message (finish), so no rank waits forever in a
//     collective for a rank that has gone.
// Only built when CMake finds MPI (libsphc_mpi.a); a solver without --mpi never includes it.
#pragma once

#include <cstdint>
#include <string>

#include "sphc/metrics.h"

namespace sphc::mpi {

// MPI_Init in the constructor, MPI_Finalize in the destructor (generated main holds one).
struct Session {
  Session(int* argc, char*** argv);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
};

int rank();
int size();

// MPI_Allreduce over MPI_COMM_WORLD.
double sum(double x);
double min(double x);
double max(double x);
long sum(long x);
long max(long x);
// True on every rank iff `x` is true on every rank (an iterated group's convergence).
bool all(bool x);

// A metric's sums over every rank's particles (metrics { }): each rank's sums are gathered
// to every rank (MPI_Allgather) and combined in rank order with the serial rules (NaN stays
// NaN in max/min; the compensated sums and their compensations added with Neumaier's
// method), so every rank holds the same result and a metric differs from the serial run's
// only by the order of its sums. Collective.
void all_reduce(NormSums& s);
void all_reduce(ScalarSums& s);
// A profile's least-squares sums at its points, added over the ranks in rank order.
void all_reduce(ProfileFit& f);

// The exit of a rank's run_main: 0 returns 0 (after a barrier); any other code prints a line
// naming the rank and ends every rank of the job with MPI_Abort(code) (does not return).
int finish(int rc);

// Ends the job at once from any rank, with a message naming the rank.
[[noreturn]] void abort_job(int code, const std::string& why);

}  // namespace sphc::mpi
