#include "analysis/Access.h"
#include "analysis/Passes.h"
#include "analysis/PlanQueries.h"

#include <functional>
#include <set>

namespace sphc {

// Array constants (`arr.c`) that group options read at run time (start_idx, stop_idx,
// condition): roots of liveness, as what a stepper reads.
static void groupOptionReads(const Plan& plan, const PlanGroup& g,
                             std::set<std::pair<int, std::string>>& live) {
  std::function<void(const ast::Expr&)> walk = [&](const ast::Expr& e) {
    size_t dot = e.kind == ast::Expr::Name ? e.text.find('.') : std::string::npos;
    if (dot != std::string::npos) {
      int a = plan.arrayIndex(e.text.substr(0, dot));
      if (a >= 0) live.insert({a, e.text.substr(dot + 1)});
    }
    for (const auto& x : e.args)
      if (x) walk(*x);
  };
  for (const auto* e : {g.startIdx.get(), g.stopIdx.get(), g.condition.get()})
    if (e) walk(*e);
  for (const auto& sub : g.subgroups) groupOptionReads(plan, *sub, live);
}

bool pruneEquations(Plan& plan, DiagnosticEngine&) {
  using Key = std::pair<int, std::string>;
  std::set<Key> live;
  // Roots: what steppers read, what is output, what the adaptive time step reads.
  for (int a = 0; a < static_cast<int>(plan.arrays.size()); ++a) {
    for (const auto& acc : stepperAccesses(plan, a))
      if (!acc.write) live.insert({a, acc.prop});
    for (const auto& p : plan.arrays[a].outputProps) live.insert({a, p});
    if (movesParticles(plan, a))
      for (const auto& p : adaptiveDtProps(plan)) live.insert({a, p});
  }
  groupOptionReads(plan, plan.root, live);
  std::vector<std::vector<Access>> accesses;
  for (const auto& eq : plan.equations) accesses.push_back(equationAccesses(plan, eq));
  std::vector<bool> isLive(plan.equations.size(), false);
  // An equation with a convergence test steers its group: it is always live.
  for (const auto& eq : plan.equations)
    if (eq.hook || (eq.declIndex >= 0 &&
                    plan.equationDecls[eq.declIndex].methods.count(ast::Method::Converged)))
      isLive[eq.id] = true;
  auto addReads = [&](int e) {
    for (const auto& acc : accesses[e])
      if (!acc.write) live.insert({acc.array, acc.prop});
  };
  for (size_t e = 0; e < plan.equations.size(); ++e)
    if (isLive[e]) addReads(static_cast<int>(e));
  // Fixpoint: an equation that writes something live is live, and so is what it reads.
  for (bool changed = true; changed;) {
    changed = false;
    for (size_t e = 0; e < plan.equations.size(); ++e) {
      if (isLive[e]) continue;
      const PlanEquation& eq = plan.equations[e];
      bool writesLive = false;
      for (const auto& acc : accesses[e])
        writesLive |= acc.write && live.count({acc.array, acc.prop});
      if (eq.declIndex >= 0) {
        const auto& pd = plan.equationDecls[eq.declIndex];
        if (!pd.reduceTarget.empty()) writesLive |= live.count({eq.dest, pd.reduceTarget}) != 0;
      }
      if (!writesLive) continue;
      isLive[e] = changed = true;
      addReads(static_cast<int>(e));
    }
  }
  for (auto& eq : plan.equations) {
    eq.live = isLive[eq.id];
    if (eq.live) continue;
    std::set<std::string> writes;
    for (const auto& acc : accesses[eq.id])
      if (acc.write) writes.insert(acc.prop);
    std::string w;
    for (const auto& p : writes) w += (w.empty() ? "" : ", ") + p;
    if (eq.declIndex >= 0 && !plan.equationDecls[eq.declIndex].reduceTarget.empty())
      w += (w.empty() ? "" : ", ") + plan.equationDecls[eq.declIndex].reduceTarget;
    eq.pruneReason = "it writes " + (w.empty() ? std::string("nothing") : w) + " of '" +
                     plan.arrays[eq.dest].name +
                     "', which no stepper, output, time-step limit or convergence test uses";
    plan.notes.push_back("pruned " + eq.name + "(dest = " + plan.arrays[eq.dest].name +
                         "): " + eq.pruneReason);
  }
  return true;
}

}  // namespace sphc
