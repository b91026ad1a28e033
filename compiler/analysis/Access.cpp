#include "analysis/Access.h"

namespace sphc {

std::vector<std::string> positionProps(int dim) {
  std::vector<std::string> p = {"x", "y", "z"};
  p.resize(dim);
  return p;
}

static void addBodyAccesses(std::vector<Access>& out, const BodyFacts& f, int dest,
                            const std::vector<int>& sources, const Access& proto) {
  auto add = [&](int array, const auto& ref, bool write, bool viaSource) {
    Access a = proto;
    a.array = array;
    a.prop = ref.prop;
    a.loc = ref.loc;
    a.write = write;
    a.viaSource = viaSource;
    out.push_back(a);
  };
  for (const auto& r : f.dReads) add(dest, r, false, false);
  for (const auto& w : f.dWrites) add(dest, w, true, false);
  for (int s : sources)
    for (const auto& r : f.sReads) add(s, r, false, true);
}

std::vector<Access> equationAccesses(const Plan& plan, const PlanEquation& eq) {
  std::vector<Access> out;
  if (eq.declIndex < 0) return out;
  const PlanEquationDecl& pd = plan.equationDecls[eq.declIndex];
  for (const auto& [kind, bodyIdx] : pd.methods) {
    const BodyFacts& f = plan.bodies[bodyIdx].facts;
    Access proto;
    proto.equation = eq.id;
    proto.method = kind;
    addBodyAccesses(out, f, eq.dest, ast::seesSources(kind) ? eq.sources : std::vector<int>{},
                    proto);
    if (kind != ast::Method::Loop && kind != ast::Method::LoopAll) continue;
    // What the generated neighbour loop reads for this body (loop_all: the neighbour test).
    std::vector<std::string> implicitProps = pairQuantityProps(
        plan.dim, pairQuantityClosure(kind == ast::Method::Loop ? f.pairQuantities
                                                                : std::set<std::string>{}));
    std::vector<int> arrays = eq.sources;
    arrays.push_back(eq.dest);
    for (int a : arrays)
      for (const auto& p : implicitProps) {
        Access acc = proto;
        acc.array = a;
        acc.prop = p;
        acc.loc = eq.loc;
        acc.implicit = true;
        acc.viaSource = a != eq.dest;
        out.push_back(acc);
      }
  }
  return out;
}

std::vector<Access> stepperAccesses(const Plan& plan, int a) {
  std::vector<Access> out;
  const PlanArray& arr = plan.arrays[a];
  if (arr.stepper < 0) return out;
  for (const auto& [name, bodyIdx] : plan.steppers[arr.stepper].methods) {
    Access proto;
    proto.stepperMethod = name;
    addBodyAccesses(out, plan.bodies[bodyIdx].facts, a, {}, proto);
  }
  return out;
}

}  // namespace sphc
