#include "sema/Plan.h"

#include "frontend/ASTPrinter.h"

#include "llvm/Support/Format.h"

namespace sphc {

int Plan::arrayIndex(const std::string& name) const {
  for (size_t i = 0; i < arrays.size(); ++i)
    if (arrays[i].name == name) return static_cast<int>(i);
  return -1;
}

const PlanProperty* PlanArray::find(const std::string& p) const {
  for (const auto& prop : props)
    if (prop.name == p) return &prop;
  return nullptr;
}

PlanProperty* PlanArray::find(const std::string& p) {
  for (auto& prop : props)
    if (prop.name == p) return &prop;
  return nullptr;
}

namespace {

const char* methodName(ast::Method::Kind k) {
  static const char* names[] = {"initialize", "loop", "post_loop", "reduce", "converged"};
  return names[k];
}

// start_idx, stop_idx, condition (evaluated at run time).
void printGroupRunTimeOptions(const PlanGroup& g, llvm::raw_ostream& os) {
  if (g.startIdx || g.stopIdx) {
    os << " (particles ";
    if (g.startIdx)
      printExpr(*g.startIdx, os);
    else
      os << "0";
    os << " <= d_idx < ";
    if (g.stopIdx)
      printExpr(*g.stopIdx, os);
    else
      os << "n";
    os << ")";
  }
  if (g.condition) {
    os << " (when ";
    printExpr(*g.condition, os);
    os << ")";
  }
}

void printGroup(const Plan& plan, const PlanGroup& g, llvm::raw_ostream& os, int depth,
                bool report) {
  std::string ind(2 * depth, ' ');
  os << ind << "group";
  if (!g.real) os << " (real = false)";
  if (g.iterate)
    os << " (iterate, " << g.minIterations << ".." << g.maxIterations << " iterations)";
  if (g.every) {
    os << " (every ";
    printExpr(*g.every, os);
    os << " steps)";
  }
  if (g.postStep) os << " (after each step)";
  printGroupRunTimeOptions(g, os);
  if (g.updateNnps) os << " (then rebuild the neighbour search)";
  os << "\n";
  for (int entry : g.order) {
    if (entry < 0) {
      printGroup(plan, *g.subgroups[-entry - 1], os, depth + 1, report);
      continue;
    }
    const PlanEquation& eq = plan.equations[g.equations[entry]];
    os << ind << "  " << eq.name << "(dest = "
       << (eq.dest >= 0 ? plan.arrays[eq.dest].name : "?");
    if (!eq.sources.empty()) {
      os << ", sources = [";
      for (size_t i = 0; i < eq.sources.size(); ++i)
        os << (i ? ", " : "") << plan.arrays[eq.sources[i]].name;
      os << "]";
    }
    os << ")";
    if (eq.declIndex >= 0) {
      os << "  {";
      bool first = true;
      for (const auto& [kind, body] : plan.equationDecls[eq.declIndex].methods) {
        os << (first ? "" : ", ") << methodName(kind);
        first = false;
      }
      os << "}";
    }
    if (!eq.live) os << "  PRUNED: " << eq.pruneReason;
    os << "\n";
  }
  for (const auto& [key, qs] : g.pairQuantities) {
    os << ind << "  pair quantities " << plan.arrays[key.first].name << " <- "
       << plan.arrays[key.second].name << ":";
    for (const auto& q : qs) os << " " << q;
    os << "\n";
  }
}

}  // namespace

void printPlan(const Plan& plan, llvm::raw_ostream& os, bool report) {
  os << "scene " << plan.sceneName << ": dim " << plan.dim << ", kernel " << plan.kernel
     << " (radius " << llvm::format("%g", plan.kernelRadiusScale) << " h), integrator "
     << (plan.integratorName.empty() ? "none" : plan.integratorName) << "\n";
  if (!plan.integratorSteps.empty()) {
    os << "time step:";
    for (const auto& s : plan.integratorSteps) os << " " << s << ";";
    os << "\n";
  }
  if (plan.adaptiveDt) os << "adaptive time step: yes\n";
  if (!plan.options.empty()) {
    os << "options:";
    for (const auto& o : plan.options)
      os << " " << o.name << "=" << o.value << (o.fromCommandLine ? " (-D)" : " (default)");
    os << "\n";
  }
  if (plan.domain.any()) {
    static const char* kAxes[3] = {"x", "y", "z"};
    os << "domain:";
    for (int a = 0; a < 3; ++a) {
      const PlanBoundary& lo = plan.domain.lo[a];
      const PlanBoundary& hi = plan.domain.hi[a];
      if (lo.kind == PlanBoundary::Periodic) {
        os << " periodic " << kAxes[a] << ";";
        continue;
      }
      if (lo.kind == PlanBoundary::Mirror) os << " mirror " << kAxes[a] << " low;";
      if (hi.kind == PlanBoundary::Mirror) os << " mirror " << kAxes[a] << " high;";
    }
    os << "\n";
  }
  os << "parameters:";
  for (const auto* p : plan.params)
    if (!p->derived) os << " " << p->name.name;
  os << "\n";
  bool anyDerived = false;
  for (const auto* p : plan.params) anyDerived |= p->derived;
  if (anyDerived) {
    os << "derived (let):";
    for (const auto* p : plan.params)
      if (p->derived) os << " " << p->name.name;
    os << "\n";
  }
  for (const auto& a : plan.arrays) {
    os << "array " << a.name;
    if (a.stepper >= 0) os << " (stepper " << plan.steppers[a.stepper].decl->name.name << ")";
    os << ": " << a.props.size() << " properties\n   ";
    for (const auto& p : a.props) {
      os << " " << p.name;
      if (p.type != "double") os << ":" << p.type;
      if (p.stride != 1) os << "[" << p.stride << "]";
    }
    os << "\n";
    if (!a.ghostProps.empty()) {
      os << "    ghosts carry:";
      for (const auto& p : a.ghostProps) os << " " << p;
      os << "\n";
    }
    if (!a.constants.empty()) {
      os << "    constants:";
      for (const auto& c : a.constants) os << " " << c;
      os << "\n";
    }
  }
  os << "equations:\n";
  printGroup(plan, plan.root, os, 1, report);
  if (report) {
    size_t live = 0;
    for (const auto& eq : plan.equations) live += eq.live;
    os << "summary: " << plan.equations.size() << " equation instances, " << live << " live, "
       << plan.equations.size() - live << " pruned\n";
    for (const auto& n : plan.notes) os << "note: " << n << "\n";
  }
  if (!plan.metrics.empty()) {  // metrics { } (sema/Metrics.cpp)
    static const char* kKinds[] = {"L1", "L2", "Linf", "max", "min", "sum", "mean"};
    os << "metrics:";
    for (const auto& m : plan.metrics) {
      os << " " << m.name << " = " << kKinds[m.kind] << "(" << plan.arrays[m.array].name << ")";
      if (!m.reference.empty()) os << " vs \"" << m.reference << "\"";
      else if (m.exact) os << " vs exact";
      os << (m.relative ? " relative;" : ";");
    }
    os << "\n";
  }
}

}  // namespace sphc
