// The pair-quantity pass: per group and (destination, source), the pair quantities its
// neighbour loop computes: the closure (analysis/PairQuantityTable.h) of those the loop
// bodies of the group's live equations use.
#include "analysis/Access.h"
#include "analysis/PairQuantityTable.h"
#include "analysis/Passes.h"

namespace sphc {

namespace {

void selectGroup(Plan& plan, PlanGroup& g) {
  g.pairQuantities.clear();
  for (int e : g.equations) {
    const PlanEquation& eq = plan.equations[e];
    if (!eq.live) continue;
    const auto& pd = plan.equationDecls[eq.declIndex];
    auto it = pd.methods.find(ast::Method::Loop);
    if (it == pd.methods.end()) continue;
    std::set<std::string> q = pairQuantityClosure(plan.bodies[it->second].facts.pairQuantities);
    for (int s : eq.sources) g.pairQuantities[{eq.dest, s}].insert(q.begin(), q.end());
  }
  for (auto& sub : g.subgroups) selectGroup(plan, *sub);
}

}  // namespace

bool selectPairQuantities(Plan& plan, DiagnosticEngine&) {
  selectGroup(plan, plan.root);
  return true;
}

}  // namespace sphc
