// The ghost pass: with a periodic or mirror domain, the properties that ghost copies of each
// array's particles must carry. A ghost is read as a neighbour (source) by every loop over its
// array, and is a destination only of groups with `real = false`; so it carries
//   - what the neighbour loop reads of a source: positions, h, what its pair quantities read
//     (pairQuantityProps: velocities for VIJ, rho for RHOIJ) and every s_ property the loop
//     bodies read;
//   - for groups with `real = false` whose destination it is: every d_ property their bodies
//     read, and what their neighbour loops read of the destination.
// Properties a `real = false` group writes on ghosts need only storage, which every
// property has. Arrays that are no source of any loop get no ghosts.
#include "analysis/Access.h"
#include "analysis/Passes.h"

#include <set>

namespace sphc {

namespace {

void collect(const Plan& plan, const PlanGroup& g, std::vector<std::set<std::string>>& carry,
             std::vector<bool>& isSource) {
  for (int e : g.equations) {
    const PlanEquation& eq = plan.equations[e];
    if (!eq.live || eq.declIndex < 0) continue;
    const PlanEquationDecl& pd = plan.equationDecls[eq.declIndex];
    auto loop = pd.methods.find(ast::Method::Loop);
    if (loop != pd.methods.end()) {
      const BodyFacts& f = plan.bodies[loop->second].facts;
      for (int s : eq.sources) {
        isSource[s] = true;
        std::set<std::string> q;
        auto it = g.pairQuantities.find({eq.dest, s});
        if (it != g.pairQuantities.end()) q = it->second;
        for (const auto& p : pairQuantityProps(plan.dim, q)) carry[s].insert(p);
        for (const auto& r : f.sReads) carry[s].insert(r.prop);
      }
    }
    // loop_all (and its neighbour test: positions and h) and initialize_pair read sources
    // too; initialize_pair searches no neighbours, so its sources get ghosts only when a
    // loop or loop_all searches them.
    for (ast::Method::Kind k : {ast::Method::LoopAll, ast::Method::InitializePair}) {
      auto m = pd.methods.find(k);
      if (m == pd.methods.end()) continue;
      for (int s : eq.sources) {
        for (const auto& r : plan.bodies[m->second].facts.sReads) carry[s].insert(r.prop);
        if (k != ast::Method::LoopAll) continue;
        isSource[s] = true;
        for (const auto& p : pairQuantityProps(plan.dim, {})) carry[s].insert(p);
      }
    }
    if (g.real) continue;
    // A `real = false` group also runs on the ghosts of its destination.
    for (const auto& [kind, b] : pd.methods)
      for (const auto& r : plan.bodies[b].facts.dReads) carry[eq.dest].insert(r.prop);
    for (const auto& [key, q] : g.pairQuantities)
      if (key.first == eq.dest)
        for (const auto& p : pairQuantityProps(plan.dim, q)) carry[eq.dest].insert(p);
  }
  for (const auto& sub : g.subgroups) collect(plan, *sub, carry, isSource);
}

}  // namespace

bool selectGhostProperties(Plan& plan, DiagnosticEngine&) {
  for (auto& a : plan.arrays) a.ghostProps.clear();
  // --mpi: the halo of remote particles carries the same, with or without a domain.
  if (!plan.domain.any() && !plan.distributed) return true;
  std::vector<std::set<std::string>> carry(plan.arrays.size());
  std::vector<bool> isSource(plan.arrays.size(), false);
  collect(plan, plan.root, carry, isSource);
  for (size_t a = 0; a < plan.arrays.size(); ++a) {
    if (!isSource[a]) continue;
    PlanArray& arr = plan.arrays[a];
    // In the array's property order; constants are shared by all particles, not copied.
    for (const auto& p : arr.props)
      if (carry[a].count(p.name)) arr.ghostProps.push_back(p.name);
  }
  return true;
}

}  // namespace sphc
