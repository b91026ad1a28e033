// The schedule of a distributed run (sphc --mpi; codegen/Schedule.h, Distribution): which
// arrays migrate and what each source array's halo carries, and its lines in
// `--dump-after=schedule`. Kept apart from Schedule.cpp so that the serial schedule reads as
// before.
#include "codegen/ScheduleDistribution.h"

#include "llvm/Support/Format.h"

namespace sphc {

namespace {

// The work of a particle of each array, estimated from the equations (the first cut's
// weights; later cuts use the work the passes count, unless SPHC_MPI_WEIGHTS=estimated): 1
// (its per-particle work: steppers, initialize) plus one per neighbour pass it is the
// destination of (each live equation with a loop or loop_all, once per source array it
// lists). A wall that only sums
// a density from the fluid weighs little next to a fluid particle with pressure, viscosity
// and diffusion loops over fluid and walls, so RCB splits the work, not the particle count.
std::vector<double> workWeights(const Plan& plan) {
  std::vector<double> w(plan.arrays.size(), 1.0);
  for (const PlanEquation& e : plan.equations) {
    if (!e.live || e.dest < 0 || e.declIndex < 0) continue;
    bool pairs = false;
    for (const auto& [kind, body] : plan.equationDecls[e.declIndex].methods)
      pairs |= kind == ast::Method::Loop || kind == ast::Method::LoopAll;
    if (pairs) w[e.dest] += static_cast<double>(e.sources.size());
  }
  return w;
}

}  // namespace

Distribution distributionOf(const Plan& plan, const std::vector<int>& cellLists) {
  Distribution d;
  d.enabled = plan.distributed;
  if (!d.enabled) return d;
  for (int a = 0; a < static_cast<int>(plan.arrays.size()); ++a) d.migrate.push_back(a);
  for (int a : cellLists) d.halo.push_back({a, plan.arrays[a].ghostProps});
  d.weights = workWeights(plan);
  return d;
}

void printDistribution(const Schedule& s, llvm::raw_ostream& os) {
  const Distribution& d = s.distribution;
  if (!d.enabled) return;
  const Plan& p = *s.plan;
  os << "distributed (MPI): Zoltan " << d.method << ", re-balance every " << d.rebalanceEvery
     << " evaluations or when max/mean work (weighted particles) per rank > "
     << llvm::format("%g", d.imbalanceLimit) << "\n";
  os << "  particle weights (work estimate: 1 + neighbour passes as destination):";
  for (size_t a = 0; a < d.weights.size(); ++a)
    os << " " << p.arrays[a].name << "=" << llvm::format("%g", d.weights[a]);
  os << "\n";
  os << "  then measured: each neighbour pass counts candidates, pairs x loops per destination array "
        "(sphc/mpi/decomposition.h, count_work)\n";
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
