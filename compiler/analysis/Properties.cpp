#include "analysis/Access.h"
#include "analysis/Passes.h"
#include "analysis/PlanQueries.h"

#include <map>
#include <regex>
#include <set>

namespace sphc {

namespace {

// The first metric of array a that reads property p (metrics { }), or null.
const PlanMetric* metricReading(const Plan& plan, int a, const std::string& p) {
  for (const auto& m : plan.metrics)
    if (m.array == a && std::find(m.reads.begin(), m.reads.end(), p) != m.reads.end()) return &m;
  return nullptr;
}

bool isConstant(const PlanArray& a, const std::string& name) {
  return std::find(a.constants.begin(), a.constants.end(), name) != a.constants.end();
}

// The element type of `name` in array `a` once its properties are known: constants and
// properties nobody declares are doubles.
std::string elementType(const PlanArray& a, const std::string& name) {
  if (isConstant(a, name)) return "double";
  const PlanProperty* p = a.find(name);
  return p ? p->type : "double";
}

std::string typeWords(const std::string& type) {
  return type == "int" ? "an int" : type == "uint" ? "a uint" : "a double";
}

// A body is one function, checked by Clang and emitted once, with one type per d_/s_ property
// (BodySource::props, by property name). Every array the body sees a property of must store it
// as that type, or the generated code would not build: a located error otherwise. Also,
// `converged` runs once per iteration, not per particle: it may write array constants only.
void checkBodyTypes(const Plan& plan, DiagnosticEngine& diags) {
  std::set<std::pair<int, std::string>> reported;  // (body, d_/s_ name)
  auto check = [&](int bodyIdx, const std::vector<PropAccess>& accesses, const char* prefix,
                   const std::vector<int>& arrays) {
    const PlanBody& b = plan.bodies[bodyIdx];
    for (const auto& acc : accesses) {
      auto shape = b.source.props.find(acc.prop);
      const std::string checked = shape == b.source.props.end() ? "double" : shape->second.type;
      // An array of this body with the checked type, to name in the message.
      const PlanArray* same = nullptr;
      for (int a : arrays)
        if (!same && elementType(plan.arrays[a], acc.prop) == checked) same = &plan.arrays[a];
      for (int a : arrays) {
        const PlanArray& arr = plan.arrays[a];
        const std::string actual = elementType(arr, acc.prop);
        if (actual == checked || !reported.insert({bodyIdx, prefix + acc.prop}).second) continue;
        diags.error(acc.loc, "property '" + acc.prop + "' is " + typeWords(actual) +
                                 " in array '" + arr.name + "' but " + typeWords(checked) +
                                 (same ? " in array '" + same->name + "'"
                                       : std::string(" in another array")) +
                                 "; a body (here " + b.source.label +
                                 ") sees one type per property name");
        const PlanProperty* p = arr.find(acc.prop);
        diags.note(p && p->declared ? p->declLoc : arr.loc,
                   "declare '" + acc.prop + "' with the same type in every array");
      }
    }
  };
  for (const auto& eq : plan.equations) {
    if (!eq.live || eq.declIndex < 0) continue;
    for (const auto& [kind, bodyIdx] : plan.equationDecls[eq.declIndex].methods) {
      const BodyFacts& f = plan.bodies[bodyIdx].facts;
      check(bodyIdx, f.dReads, "d_", {eq.dest});
      check(bodyIdx, f.dWrites, "d_", {eq.dest});
      if (ast::seesSources(kind)) check(bodyIdx, f.sReads, "s_", eq.sources);
      if (kind != ast::Method::Converged && kind != ast::Method::HostReduce) continue;
      for (const auto& w : f.dWrites)
        if (!isConstant(plan.arrays[eq.dest], w.prop))
          diags.error(w.loc, std::string(kind == ast::Method::Converged
                                             ? "'converged' runs once per iteration"
                                             : "'reduce { }' runs once per evaluation") +
                                 ", not per particle: it may write array constants, not the "
                                 "property '" + w.prop + "' of array '" +
                                 plan.arrays[eq.dest].name + "'");
    }
  }
  for (int a = 0; a < static_cast<int>(plan.arrays.size()); ++a) {
    if (plan.arrays[a].stepper < 0) continue;
    for (const auto& [name, bodyIdx] : plan.steppers[plan.arrays[a].stepper].methods) {
      const BodyFacts& f = plan.bodies[bodyIdx].facts;
      check(bodyIdx, f.dReads, "d_", {a});
      check(bodyIdx, f.dWrites, "d_", {a});
    }
  }
}

// What the generated code reads on the bodies' behalf (positions and h for the neighbour
// search, what the pair quantities read, what the adaptive time step reads) it reads as
// double scalars: a located error for any other shape.
void checkImplicitReads(const Plan& plan, DiagnosticEngine& diags) {
  std::set<std::pair<int, std::string>> reported;
  auto mustBeDouble = [&](int a, const std::string& prop, const std::string& why,
                          llvm::SMLoc use, const std::string& useNote) {
    const PlanArray& arr = plan.arrays[a];
    const PlanProperty* p = arr.find(prop);
    if (!p || (p->type == "double" && p->stride == 1) ||
        !reported.insert({a, prop}).second)
      return;
    std::string shape = p->type + (p->stride > 1 ? "[" + std::to_string(p->stride) + "]" : "");
    diags.error(p->declared ? p->declLoc : arr.loc,
                "property '" + prop + "' of array '" + arr.name +
                    "' must be a double scalar, not " + shape + ": " + why + " reads it");
    if (use.isValid()) diags.note(use, useNote);
  };
  for (const auto& eq : plan.equations) {
    if (!eq.live) continue;
    for (const auto& acc : equationAccesses(plan, eq))
      if (acc.implicit)
        mustBeDouble(acc.array, acc.prop,
                     "the neighbour loop (neighbour search and pair quantities)", eq.loc,
                     "in this use of '" + eq.name + "'");
  }
  for (int a = 0; a < static_cast<int>(plan.arrays.size()); ++a)
    if (movesParticles(plan, a))
      for (const auto& p : adaptiveDtProps(plan))
        mustBeDouble(a, p, "the adaptive time step", llvm::SMLoc(), "");
}

// A property that no array declares is allocated as a scalar (stride 1). A body that indexes
// it with a stride (`d_L[9 * d_idx + k]`) would read and write past the end: a located error
// that says what to declare.
void checkUndeclaredStrides(const Plan& plan, DiagnosticEngine& diags) {
  static const std::regex stride(R"(^\s*(\d+)\s*\*\s*\(?\s*[ds]_idx\b|\b[ds]_idx\s*\)?\s*\*\s*(\d+))");
  std::set<std::pair<int, std::string>> reported;
  auto checkBody = [&](int bodyIdx, const std::vector<int>& dests, const std::vector<int>& srcs) {
    const PlanBody& b = plan.bodies[bodyIdx];
    for (const PropSite& site : b.facts.sites) {
      if (site.end <= site.begin || site.end > b.source.text.size()) continue;
      const std::string text = b.source.text.substr(site.begin, site.end - site.begin);
      const size_t open = text.find('[');
      if (open == std::string::npos) continue;
      std::smatch m;
      const std::string index = text.substr(open + 1);
      if (!std::regex_search(index, m, stride)) continue;
      const std::string n = m[1].matched ? m[1].str() : m[2].str();
      for (int a : site.source ? srcs : dests) {
        const PlanProperty* p = plan.arrays[a].find(site.prop);
        if (!p || p->declared || p->stride != 1 || !reported.insert({a, site.prop}).second)
          continue;
        diags.error(llvm::SMLoc::getFromPointer(b.source.start.getPointer() + site.begin),
                    "property '" + site.prop + "' of array '" + plan.arrays[a].name +
                        "' is indexed with a stride of " + n + " but not declared (an "
                        "undeclared property is a scalar): declare it in the array, e.g. "
                        "`property double[" + n + "] " + site.prop + " = 0;`");
        diags.note(plan.arrays[a].loc, "array '" + plan.arrays[a].name + "' is declared here");
      }
    }
  };
  for (const auto& eq : plan.equations) {
    if (!eq.live || eq.declIndex < 0) continue;
    for (const auto& [kind, bodyIdx] : plan.equationDecls[eq.declIndex].methods)
      checkBody(bodyIdx, {eq.dest}, ast::seesSources(kind) ? eq.sources : std::vector<int>{});
  }
  for (int a = 0; a < static_cast<int>(plan.arrays.size()); ++a) {
    if (plan.arrays[a].stepper < 0) continue;
    for (const auto& [name, bodyIdx] : plan.steppers[plan.arrays[a].stepper].methods)
      checkBody(bodyIdx, {a}, {});
  }
}

}  // namespace

bool inferProperties(Plan& plan, DiagnosticEngine& diags) {
  unsigned errorsBefore = diags.errorCount();
  // Every live access, grouped by array.
  std::vector<std::vector<Access>> byArray(plan.arrays.size());
  for (const auto& eq : plan.equations)
    if (eq.live)
      for (auto& acc : equationAccesses(plan, eq)) byArray[acc.array].push_back(acc);
  for (int a = 0; a < static_cast<int>(plan.arrays.size()); ++a)
    for (auto& acc : stepperAccesses(plan, a)) byArray[a].push_back(acc);

  for (int a = 0; a < static_cast<int>(plan.arrays.size()); ++a) {
    PlanArray& arr = plan.arrays[a];
    std::vector<Access>& accs = byArray[a];
    std::map<std::string, const Access*> firstRead, firstWrite;
    std::vector<std::string> order;  // first-appearance order of undeclared properties
    auto note = [&](const std::string& p) {
      if (!arr.find(p) && std::find(order.begin(), order.end(), p) == order.end())
        order.push_back(p);
    };
    for (const auto& acc : accs) {
      if (isConstant(arr, acc.prop)) continue;
      auto& slot = acc.write ? firstWrite[acc.prop] : firstRead[acc.prop];
      if (!slot) slot = &acc;
      note(acc.prop);
    }
    std::set<std::string> readByOthers;  // output, neighbour search, time step
    for (const auto& p : arr.outputProps) {
      if (isConstant(arr, p)) continue;  // constants are written with every snapshot
      readByOthers.insert(p);
      note(p);
    }
    for (const auto& p : arr.limitProps) {  // the scene's limits { } read them at run time
      readByOthers.insert(p);
      note(p);
    }
    for (const auto& p : arr.metricProps) {  // the scene's metrics { } read them at run time
      if (isConstant(arr, p)) continue;      // an array constant: on the host already
      readByOthers.insert(p);
      note(p);
    }
    for (const auto& p : arr.zoneProps) {  // the inlet/outlet manager copies them
      readByOthers.insert(p);
      note(p);
    }
    if (movesParticles(plan, a))
      for (const auto& p : adaptiveDtProps(plan)) {
        readByOthers.insert(p);
        note(p);
      }

    // The final property list: positions, declared properties that something uses (in
    // declaration order), then the rest in order of first use.
    std::vector<PlanProperty> props;
    std::set<std::string> positions;
    for (const auto& p : positionProps(plan.dim)) positions.insert(p);
    for (const char* p : {"x", "y", "z"}) {
      bool used = positions.count(p) || firstRead.count(p) || firstWrite.count(p) ||
                  readByOthers.count(p);
      if (!used) continue;
      PlanProperty pp;
      pp.name = p;
      props.push_back(pp);
    }
    auto isPosition = [](const std::string& p) { return p == "x" || p == "y" || p == "z"; };
    auto usedProp = [&](const std::string& p) {
      return firstRead.count(p) || firstWrite.count(p) || readByOthers.count(p);
    };
    // Those only the initial values of used ones read: computed at set-up, not allocated.
    std::set<std::string> initInputs;
    if (arr.decl) initInputs = initialValueInputs(*arr.decl, usedProp);
    for (const auto& d : arr.props) {
      if (!usedProp(d.name)) {
        if (initInputs.count(d.name)) continue;
        if (plan.leftOutComponents.count(d.name)) continue;  // a z-component in 2D (Dimensions.cpp)
        // A scheme declares what its equations of an effect may need, for every array of a
        // list parameter: one that no kept equation uses is not the scene's doing.
        if (d.fromScheme) continue;
        diags.warning(d.declLoc, "property '" + d.name + "' of array '" + arr.name +
                                     "' is declared but nothing uses it; it is not allocated");
        continue;
      }
      props.push_back(d);
    }
    for (const auto& p : order) {
      if (isPosition(p)) continue;
      PlanProperty pp;
      pp.name = p;
      props.push_back(pp);
    }
    for (auto& p : props) {
      p.read = firstRead.count(p.name) || readByOthers.count(p.name) || positions.count(p.name);
      p.written = firstWrite.count(p.name) != 0;
      p.output = std::find(arr.outputProps.begin(), arr.outputProps.end(), p.name) !=
                 arr.outputProps.end();
      bool set = p.written || p.declared || isPosition(p.name);
      if (p.read && !set) {
        auto it = firstRead.find(p.name);
        if (it != firstRead.end()) {
          const Access& r = *it->second;
          std::string who = r.equation >= 0 ? "equation '" + plan.equations[r.equation].name +
                                                   "'"
                                             : "the stepper of '" + arr.name + "'";
          diags.error(r.loc, "property '" + p.name + "' of array '" + arr.name + "' is read" +
                                 (r.implicit ? " (by the neighbour loop of " + who + ")"
                                             : " by " + who) +
                                 " but nothing sets it");
          if (r.equation >= 0 && !r.implicit)
            diags.note(plan.equations[r.equation].loc,
                       "in this use of '" + plan.equations[r.equation].name + "'");
        } else if (const PlanMetric* m = metricReading(plan, static_cast<int>(a), p.name);
                   m && !p.output) {
          diags.error(m->loc, "property '" + p.name + "' of array '" + arr.name +
                                  "' is read by metric '" + m->name + "' but nothing sets it");
        } else {
          const bool limited = std::find(arr.limitProps.begin(), arr.limitProps.end(),
                                         p.name) != arr.limitProps.end();
          const PlanLimit* limit = nullptr;
          for (const auto& l : plan.limits)
            if (l.array == static_cast<int>(a) && !limit &&
                (l.quantity == p.name || l.quantity == "speed"))
              limit = &l;
          diags.error(p.output ? plan.scene->name.loc : limited && limit ? limit->loc : arr.loc,
                      "property '" + p.name + "' of array '" + arr.name + "' is " +
                          (p.output    ? "output"
                           : limited ? "watched by a limit"
                           : std::find(arr.zoneProps.begin(), arr.zoneProps.end(), p.name) !=
                                   arr.zoneProps.end()
                               ? "copied by an inlet or outlet"
                               : "needed by the adaptive time step") +
                          " but nothing sets it");
        }
        diags.note(arr.loc, "give it an initial value in array '" + arr.name +
                                "': property " + p.name + " = ...;");
      }
      if (p.written && !p.read && !p.output) {
        const Access& w = *firstWrite[p.name];
        std::string who = w.equation >= 0 ? "equation '" + plan.equations[w.equation].name +
                                                 "'"
                                           : "the stepper of '" + arr.name + "'";
        diags.warning(w.loc, "property '" + p.name + "' of array '" + arr.name +
                                 "' is written by " + who + " but never read");
      }
    }
    arr.props = std::move(props);
  }
  if (diags.errorCount() == errorsBefore) {
    checkBodyTypes(plan, diags);
    checkImplicitReads(plan, diags);
    checkUndeclaredStrides(plan, diags);
  }
  return diags.errorCount() == errorsBefore;
}

}  // namespace sphc
