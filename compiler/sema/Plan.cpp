#include "sema/Plan.h"

#include <algorithm>

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

void namesOf(const ast::Expr& e, std::set<std::string>& out) {
  if (e.kind == ast::Expr::Name) out.insert(e.text);
  for (const auto& a : e.args)
    if (a) namesOf(*a, out);
}

std::set<std::string> initialValueInputs(
    const ast::ArrayDecl& a, const std::function<bool(const std::string&)>& allocated) {
  // Backwards through the declarations: a property whose value is needed (allocated, or read
  // by a later needed one) needs the earlier properties its initial value names.
  std::set<std::string> needed, inputs;
  const auto& ps = a.properties;
  for (size_t i = ps.size(); i-- > 0;) {
    const auto& p = ps[i];
    bool own = allocated(p.name.name);
    if (!own && !needed.count(p.name.name)) continue;
    if (!own) inputs.insert(p.name.name);
    if (!p.init) continue;
    std::set<std::string> names;
    namesOf(*p.init, names);
    for (size_t j = 0; j < i; ++j)
      if (names.count(ps[j].name.name)) needed.insert(ps[j].name.name);
  }
  return inputs;
}

namespace {

const char* methodName(ast::Method::Kind k) {
  return ast::methodKeyword(k);
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

int bytesPerParticle(const PlanArray& a) {
  int bytes = 0;
  for (const auto& p : a.props) bytes += (p.type == "double" ? 8 : 4) * p.stride;
  return bytes;
}

// A line of a --report's array or effect: "    LABEL: a b c", nothing when there is nothing.
template <class Names>
void printList(llvm::raw_ostream& os, const char* label, const Names& names) {
  if (names.empty()) return;
  os << "    " << label << ":";
  for (const auto& n : names) os << " " << n;
  os << "\n";
}

// The scene's effects (docs/effects.md): on or off, and what an effect that is off left out.
void printEffects(const Plan& plan, llvm::raw_ostream& os) {
  bool any = false;
  for (const auto& o : plan.options) any |= o.isEffect;
  if (!any) return;
  os << "effects:\n";
  for (const auto& o : plan.options) {
    if (!o.isEffect) continue;
    os << "  " << o.name << ": " << o.value
       << (o.fromCommandLine ? " (-D)" : o.fromScene ? " (the scene's effects)" : " (not listed)");
    if (!o.doc.empty()) os << "  -- " << o.doc;
    os << "\n";
    if (o.on()) continue;
    if (!o.droppedEquations.empty()) {
      os << "    left out (effect off): ";
      for (size_t i = 0; i < o.droppedEquations.size(); ++i)
        os << (i ? ", " : "") << o.droppedEquations[i];
      os << "\n";
    }
    printList(os, "properties left out", o.droppedProperties);
    printList(os, "params left out (--set is an error naming the effect)", o.params);
  }
}

// Per array: the effects its live equations belong to, and the equations kept.
void printArrayEffects(const Plan& plan, const PlanArray& a, llvm::raw_ostream& os) {
  int index = plan.arrayIndex(a.name);
  std::vector<std::string> effects, kept;
  for (const auto& eq : plan.equations) {
    if (eq.dest != index || !eq.live) continue;
    if (std::find(kept.begin(), kept.end(), eq.name) == kept.end()) kept.push_back(eq.name);
    for (const auto& e : eq.effects)
      if (std::find(effects.begin(), effects.end(), e) == effects.end()) effects.push_back(e);
  }
  printList(os, "effects simulated", effects);
  printList(os, "equations kept", kept);
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
  bool anyOption = false;
  for (const auto& o : plan.options) anyOption |= !o.isEffect;
  if (anyOption) {
    os << "options:";
    for (const auto& o : plan.options)
      if (!o.isEffect)
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
  for (const auto& z : plan.zones) {  // inlets and outlets (sema/Zones.cpp)
    auto ex = [&](const ast::ExprPtr& e) {
      if (e) printExpr(*e, os);
      else os << "0";
    };
    os << (z.inlet ? "inlet " : "outlet ") << z.name << ": " << plan.arrays[z.array].name
       << (z.inlet ? " -> " : " <- ") << plan.arrays[z.other].name << "; face (";
    for (int k = 0; k < plan.dim; ++k) {
      if (k) os << ", ";
      ex(z.point[k]);
    }
    os << "), normal (";
    for (int k = 0; k < plan.dim; ++k) {
      if (k) os << ", ";
      ex(z.normal[k]);
    }
    os << "), length ";
    ex(z.length);
    if (z.width) {
      os << ", width ";
      ex(z.width);
    }
    if (z.inlet) {
      os << "; velocity";
      const char* sep = " ";
      for (int k = 0; k < 3; ++k)
        if (z.velocity[k]) {
          os << sep << "uvw"[k] << " = ";
          ex(z.velocity[k]);
          sep = ", ";
        }
      if (*sep == ' ') os << " kept";
    } else {
      os << "; type " << z.type;
      if (z.c) {
        os << " (c = ";
        ex(z.c);
        if (z.pRef) os << ", p_ref = ", ex(z.pRef);
        if (z.tau) os << ", tau = ", ex(z.tau);
        os << ")";
      }
    }
    os << "; copies ";
    if (z.copy.empty()) os << "every common property";
    for (size_t i = 0; i < z.copy.size(); ++i) os << (i ? " " : "") << z.copy[i];
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
  if (report) printEffects(plan, os);
  for (const auto& a : plan.arrays) {
    os << "array " << a.name;
    if (a.stepper >= 0) os << " (stepper " << plan.steppers[a.stepper].decl->name.name << ")";
    os << ": " << a.props.size() << " properties";
    if (report) os << ", " << bytesPerParticle(a) << " bytes per particle (in double precision)";
    os << "\n   ";
    for (const auto& p : a.props) {
      os << " " << p.name;
      if (p.type != "double") os << ":" << p.type;
      if (p.stride != 1) os << "[" << p.stride << "]";
    }
    os << "\n";
    if (report) printArrayEffects(plan, a, os);
    printList(os, "ghosts carry", a.ghostProps);
    printList(os, "constants", a.constants);
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
      if (m.isProfile()) os << " profile vs \"" << m.reference << "\"";
      else if (!m.reference.empty()) os << " vs \"" << m.reference << "\"";
      else if (m.exact) os << " vs exact";
      os << (m.relative ? " relative;" : ";");
    }
    os << "\n";
  }
}

}  // namespace sphc
