// Group fusion, a schedule decision: consecutive subgroups of a group run as one phase (one
// neighbour pass per destination and source instead of one per group) where the schedule
// proves that no result bit changes.
//
// Legality. Both groups are plain: direct equations only (no subgroups, no pre/post hooks),
// not iterated, no `every`, `condition`, `post_step`, `start_idx`/`stop_idx` or `update_nnps`,
// the same `real` flag, no reduction and no host `reduce` (whose values feed the host between
// them). Nothing runs between two consecutive subgroups of a group, so the only difference is
// the order of the equations' methods: B's initialize before A's neighbour passes, B's loops
// interleaved with A's over the same neighbours, A's post_loop after B's loops, A's ghost
// refresh after B's work. Per (array, property), from the access analysis (analysis/Access.h,
// every method, implicit reads of the pair quantities included): nothing A writes is read or
// written by B, and nothing B writes is read by A. Then every equation reads the values it
// read without fusion, and each equation's sums run over the same neighbours in the same
// order: the outputs are bitwise those without fusion. A group whose equations are all
// pruned accesses nothing and joins a run freely; a run is fused only when at least two of
// its groups have live equations.
#include "codegen/Schedule.h"

#include "analysis/Access.h"

#include <set>
#include <utility>

namespace sphc {

namespace {

using Key = std::pair<int, std::string>;  // (array, property)

struct GroupAccesses {
  std::set<Key> reads, writes;
};

void addAccesses(const Plan& plan, const PlanGroup& g, GroupAccesses& out) {
  for (int e : g.equations) {
    const PlanEquation& eq = plan.equations[e];
    if (!eq.live) continue;
    for (const Access& a : equationAccesses(plan, eq))
      (a.write ? out.writes : out.reads).insert({a.array, a.prop});
  }
}

bool intersects(const std::set<Key>& a, const std::set<Key>& b) {
  for (const Key& k : a)
    if (b.count(k)) return true;
  return false;
}

bool hasLive(const Plan& plan, const PlanGroup& g) {
  for (int e : g.equations)
    if (plan.equations[e].live) return true;
  return false;
}

}  // namespace

bool fusibleGroup(const Plan& plan, const PlanGroup& g) {
  if (g.iterate || g.every || g.condition || g.postStep || g.startIdx || g.stopIdx ||
      g.updateNnps || !g.subgroups.empty())
    return false;
  // --mpi: a real = false phase with neighbour loops leaves the halo to a refresh
  // (Schedule.cpp); joining it with per-particle work on the halo would change where that
  // work runs.
  if (!g.real && plan.distributed) return false;
  for (int e : g.equations) {
    const PlanEquation& eq = plan.equations[e];
    if (eq.hook) return false;
    if (!eq.live || eq.declIndex < 0) continue;
    const auto& methods = plan.equationDecls[eq.declIndex].methods;
    if (methods.count(ast::Method::Reduce) || methods.count(ast::Method::HostReduce) ||
        methods.count(ast::Method::Converged))
      return false;
  }
  return true;
}

std::vector<std::vector<int>> groupFusionRuns(const Plan& plan, const PlanGroup& parent) {
  std::vector<std::vector<int>> runs;  // order positions
  const auto& order = parent.order;
  for (size_t i = 0; i < order.size();) {
    std::vector<int> run = {static_cast<int>(i)};
    if (order[i] < 0) {
      const PlanGroup& first = *parent.subgroups[-order[i] - 1];
      if (fusibleGroup(plan, first)) {
        GroupAccesses acc;
        addAccesses(plan, first, acc);
        for (size_t j = i + 1; j < order.size() && order[j] < 0; ++j) {
          const PlanGroup& next = *parent.subgroups[-order[j] - 1];
          if (!fusibleGroup(plan, next) || next.real != first.real) break;
          GroupAccesses b;
          addAccesses(plan, next, b);
          if (intersects(acc.writes, b.reads) || intersects(acc.writes, b.writes) ||
              intersects(b.writes, acc.reads))
            break;
          acc.reads.insert(b.reads.begin(), b.reads.end());
          acc.writes.insert(b.writes.begin(), b.writes.end());
          run.push_back(static_cast<int>(j));
        }
        // Trailing pruned groups stay on their own (nothing to gain), and a run with a
        // single live group is no fusion.
        while (run.size() > 1 && !hasLive(plan, *parent.subgroups[-order[run.back()] - 1]))
          run.pop_back();
        int live = 0;
        for (int k : run) live += hasLive(plan, *parent.subgroups[-order[k] - 1]);
        if (live < 2) run.resize(1);
      }
    }
    i += run.size();
    runs.push_back(std::move(run));
  }
  return runs;
}

}  // namespace sphc
