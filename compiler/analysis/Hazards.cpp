#include "analysis/Access.h"
#include "analysis/Passes.h"

namespace sphc {

namespace {

// Checks the direct members of one group, then its subgroups.
void checkGroup(const Plan& plan, const PlanGroup& g, DiagnosticEngine& diags) {
  std::vector<std::vector<Access>> acc;
  for (int e : g.equations) acc.push_back(equationAccesses(plan, plan.equations[e]));
  for (size_t i = 0; i < g.equations.size(); ++i) {
    const PlanEquation& reader = plan.equations[g.equations[i]];
    if (!reader.live) continue;
    for (const auto& r : acc[i]) {
      if (r.write || !r.viaSource || r.implicit || !ast::seesSources(r.method)) continue;
      for (size_t j = 0; j < g.equations.size(); ++j) {
        const PlanEquation& writer = plan.equations[g.equations[j]];
        if (!writer.live) continue;
        for (const auto& w : acc[j]) {
          if (!w.write || w.array != r.array || w.prop != r.prop) continue;
          // For the reader's own destination, every `initialize` of the group finishes before
          // its loops start and every `post_loop` starts after they end: no hazard. Only
          // writes made while loops run, or to another destination (whose turn may come
          // before or after), make the result order dependent.
          if (writer.dest == reader.dest && !ast::seesSources(w.method)) continue;
          const std::string& arr = plan.arrays[r.array].name;
          diags.error(r.loc, "equation '" + reader.name + "' reads 's_" + r.prop + "' of '" +
                                 arr + "' in its " +
                                 ast::methodKeyword(r.method) + ", but " +
                                 (i == j ? std::string("it also writes")
                                         : "equation '" + writer.name + "' writes") +
                                 " '" + r.prop + "' of '" + arr +
                                 "' in the same group: the result would depend on the order "
                                 "in which particles are processed");
          diags.note(w.loc, "'" + r.prop + "' is written here; split the group so that this "
                            "write happens in a group before the loop that reads it");
          diags.note(reader.loc, "the reading equation is used here");
          if (i != j) diags.note(writer.loc, "the writing equation is used here, in the same group");
          goto nextRead;
        }
      }
    nextRead:;
    }
  }
  for (const auto& sub : g.subgroups) checkGroup(plan, *sub, diags);
}

}  // namespace

bool checkHazards(Plan& plan, DiagnosticEngine& diags) {
  unsigned before = diags.errorCount();
  checkGroup(plan, plan.root, diags);
  return diags.errorCount() == before;
}

}  // namespace sphc
