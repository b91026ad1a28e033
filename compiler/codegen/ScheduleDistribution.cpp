// The schedule of a distributed run (sphc --mpi; codegen/Schedule.h, Distribution): which
// arrays migrate and what each source array's halo carries, and its lines in
// `--dump-after=schedule`. Kept apart from Schedule.cpp so that the serial schedule reads as
// before.
#include "codegen/ScheduleDistribution.h"

#include "llvm/Support/Format.h"

namespace sphc {

Distribution distributionOf(const Plan& plan, const std::vector<int>& cellLists) {
  Distribution d;
  d.enabled = plan.distributed;
  if (!d.enabled) return d;
  for (int a = 0; a < static_cast<int>(plan.arrays.size()); ++a) d.migrate.push_back(a);
  for (int a : cellLists) d.halo.push_back({a, plan.arrays[a].ghostProps});
  return d;
}

void printDistribution(const Schedule& s, llvm::raw_ostream& os) {
  const Distribution& d = s.distribution;
  if (!d.enabled) return;
  const Plan& p = *s.plan;
  os << "distributed (MPI): Zoltan " << d.method << ", re-balance every " << d.rebalanceEvery
     << " evaluations or when max/mean particles per rank > "
     << llvm::format("%g", d.imbalanceLimit) << "\n";
  os << "  update_neighbours starts with: migrate";
  for (int a : d.migrate) os << " " << p.arrays[a].name;
  os << " (every property, global id gid)\n";
  for (const auto& [a, props] : d.halo) {
    os << "  halo exchange of " << p.arrays[a].name << " (replaces its ghosts), sends:";
    for (const auto& q : props) os << " " << q;
    os << "\n";
  }
  os << "  global (MPI_Allreduce): reductions, adaptive dt, converged of iterated groups\n";
  os << "  output: parallel HDF5 (collective, gid order), or gathered to rank 0 without it\n";
}

}  // namespace sphc
