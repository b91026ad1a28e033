// The host program every backend shares: the file's header and includes, the equation and
// stepper bodies, the scene's parameters and set-up, the functions of groups and phases
// (their per-destination work is the backend's), iteration and convergence, the integrator's
// step, the adaptive time step's combination, struct Scene and `main`.
#include "codegen/DtBoundCpp.h"
#include "codegen/Printer.h"
#include "sema/Geometry.h"

#include "llvm/ADT/StringRef.h"
#include "llvm/Support/FileSystem.h"
#include "llvm/Support/Path.h"

#include <algorithm>
#include <functional>
#include <sstream>

namespace sphc {

// A parameter or const of an equation instance whose value is a literal (`dim = 2`, `beta =
// 0.0`, a default `R = 0.2`; also -literal, true, false) and not a state (which `converged`
// and a host `reduce` write): the C++ literal, printed as a `static constexpr` member of the
// instance's values, so that the C++ compiler sees the value in the loops (e.g. folds
// DeltaPlusShiftingSums' `dim == 1 ? ... : dim == 2 ? HIJ * HIJ : ...` and keeps it out of
// memory, where every store through a d_ pointer could change it as far as the compiler
// knows). The same double as the member assigned at set-up from the same literal, so the
// same operations on the same values. "" otherwise (a scene parameter, an expression).
std::string ScenePrinter::literalValue(const PlanEquation& eq, const std::string& name,
                                       const ast::Expr& v) const {
  if (!constantValues_) return "";
  const auto* decl = plan_.equationDecls[eq.declIndex].decl;
  for (const auto& s : decl->states)
    if (s.name.name == name) return "";
  const ast::Expr* e = &v;
  std::string sign;
  if (e->kind == ast::Expr::Unary && (e->op == "-" || e->op == "+") && e->args.size() == 1) {
    sign = e->op;
    e = e->args[0].get();
  }
  auto none = [](const std::string&) { return std::string(); };
  if (e->kind == ast::Expr::Number) return "(" + sign + exprCpp(*e, none) + ")";
  if (e->kind == ast::Expr::Name && (e->text == "true" || e->text == "false"))
    return "(" + sign + exprCpp(*e, none) + ")";
  return "";
}

void ScenePrinter::emitParams() {
  scene_ << "  struct Params {\n";
  for (const auto* p : plan_.params)
    scene_ << "    double " << p->name.name << " = 0.0;  // from " << loc(p->name.loc) << "\n";
  scene_ << "  } P;\n\n";
  // Equation instances: their parameters and constants, evaluated at set-up; those of a
  // literal value constants of the C++ (literalValue; a named struct: an anonymous one may
  // not hold a static member).
  for (const auto& eq : plan_.equations) {
    if (!eq.live) continue;
    std::string members;
    bool literal = false;
    for (const auto& [n, v] : eq.values) {
      const std::string lit = literalValue(eq, n, *v);
      literal |= !lit.empty();
      members += lit.empty() ? " double " + n + " = 0.0;"
                             : " static constexpr double " + n + " = " + lit + ";";
    }
    scene_ << "  struct " << (literal ? eqStruct(eq) + "_values " : "") << "{" << members
           << " } " << eqStruct(eq) << ";  // " << eq.name << "(dest = " << arr(eq.dest).name
           << "), from " << loc(eq.loc) << "\n";
  }
  scene_ << "\n";
}

void ScenePrinter::emitArraySetup(const PlanArray& a) {
  const std::string& A = a.name;
  scene_ << "    // array " << A << ", from " << loc(a.loc) << "\n    {\n";
  scene_ << "      sphc::Points pts;\n";
  if (!a.decl->loads.empty()) scene_ << "      loaded_" << A << ".clear();  // set-up runs twice\n";
  auto paramNames = [&](const std::string& n) { return paramRef(n); };
  for (const auto& g : a.decl->geometry) {
    const GeometryBuilder* b = findGeometryBuilder(g.builder.name);
    std::map<std::string, std::string> args;
    for (const auto& arg : b->args)
      if (arg.defaultValue) args[arg.name] = arg.defaultValue + std::string(".0");
    const ast::Expr* where = nullptr;
    for (const auto& kw : g.args)
      if (kw.name.name == "where") where = kw.value.get();
      else if (kw.value) args[kw.name.name] = exprCpp(*kw.value, paramNames);
    scene_ << "      {  // geometry " << b->name << ", from " << loc(g.builder.loc) << "\n";
    if (where) scene_ << "        const std::size_t first = pts.size();\n";
    const std::string& n = b->name;
    if (n == "block" || n == "tank") {
      scene_ << "        const double lo[3] = {" << args["xmin"] << ", " << args["ymin"] << ", "
             << args["zmin"] << "};\n";
      scene_ << "        const double hi[3] = {" << args["xmax"] << ", " << args["ymax"] << ", "
             << args["zmax"] << "};\n";
      if (n == "block")
        scene_ << "        pts.append(sphc::block(DIM, lo, hi, " << args["dx"] << "));\n";
      else
        scene_ << "        pts.append(sphc::tank(DIM, lo, hi, " << args["dx"]
               << ", static_cast<int>(" << args["layers"] << "), " << args["top"]
               << " != 0.0));\n";
    } else if (n == "disk") {
      scene_ << "        pts.append(sphc::disk(" << args["cx"] << ", " << args["cy"] << ", "
             << args["r"] << ", " << args["dx"] << "));\n";
    } else if (n == "sphere") {
      scene_ << "        pts.append(sphc::sphere(" << args["cx"] << ", " << args["cy"] << ", "
             << args["cz"] << ", " << args["r"] << ", " << args["dx"] << "));\n";
    } else if (n == "cylinder") {
      scene_ << "        pts.append(sphc::cylinder(" << args["cx"] << ", " << args["cy"] << ", "
             << args["r"] << ", " << args["zmin"] << ", " << args["zmax"] << ", "
             << args["dx"] << "));\n";
    } else if (n == "line") {
      scene_ << "        const double p0[3] = {" << args["x0"] << ", " << args["y0"] << ", "
             << args["z0"] << "};\n";
      scene_ << "        const double p1[3] = {" << args["x1"] << ", " << args["y1"] << ", "
             << args["z1"] << "};\n";
      scene_ << "        pts.append(sphc::line(p0, p1, " << args["dx"] << "));\n";
    }
    if (where) {  // `where = E`: keep the new points where E != 0, in order
      auto whereNames = [&](const std::string& v) {
        return v == "x" || v == "y" || v == "z" ? v : paramRef(v);
      };
      scene_ << "        std::size_t kept = first;\n";
      scene_ << "        for (std::size_t i = first; i < pts.size(); ++i) {\n";
      scene_ << "          const double x = pts.x[i], y = pts.y[i], z = pts.z[i];\n";
      scene_ << "          (void)x; (void)y; (void)z;\n";
      scene_ << "          if ((" << exprCpp(*where, whereNames) << ") != 0.0) {  // where, from "
             << loc(g.builder.loc) << "\n";
      scene_ << "            pts.x[kept] = x; pts.y[kept] = y; pts.z[kept] = z; ++kept;\n";
      scene_ << "          }\n        }\n";
      scene_ << "        pts.x.resize(kept); pts.y.resize(kept); pts.z.resize(kept);\n";
    }
    scene_ << "      }\n";
  }
  // Files: positions, and the values of any property of this array that the file has.
  for (const auto& l : a.decl->loads) {
    std::string path = l.path;
    scene_ << "      {  // load \"" << path << "\", from " << loc(l.loc) << "\n";
    scene_ << "        loaded_" << A << ".push_back(sphc::load_particles(source_dir, \"" << path
           << "\", \"" << A << "\"));\n";
    scene_ << "        pts.append(sphc::positions_of(loaded_" << A << ".back()));\n";
    scene_ << "      }\n";
  }
  scene_ << "      " << A << ".name = \"" << A << "\";\n";
  for (const auto& p : a.props)
    scene_ << "      " << A << ".add_property(\"" << p.name << "\", " << propTypeEnum(p.type)
           << ", " << p.stride << ");\n";
  for (const auto* c : [&] {
         std::vector<const ast::ConstDecl*> v;
         for (const auto& c : a.decl->constants) v.push_back(&c);
         return v;
       }()) {
    scene_ << "      " << A << ".add_constant(\"" << c->name.name << "\", " << c->size << ", "
           << (c->init ? exprCpp(*c->init, paramNames) : "0.0") << ");\n";
  }
  for (const auto& c : a.constants) {
    bool declared = false;
    for (const auto& dc : a.decl->constants) declared |= dc.name.name == c;
    if (!declared)
      scene_ << "      " << A << ".add_constant(\"" << c << "\", 1, 0.0);  // reduce target\n";
  }
  scene_ << "      " << A << ".resize(pts.size());\n";
  // Initial values, particle by particle, in declaration order: those of the allocated
  // properties and of the unallocated ones they read (computed, not stored).
  std::set<std::string> initInputs =
      initialValueInputs(*a.decl, [&](const std::string& n) { return a.find(n) != nullptr; });
  // One without an initial value is 0 where a later initial value reads it.
  std::vector<const ast::PropertyDecl*> inits;  // backwards first
  for (auto p = a.decl->properties.rbegin(); p != a.decl->properties.rend(); ++p) {
    const std::string& n = p->name.name;
    bool computed = p->init ? a.find(n) || initInputs.count(n)
                            : std::any_of(inits.begin(), inits.end(), [&](const auto* q) {
                                return q->init && mentions(*q->init, n);
                              });
    if (computed) inits.push_back(&*p);
  }
  std::reverse(inits.begin(), inits.end());
  scene_ << "      for (std::size_t i = 0; i < pts.size(); ++i) {\n";
  // The coordinates the positions and initial values use.
  std::vector<std::string> coords;
  for (const char* c : {"x", "y", "z"}) {
    bool used = propIndex(plan_.arrayIndex(A), c) >= 0;
    for (const auto* p : inits) used |= p->init && mentions(*p->init, c);
    if (used) coords.push_back(c);
  }
  for (size_t k = 0; k < coords.size(); ++k)
    scene_ << (k ? ", " : "        const double ") << coords[k] << " = pts." << coords[k]
           << "[i]" << (k + 1 == coords.size() ? ";\n" : "");
  for (const char* c : {"x", "y", "z"})
    if (propIndex(plan_.arrayIndex(A), c) >= 0)
      scene_ << "        " << hostPtr(plan_.arrayIndex(A), c) << "[i] = " << c << ";\n";
  std::set<std::string> locals = {"x", "y", "z"};
  auto initNames = [&](const std::string& n) {
    if (locals.count(n)) return n == "x" || n == "y" || n == "z" ? n : "v_" + n;
    return paramRef(n);
  };
  for (const auto* p : inits) {
    const std::string& n = p->name.name;
    // A later initial value reads the value as stored (an int property's, truncated).
    std::string value = p->init ? exprCpp(*p->init, initNames) : "0.0";
    if (p->type != "double") value = "static_cast<" + cppType(p->type) + ">(" + value + ")";
    scene_ << "        const double v_" << n << " = " << value << ";  // from "
           << loc(p->name.loc)
           << (!p->init ? ", no initial value (0)"
               : a.find(n) ? "" : ", read by initial values only") << "\n";
    // Stored with the planned stride (a 2D scene keeps 2 of a double[3]'s components).
    if (const PlanProperty* kept = a.find(n); kept && p->init)
      for (int k = 0; k < kept->stride; ++k)
        scene_ << "        " << hostPtr(plan_.arrayIndex(A), n) << "[i * " << kept->stride
               << " + " << k << "] = static_cast<" << cppType(kept->type) << ">(v_" << n
               << ");\n";
    locals.insert(n);
  }
  scene_ << "      }\n";
  if (!a.decl->loads.empty())
    scene_ << "      sphc::apply_loaded(" << A << ", pts.size(), loaded_" << A << ");\n";
  scene_ << "    }\n";
}

void ScenePrinter::emitSetup() {
  scene_ << "  void setup(const std::vector<double>& values, sphc::SceneTimes& times) {\n";
  // Parameters in declaration order: a `param` takes its --set value if given, else its
  // default (which may use earlier ones); a `let` is always computed.
  size_t given = 0;
  for (const auto* p : plan_.params) {
    std::string value = exprCpp(*p->value, [&](const std::string& n) { return paramRef(n); });
    if (p->derived) {
      scene_ << "    P." << p->name.name << " = " << value << ";\n";
      continue;
    }
    scene_ << "    P." << p->name.name << " = std::isnan(values[" << given << "]) ? " << value
           << " : values[" << given << "];\n";
    ++given;
  }
  for (const auto& eq : plan_.equations) {
    if (!eq.live) continue;
    std::set<std::string> earlier;
    std::string s = eqStruct(eq);
    for (const auto& [n, v] : eq.values) {
      // Arguments are scene expressions; defaults and consts use the equation's own values.
      bool own = false;
      const auto* decl = plan_.equationDecls[eq.declIndex].decl;
      for (const auto& c : decl->consts) own |= c.value == v;
      for (const auto& c : decl->states) own |= c.value == v;
      for (const auto& p : decl->params) own |= p.defaultValue == v;
      auto names = [&](const std::string& x) {
        return own && earlier.count(x) ? s + "." + x : paramRef(x);
      };
      earlier.insert(n);
      if (!literalValue(eq, n, *v).empty()) continue;  // a constant of the C++ (emitParams)
      scene_ << "    " << s << "." << n << " = " << exprCpp(*v, names) << ";\n";
    }
  }
  for (int a : sched_.setupArrays) emitArraySetup(arr(a));
  if (plan_.domain.any()) emitDomainSetup();
  if (hasZones()) emitZoneSetup();
  auto pn = [&](const std::string& n) { return paramRef(n); };
  scene_ << "    times.tf = " << exprCpp(*plan_.tf, pn) << ";\n";
  scene_ << "    times.dt = " << exprCpp(*plan_.dt, pn) << ";\n";
  scene_ << dtBoundSetupCpp(plan_, pn, "    ");
  if (plan_.outputEvery)
    scene_ << "    times.output_every = " << exprCpp(*plan_.outputEvery, pn) << ";\n";
  for (const auto& t : plan_.outputAt)
    scene_ << "    times.output_at.push_back(" << exprCpp(*t, pn) << ");\n";
  if (plan_.outputNearestStep) scene_ << "    times.output_nearest_step = true;\n";
  scene_ << "  }\n\n";
}

void ScenePrinter::emitDomainSetup() {
  const PlanDomain& dom = plan_.domain;
  auto pn = [&](const std::string& n) { return paramRef(n); };
  static const char* kAxes[3] = {"x", "y", "z"};
  scene_ << "    // domain, from " << loc(dom.loc) << "\n";
  scene_ << "    box.dim = DIM;\n";
  for (int a = 0; a < 3; ++a)
    for (int side = 0; side < 2; ++side) {
      const PlanBoundary& b = side == 0 ? dom.lo[a] : dom.hi[a];
      if (b.kind == PlanBoundary::Open) continue;
      const std::string which = side == 0 ? "lo" : "hi";
      scene_ << "    box." << which << "_kind[" << a << "] = sphc::Boundary::"
             << (b.kind == PlanBoundary::Periodic ? "Periodic" : "Mirror") << ";  // "
             << kAxes[a] << ", from " << loc(b.loc) << "\n";
      scene_ << "    box." << which << "[" << a << "] = " << exprCpp(*b.at, pn) << ";\n";
    }
  scene_ << "    sphc::check_domain(box);\n";
}

void ScenePrinter::emitGroup(const ScheduleGroup& sg) {
  const PlanGroup& g = *sg.group;
  const std::string& name = sg.name;
  // Phases and subgroups first, in order; then the group's own function.
  for (const auto& m : sg.members) {
    if (m.isPhase)
      emitPhase(sg.phases[m.index]);
    else
      emitGroup(*sg.subgroups[m.index]);
  }
  scene_ << "  // group, from " << loc(g.loc);
  for (std::size_t k = 0; k < sg.fused.size(); ++k)  // group fusion (ScheduleGroupFusion.cpp)
    scene_ << (k ? ", " : "; fused with the groups from ") << loc(sg.fused[k]->loc);
  scene_ << "\n";
  if (g.every) {
    // `every = N`: only when the number of completed steps is a multiple of N (N < 1: never).
    auto pn = [&](const std::string& n) { return paramRef(n); };
    scene_ << "  bool " << name << "_due() const {\n"
           << "    const long every = static_cast<long>(std::floor(" << exprCpp(*g.every, pn)
           << " + 0.5));\n"
           << "    return every >= 1 && step_count % every == 0;\n  }\n\n";
  }
  scene_ << "  void " << name << "(double t, double dt) {\n";
  if (g.every) scene_ << "    if (!" << name << "_due()) return;\n";
  if (g.condition)
    scene_ << "    if (!(" << groupOptionCpp(*g.condition) << ")) return;  // condition = "
           << exprText(*g.condition) << "\n";
  if (!g.iterate && &sg == &sched_.equations && timesGroups()) {
    // --timing: the wall time of each top-level group (group_seconds).
    for (std::size_t k = 0; k < sg.calls.size(); ++k)
      scene_ << "    {\n      const double t0 = sphc::wall_seconds();\n      " << sg.calls[k]
             << "(t, dt);\n      group_seconds[" << k << "] += sphc::wall_seconds() - t0;\n    }\n";
    if (sg.rebuildNeighbours) emitNeighbourRebuild("    ");
    if (sg.calls.empty()) scene_ << "    (void)t; (void)dt;  // an empty group\n";
    scene_ << "  }\n\n";
    return;
  }
  if (!g.iterate) {
    for (const auto& c : sg.calls) scene_ << "    " << c << "(t, dt);\n";
    if (sg.rebuildNeighbours) emitNeighbourRebuild("    ");
    if (sg.calls.empty()) scene_ << "    (void)t; (void)dt;  // an empty group\n";
    scene_ << "  }\n\n";
    return;
  }
  emitIteration(sg);
}

// The live equations of a group and its subgroups, comma-separated (--timing's labels).
static void liveEquationNames(const Plan& plan, const ScheduleGroup& g, std::string& names) {
  for (const auto& m : g.members) {
    if (!m.isPhase) {
      liveEquationNames(plan, *g.subgroups[m.index], names);
      continue;
    }
    for (int e : g.phases[m.index].equations)
      if (plan.equations[e].live) names += (names.empty() ? "" : ",") + plan.equations[e].name;
  }
}

std::vector<std::pair<std::string, std::string>> ScenePrinter::topGroupLabels() const {
  std::vector<std::pair<std::string, std::string>> labels;
  const ScheduleGroup& root = sched_.equations;
  for (const auto& m : root.members) {
    std::string names;
    if (m.isPhase) {
      const Phase& ph = root.phases[m.index];
      for (int e : ph.equations)
        if (plan_.equations[e].live)
          names += (names.empty() ? "" : ",") + plan_.equations[e].name;
      labels.push_back({ph.equations.empty() ? std::string("equations")
                                              : loc(plan_.equations[ph.equations.front()].loc),
                        names});
      continue;
    }
    const ScheduleGroup& sub = *root.subgroups[m.index];
    if (sub.group->postStep) continue;  // runs in step(), not in equations()
    liveEquationNames(plan_, sub, names);
    labels.push_back({loc(sub.group->loc), names});
  }
  return labels;
}

std::vector<std::pair<std::string, std::string>> ScenePrinter::postStepLabels() const {
  std::vector<std::pair<std::string, std::string>> labels;
  const ScheduleGroup& root = sched_.equations;
  for (const auto& ps : sched_.postStep)
    for (const auto& m : root.members)
      if (!m.isPhase && root.subgroups[m.index]->group == ps.group) {
        std::string names;
        liveEquationNames(plan_, *root.subgroups[m.index], names);
        labels.push_back({loc(ps.group->loc), names});
      }
  return labels;
}

// An iterated group: its members again and again until every `converged` test passes (and at
// least min_iterations ran), or max_iterations ran; the count goes to iteration_stats.
void ScenePrinter::emitIteration(const ScheduleGroup& sg) {
  const PlanGroup& g = *sg.group;
  scene_ << "    int iteration = 1;\n    bool converged = true;\n";
  scene_ << "    for (;; ++iteration) {\n";
  for (const auto& c : sg.calls) scene_ << "      " << c << "(t, dt);\n";
  if (sg.rebuildNeighbours) emitNeighbourRebuild("      ");
  // As PySPH (its Cython backend): from min_iterations on, every `converged` is called each
  // iteration, none skipped once one says no (they may keep state), and the results ANDed.
  scene_ << "      const bool run_tests = iteration >= " << g.minIterations << ";\n";
  scene_ << "      converged = run_tests;\n";
  for (const auto* eq : sg.convergers) emitConverged(*eq);
  if (mpi_) scene_ << "      converged = sphc::mpi::all(converged);  // the same on every rank\n";
  scene_ << "      if (converged && iteration >= " << g.minIterations << ") break;\n";
  scene_ << "      if (iteration >= " << g.maxIterations << ") break;\n";
  scene_ << "    }\n";
  scene_ << "    iteration_stats[" << sg.statsIndex << "].record(iteration, converged);\n  }\n\n";
}

// `converged` runs on the host for every backend, on particle 0 of its destination
// (constants are current on the host; properties may need to come back first).
void ScenePrinter::emitConverged(const PlanEquation& eq) {
  const auto& pd = plan_.equationDecls[eq.declIndex];
  const PlanBody& b = plan_.bodies[pd.methods.at(ast::Method::Converged)];
  scene_ << "      if (run_tests) {\n        const int d_idx = 0;\n";
  std::set<std::string> dprops, written;
  for (const auto& r : b.facts.dReads) dprops.insert(r.prop);
  // It may write array constants (its state; analysis/Properties.cpp refuses particle
  // properties): afterConverged sends them where the backend keeps them.
  for (const auto& w : b.facts.dWrites) written.insert(w.prop);
  dprops.insert(written.begin(), written.end());
  bool needsProps = false;
  for (const auto& p : dprops) needsProps |= constIndex(eq.dest, p) < 0;
  if (needsProps) beforeConverged(eq);
  for (const auto& p : dprops)
    scene_ << "        " << hostType(eq.dest, p) << "* d_" << p << " = " << propPtr(eq.dest, p)
           << ";\n";
  scene_ << "        converged = ("
         << callBody(bodyFunctionName(eq.name, "converged"), b, eq.dest, eqStruct(eq), "t")
         << " > 0) && converged;  // " << eq.name << ", from " << loc(eq.loc) << "\n";
  for (const auto& p : written)
    if (int c = constIndex(eq.dest, p); c >= 0) afterConverged(eq, c);
  scene_ << "      }\n";
}

// PySPH's reduce(dst, t, dt): once per evaluation, on the host, with N the real particles
// of the destination; it reads properties (brought to the host first, on a device) and may
// write array constants (sent back) and the equation's states.
void ScenePrinter::emitHostReduces(const DestinationWork& w) {
  const int d = w.array;
  const std::string& D = arr(d).name;
  for (const PlanEquation* eq : w.hostReduce) {
    const PlanBody& b = methodBody(*eq, ast::Method::HostReduce);
    scene_ << "      {  // reduce on the host: " << eq->name << ", from " << loc(eq->loc) << "\n";
    scene_ << "        const int N = static_cast<int>(" << D << ".n);\n";
    std::set<std::string> dprops, written;
    for (const auto& r : b.facts.dReads) dprops.insert(r.prop);
    for (const auto& wr : b.facts.dWrites) written.insert(wr.prop);
    dprops.insert(written.begin(), written.end());
    bool needsProps = false;
    for (const auto& p : dprops) needsProps |= constIndex(d, p) < 0;
    if (needsProps) beforeConverged(*eq);
    for (const auto& p : dprops)
      scene_ << "        " << hostType(d, p) << "* d_" << p << " = " << propPtr(d, p) << ";\n";
    scene_ << "        " << callBody(bodyFunctionName(eq->name, "host_reduce"), b, d, eqStruct(*eq), "t")
           << ";\n";
    for (const auto& p : written)
      if (int c = constIndex(d, p); c >= 0) afterConverged(*eq, c);
    scene_ << "      }\n";
  }
}

void ScenePrinter::emitPhase(const Phase& ph) {
  if (splitPhases_) {
    // Printed on its own, then declared in struct Scene and defined after it (phases_).
    std::ostringstream members;
    scene_.swap(members);
    emitPhaseMember(ph);
    scene_.swap(members);
    outOfClassMembers(members.str(), {ph.name});
    return;
  }
  emitPhaseMember(ph);
}

// Members printed as in struct Scene: comment lines, `  TYPE NAME(ARGS) {`, the body, `  }`.
// Split (splitPhases_): those named in `names` leave only their comments and a declaration
// in the class (scene_); their definitions, qualified, go after it with the same comments and
// body (phases_). The others stay in the class as printed.
void ScenePrinter::outOfClassMembers(const std::string& members,
                                     const std::set<std::string>& names) {
  std::istringstream in(members);
  std::string line, comments;
  while (std::getline(in, line)) {
    const std::size_t paren = line.find('(');
    const std::size_t space = line.rfind(' ', paren);
    const bool head = line.size() > 5 && line.compare(0, 2, "  ") == 0 && line[2] != ' ' &&
                      line[2] != '/' && paren != std::string::npos && space > 2 &&
                      line.compare(line.size() - 3, 3, ") {") == 0;
    if (!head || !names.count(line.substr(space + 1, paren - space - 1))) {
      scene_ << line << "\n";
      comments = line.compare(0, 4, "  //") == 0 ? comments + line.substr(2) + "\n" : "";
      continue;
    }
    scene_ << line.substr(0, line.size() - 2) << ";  // defined after the struct\n";
    phases_ << comments << line.substr(2, space - 1) << "sphc_scene::Scene::"
            << line.substr(space + 1) << "\n";
    while (std::getline(in, line) && line != "  }") phases_ << line << "\n";
    phases_ << "}\n\n";
    comments.clear();
  }
}

void ScenePrinter::emitPhaseMember(const Phase& ph) {
  // Provenance: the group and the equations fused into this phase.
  scene_ << "  // phase of the group from " << loc(ph.group->loc) << ":";
  for (size_t k = 0; k < ph.equations.size(); ++k) {
    const PlanEquation& eq = plan_.equations[ph.equations[k]];
    scene_ << (k ? ", " : " ") << eq.name << (eq.live ? "" : " (pruned)");
  }
  scene_ << "\n";
  scene_ << "  void " << ph.name << "(double t, double dt) {\n";
  // Every body takes t and dt: only a phase whose equations were all pruned ignores them.
  if (ph.destinations.empty()) scene_ << "    (void)t; (void)dt;\n";
  phasePrologue(ph);
  for (const DestinationWork& w : ph.destinations) {
    const std::string& D = arr(w.array).name;
    // Groups with `real = false` run on the ghosts too (they follow the real particles).
    const bool onGhosts = w.onGhosts;
    scene_ << "    {  // destination " << D << "\n";
    scene_ << "      const int n = static_cast<int>(" << D << ".n"
           << (onGhosts ? " + ghosts_" + D + ".size()" : std::string("")) << ");"
           << (onGhosts ? "  // real particles and ghosts (real = false)" : "") << "\n";
    if (w.ranged()) emitParticleRange(w);
    destination(w, ph.name);
    scene_ << "    }\n";
  }
  scene_ << "  }\n\n";
}

// Group option update_nnps: the neighbour search rebuilt within an evaluation, as at its
// start (with a domain: the ghosts go, particles wrap into the box, the ghosts come back).
void ScenePrinter::emitNeighbourRebuild(const std::string& indent) {
  scene_ << indent << "// update_nnps: positions may have changed, the neighbours with them\n";
  if (hasDomain()) {
    // removeGhosts() is written for the 4-space indent of compute_accelerations.
    std::istringstream lines(removeGhosts());
    for (std::string line; std::getline(lines, line);)
      scene_ << indent << llvm::StringRef(line).ltrim().str() << "\n";
    scene_ << indent << "update_domain();\n";
  }
  scene_ << indent << "update_neighbours();\n";
}

std::string ScenePrinter::groupOptionCpp(const ast::Expr& e) const {
  return exprCpp(e, [&](const std::string& n) {
    if (n == "t" || n == "dt") return n;
    size_t dot = n.find('.');
    if (dot == std::string::npos) return paramRef(n);
    int a = plan_.arrayIndex(n.substr(0, dot));
    return "static_cast<double>(" + propPtr(a, n.substr(dot + 1)) + "[0])";
  });
}

// Group options start_idx / stop_idx: the destination particles the per-particle loops and
// neighbour passes run on, rounded to the nearest integer and clamped to [0, n).
void ScenePrinter::emitParticleRange(const DestinationWork& w) {
  auto index = [&](const ast::ExprPtr& e, const std::string& otherwise) {
    return e ? "std::fmax(0.0, std::floor(" + groupOptionCpp(*e) + " + 0.5))" : otherwise;
  };
  scene_ << "      // group options start_idx = " << (w.startIdx ? exprText(*w.startIdx) : "0")
         << ", stop_idx = " << (w.stopIdx ? exprText(*w.stopIdx) : "n") << "\n";
  scene_ << "      const int d_end = static_cast<int>(std::fmin(static_cast<double>(n), "
         << index(w.stopIdx, "static_cast<double>(n)") << "));\n";
  scene_ << "      const int d_begin = static_cast<int>(std::fmin(static_cast<double>(d_end), "
         << index(w.startIdx, "0.0") << "));\n";
  scene_ << "      (void)d_begin;\n";
}

void ScenePrinter::emitStep() {
  if (hasDomain()) {
    scene_ << "  // Periodic axes: particles that left the box come back in.\n";
    scene_ << "  void update_domain() {\n";
    for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a) wrapPeriodic(a);
    scene_ << "  }\n\n";
    scene_ << "  // Rebuilds the neighbour search of every array that is a source, with ghosts.\n";
    scene_ << "  void update_neighbours() {\n";
    if (!loopArrays_.empty()) updateNeighboursWithGhosts();
    scene_ << "  }\n\n";
    scene_ << "  // Ghosts exist during an evaluation only: outside it arrays hold real particles.\n";
    scene_ << "  void compute_accelerations(double t, double dt) {\n";
    scene_ << wrapBeforeEvaluation();
    scene_ << "    update_domain();\n";
    timedNeighbourUpdate();
    scene_ << "    equations(t, dt);\n";
    scene_ << removeGhosts();
    scene_ << "  }\n\n";
  } else {
    staticCellLists();
    scene_ << "  // Rebuilds the neighbour search of every array that is a source.\n";
    scene_ << "  void update_neighbours() {\n";
    updateNeighbours();
    scene_ << "  }\n\n";
    scene_ << "  void compute_accelerations(double t, double dt) {\n";
    timedNeighbourUpdate();
    scene_ << "    equations(t, dt);\n  }\n\n";
  }
  if (!sched_.postStep.empty()) {
    // Groups with post_step = true: after the integrator's time step, on the new positions.
    scene_ << "  // groups with post_step = true, after each time step\n";
    // No neighbour update when no group is due (a disabled group changes nothing at all).
    scene_ << "  void post_step(double t, double dt) {\n    if (!(";
    for (size_t i = 0; i < sched_.postStep.size(); ++i)
      scene_ << (i ? " || " : "")
             << (sched_.postStep[i].group->every ? sched_.postStep[i].function + "_due()"
                                                 : std::string("true"));
    scene_ << ")) return;\n";
    const bool neighbours = sched_.postStepNeighbours;  // Schedule.h
    scene_ << (hasDomain() ? "    update_domain();\n" : "");
    if (!neighbours)
      scene_ << "    // per-particle groups only: no neighbour search\n";
    else if (timesGroups())
      timedNeighbourUpdate();
    else
      scene_ << "    update_neighbours();\n";
    if (timesGroups()) {
      // --timing: each post_step group's wall time, after the equations' in group_seconds;
      // the neighbour update before them counts as neighbour search.
      for (std::size_t i = 0; i < sched_.postStep.size(); ++i)
        scene_ << "    {\n      const double t0 = sphc::wall_seconds();\n      "
               << sched_.postStep[i].function << "(t, dt);\n      group_seconds["
               << sched_.equations.calls.size() + i << "] += sphc::wall_seconds() - t0;\n    }\n";
    } else {
      for (const auto& ps : sched_.postStep) scene_ << "    " << ps.function << "(t, dt);\n";
    }
    if (hasDomain()) {
      if (neighbours) scene_ << removeGhosts();
      // A group that moves particles (a shift) can move one out of a periodic box: wrap it
      // now, so that an output written after this step holds positions in the box.
      scene_ << "    update_domain();\n";
    }
    scene_ << "  }\n\n";
  }
  // The integrator's time step; after stage k of m the time is t + k/m dt.
  const int stages = sched_.stages;
  scene_ << "  // integrator " << plan_.integratorName << "\n";
  scene_ << "  void step(double t, double dt) {\n";
  auto timeAfter = [&](int stagesDone) {
    return stagesDone == 0 ? std::string("t")
                           : "t + " + std::to_string(stagesDone) + ".0 / " +
                                 std::to_string(stages) + ".0 * dt";
  };
  for (const StepStatement& st : sched_.step) {
    if (st.kind == StepStatement::ComputeAccelerations) {
      scene_ << "    compute_accelerations(" << timeAfter(st.stagesDone[0]) << ", dt);\n";
      continue;
    }
    if (st.kind == StepStatement::InletOutlet) {
      scene_ << "    inlet_outlet(" << timeAfter(st.stagesDone[0]) << ");\n";
      continue;
    }
    if (st.kind == StepStatement::UpdateDomain) {
      scene_ << (hasDomain() ? "    update_domain();\n"
                             : "    // update_domain: no periodic or mirror domain in this scene\n");
      continue;
    }
    stepperCall(st, timeAfter);
  }
  scene_ << "    ++step_count;\n";
  if (!sched_.postStep.empty()) scene_ << "    post_step(t + dt, dt);\n";
  scene_ << "  }\n\n";
}

void ScenePrinter::emitAdaptiveDt() {
  const AdaptiveDt& ad = sched_.adaptiveDt;
  if (!ad.enabled) return;
  auto pn = [&](const std::string& n) { return paramRef(n); };
  std::string cfl = plan_.cfl ? exprCpp(*plan_.cfl, pn) : "0.3";
  scene_ << "  // The stable time step: CFL (h / (c + |v|)), force (sqrt(h / |a|)) and viscous\n"
            "  // (h^2 / nu) limits over moving particles.\n";
  scene_ << "  double adaptive_dt() {\n";
  scene_ << "    double dt_cfl = HUGE_VAL, dt_force = HUGE_VAL, h2min = HUGE_VAL;\n";
  for (int a : ad.arrays) {
    scene_ << "    {  // " << arr(a).name << "\n";
    adaptiveDtArray(a);
  }
  scene_ << "    double dt = std::fmin(" << cfl << " * dt_cfl, "
         << (plan_.forceFactor ? exprCpp(*plan_.forceFactor, pn) : "1.0") << " * dt_force);\n";
  if (ad.viscous)
    scene_ << "    dt = std::fmin(dt, "
           << (plan_.viscousFactor ? exprCpp(*plan_.viscousFactor, pn) : "0.125")
           << " * h2min / " << exprCpp(*plan_.nu, pn) << ");  // viscous limit\n";
  scene_ << "    return dt;\n";
  scene_ << "  }\n\n";
}

// The scene's limits { } (sphc/sanity.h), evaluated after the set-up from the parameters.
void ScenePrinter::emitLimits() {
  auto pn = [&](const std::string& n) { return "scene." + paramRef(n); };
  auto end = [&](const ast::ExprPtr& e, const char* none) {
    return e ? exprCpp(*e, pn) : std::string(none);
  };
  auto bounds = [&](bool has, const ast::ExprPtr& lo, const ast::ExprPtr& hi) {
    if (!has) return std::string("std::nullopt");
    return "sphc::Bounds{" + end(lo, "-HUGE_VAL") + ", " + end(hi, "HUGE_VAL") + "}";
  };
  out_ << "  prog.limits = [] {  // limits { }: warn once outside warn, stop outside stop\n"
          "    std::vector<sphc::Limit> l;\n";
  for (const auto& l : plan_.limits) {
    out_ << "    l.push_back({\"" << arr(l.array).name << "\", \"" << l.quantity << "\", \""
         << loc(l.loc) << "\", " << bounds(l.hasWarn, l.warnLo, l.warnHi) << ", "
         << bounds(l.hasStop, l.stopLo, l.stopHi) << "});\n";
    if (!l.hasRemove) continue;
    // remove [lo, hi] where C in [lo, hi]: taken out of the run (the run loop, sphc/sanity.h)
    out_ << "    l.back().remove = " << bounds(true, l.removeLo, l.removeHi) << ";\n";
    if (!l.removeWhere.empty())
      out_ << "    l.back().remove_where = \"" << l.removeWhere << "\";\n"
           << "    l.back().where_bounds = " << bounds(true, l.whereLo, l.whereHi) << ";\n";
  }
  out_ << "    return l;\n  };\n";
  bool removes = false;
  for (const auto& l : plan_.limits) removes |= l.hasRemove;
  if (!removes) return;
  // What follows the run loop's removal of particles from a host array (afterRemoval).
  std::string after;
  for (std::size_t a = 0; a < plan_.arrays.size(); ++a) {
    bool removed = false;
    for (const auto& l : plan_.limits) removed |= l.hasRemove && l.array == static_cast<int>(a);
    const std::string s = removed ? afterRemoval(static_cast<int>(a)) : "";
    if (!s.empty())
      after += "    if (&a == &scene." + arr(static_cast<int>(a)).name + ") {\n" + s + "    }\n";
  }
  out_ << "  prog.after_removal = [](const sphc::ParticleArray& a) {  // limits' remove\n"
       << (after.empty() ? "    (void)a;  // kept lists see the new count\n" : after) << "  };\n";
}

void ScenePrinter::emitMain() {
  out_ << "int main(int argc, char** argv) {\n";
  mainPrologue();
  if (mpi_) out_ << "  sphc::mpi::Session mpi_session(&argc, &argv);  // MPI_Init, MPI_Finalize\n";
  out_ << "  static Scene scene;\n";
  out_ << "  sphc::SceneProgram prog;\n";
  out_ << "  prog.name = \"" << plan_.sceneName << "\";\n";
  out_ << "  prog.dim = DIM;\n";
  out_ << "  prog.backend = \"" << backendName_ << "\";\n";
  mainBackendOptions();
  // The parameters, options and effects' parameters: one call each with a list of plain data
  // (sphc::add_params, ...: the runtime fills the vectors), no code per entry to compile.
  std::vector<std::string> entries;
  auto list = [&](const char* call, const char* what) {
    if (entries.empty()) return;
    out_ << "  " << call << "{  // " << what << "\n";
    for (std::size_t k = 0; k < entries.size(); ++k) {
      const std::string& e = entries[k];
      const std::size_t comment = e.find("  //");  // after the entry's comma
      const std::string end = k + 1 == entries.size() ? "});" : ",";
      out_ << "      "
           << (comment == std::string::npos ? e + end
                                            : e.substr(0, comment) + end + e.substr(comment))
           << "\n";
    }
    entries.clear();
  };
  for (const auto* p : plan_.params) {
    if (p->derived) continue;  // `let`: not overridable
    // A literal default is printed as setup() prints it (the .sph spelling, `0.03`).
    bool lit = isLiteral(*p->value);
    auto none = [](const std::string& n) -> std::string { SPHC_INTERNAL("name in literal " + n); };
    entries.push_back("{\"" + p->name.name + "\", " +
                      (lit ? exprCpp(*p->value, none) : "std::nan(\"\")") + ", \"" +
                      (lit ? std::string("") : "= " + exprText(*p->value)) + "\"}");
  }
  list("sphc::add_params(prog.params, ", "name, default, help");
  for (const auto& o : plan_.options) {
    std::string choices;
    for (const auto& c : o.choices) choices += (choices.empty() ? "" : ", ") + c;
    entries.push_back("{\"" + o.name + "\", \"" + o.value + "\", \"" + choices +
                      "\"}  // sphc -D " + o.name + "=...");
  }
  list("sphc::add_options(prog.options, ", "name, value, choices");
  for (const auto& o : plan_.options) {
    if (!o.isEffect || o.on()) continue;
    // The sphc command that turns the effect on, with the effects it needs that are off.
    std::vector<std::string> turnOn;
    std::function<void(const std::string&)> need = [&](const std::string& name) {
      for (const auto& d : plan_.options)
        if (d.name == name && !d.on() &&
            std::find(turnOn.begin(), turnOn.end(), name) == turnOn.end()) {
          for (const auto& n : d.needs) need(n);
          turnOn.push_back(name);
        }
    };
    need(o.name);
    std::string cmd = "sphc " + llvm::sys::path::filename(plan_.mainFile).str();
    for (const auto& n : turnOn) cmd += " -D " + n + "=on";
    for (const auto& p : o.params)
      entries.push_back("{\"" + p + "\", \"" + o.name + "\", \"" + cmd + "\"}");
  }
  list("sphc::add_effect_params(prog.effect_params, ", "name, effect, sphc command");
  if (singlePrecision_) out_ << "  prog.precision = \"single\";\n";
  out_ << "  prog.setup = [](const std::vector<double>& v, sphc::SceneTimes& times) {\n"
          "    scene.setup(v, times);\n"
       << afterSetupDistributed() << afterSetup() << "  };\n";
  out_ << "  prog.arrays = [] { return std::vector<sphc::ParticleArray*>{";
  bool first = true;
  for (const auto& a : plan_.arrays) {
    out_ << (first ? "" : ", ") << "&scene." << a.name;
    first = false;
  }
  out_ << "}; };\n";
  out_ << "  prog.compute_initial = [](double t, double dt) { scene.compute_accelerations(t, dt); };\n";
  out_ << "  prog.step = [](double t, double dt) { scene.step(t, dt); };\n";
  // OpenCL: particle data stays on the device; the run loop asks for it back only when it
  // writes output or checks for a blow-up.
  // --precision=single on the CPU: likewise for the float copies.
  if (hasToHost()) out_ << "  prog.to_host = [] { scene.to_host(); };\n";
  if (plan_.adaptiveDt)
    out_ << (mpi_ ? "  prog.adaptive_dt = [] { return sphc::mpi::min(scene.adaptive_dt()); };  // every rank's\n"
                  : "  prog.adaptive_dt = [] { return scene.adaptive_dt(); };\n");
  if (!sched_.iteratedGroups.empty())
    out_ << "  prog.iterations = [] { return scene.iteration_stats; };\n";
  emitRestart();
  if (timesNeighbourSearch()) out_ << "  prog.neighbour_seconds = [] { return scene.nnps_seconds; };\n";
  if (hasZones()) out_ << "  prog.inlet_outlet_seconds = [] { return scene.io_seconds; };\n";
  if (timesGroups() && !sched_.equations.group->iterate) {
    const auto labels = topGroupLabels();
    if (labels.size() == sched_.equations.calls.size()) {
      out_ << "  prog.group_seconds = [] {\n    return std::vector<sphc::GroupSeconds>{";
      for (std::size_t k = 0; k < labels.size(); ++k)
        out_ << (k ? "," : "") << "\n        {\"" << labels[k].first << "\", \""
             << labels[k].second << "\", scene.group_seconds[" << k << "]}";
      const auto post = postStepLabels();
      for (std::size_t i = 0; i < post.size(); ++i)
        out_ << ",\n        {\"" << post[i].first << "\", \"" << post[i].second
             << "\", scene.group_seconds[" << labels.size() + i << "], true}";
      out_ << "};\n  };\n";
    }
  }
  if (!plan_.limits.empty()) emitLimits();
  emitMetricsMain();
  bool anyOutput = false;
  for (const auto& a : plan_.arrays) anyOutput |= !a.outputProps.empty();
  for (const auto& a : plan_.arrays) {
    if (anyOutput && a.outputProps.empty()) continue;
    out_ << "  prog.output.push_back({\"" << a.name << "\", {";
    bool firstProp = true;
    for (const auto& p : a.outputProps) {
      if (constIndex(plan_.arrayIndex(a.name), p) >= 0) continue;  // constants: always written
      out_ << (firstProp ? "" : ", ") << "\"" << p << "\"";
      firstProp = false;
    }
    // Global ids: arrays that grow and shrink, and --global-ids / --mpi runs (an empty
    // list writes every property, gid included).
    if ((hasZones() || globalIds_) && !firstProp) out_ << ", \"gid\"";
    out_ << "}});\n";
  }
  distributedMain();
  if (mpi_)
    out_ << "  const int rc = sphc::run_main(argc, argv, prog);\n" << distributedReport()
         << "  // A rank that fails ends the whole job (MPI_Abort), so none waits forever.\n"
            "  return sphc::mpi::finish(rc);\n}\n";
  else
    out_ << "  return sphc::run_main(argc, argv, prog);\n}\n";
}

std::string ScenePrinter::run() {
  std::string file = llvm::sys::path::filename(plan_.mainFile).str();
  out_ << "// Generated by sphc from " << file << ": do not edit; edit the .sph and recompile.\n";
  out_ << "// Backend: " << backendComment() << ".\n";
  out_ << "// Scene '" << plan_.sceneName << "': dim " << plan_.dim << ", kernel "
       << plan_.kernel << ", integrator "
       << (plan_.integratorName.empty() ? "none" : plan_.integratorName) << ".\n";
  out_ << "#include \"sphc/geometry.h\"\n#include \"sphc/kernels.h\"\n"
          "#include \"sphc/nnps.h\"\n#include \"sphc/particle_array.h\"\n"
          "#include \"sphc/solver.h\"\n";
  bool anyLoad = false;
  for (const auto& a : plan_.arrays) anyLoad |= !a.decl->loads.empty();
  if (anyLoad) out_ << "#include \"sphc/load.h\"\n";
  if (hasDomain()) out_ << "#include \"sphc/domain.h\"\n";
  if (!plan_.metrics.empty()) out_ << "#include \"sphc/metrics.h\"\n";
  if (hasZones()) out_ << "#include \"sphc/inlet_outlet.h\"\n";
  if (hasZones() && mpi_) out_ << "#include \"sphc/mpi/zones.h\"\n";
  out_ << "#include \"sphc/restart.h\"\n";
  if (globalIds_) out_ << "#include \"sphc/global_ids.h\"\n";
  if (mpi_)
    out_ << "#include \"sphc/mpi/comm.h\"\n#include \"sphc/mpi/decomposition.h\"\n"
            "#include \"sphc/mpi/gather.h\"\n#include \"sphc/mpi/halo.h\"\n"
            "#include \"sphc/mpi/output.h\"\n";
  runtimeIncludes();
  if (intPowUsed()) out_ << "#include \"sphc/pow.h\"\n";
  out_ << "\n#include <math.h>\n#include <cmath>\n#include <cstdint>\n#include <vector>\n";
  systemIncludes();
  out_ << "\n";
  // Split units (splitPhases_): a named namespace, whose Scene both units share.
  out_ << (splitPhases_ ? "namespace sphc_scene {\n\n" : "namespace {\n\n");
  out_ << "constexpr int DIM = " << plan_.dim << ";\n";
  out_ << "using Kernel = sphc::" << plan_.kernel << "<DIM>;\n";
  out_ << "constexpr " << real_
       << " RADIUS2 = Kernel::radius_scale * Kernel::radius_scale;\n\n";
  emitSlots();
  out_ << "// ---- Equation and stepper bodies, as written in the .sph files ----\n\n";
  emitBodies();
  emitParams();
  emitSetup();
  emitSceneFunctions();
  beforeScene();
  emitSceneMembers();
  dataMovement();
  out_ << "\n" << scene_.str() << "};\n\n";
  if (splitPhases_ && phases_.tellp() > 0)
    out_ << "}  // namespace sphc_scene\n\nusing namespace sphc_scene;\n\n"
         << kPhasesBeginMarker << " (sphc --single-unit: members of Scene) ----\n\n"
         << phases_.str() << kPhasesEndMarker << " ----\n\n";
  else if (splitPhases_)
    out_ << "}  // namespace sphc_scene\n\nusing namespace sphc_scene;\n\n";
  else
    out_ << "}  // namespace\n\n";
  emitMain();
  return out_.str();
}

std::string ScenePrinter::kernelSource() {
  emitBodies();
  emitSceneFunctions();
  return cl_.str();
}

// The functions of equation and stepper bodies (each declaration once), where they run.
void ScenePrinter::emitBodies() {
  emitKernelFunctions();
  emitPowFunction();
  // The .sph file's helper functions, before the bodies that call them: on the host (the C++
  // of the CPU backends, and the host-run converged tests of OpenCL) and in the kernels.
  for (const auto& f : plan_.functions) {
    emitHelperFunction(f, host_, out_);
    if (bodyOnDevice(false)) emitHelperFunction(f, device_, cl_);
  }
  // Bodies of live equations (each declaration once) and of steppers.
  std::set<int> emittedDecls;
  for (const auto& eq : plan_.equations) {
    if (!eq.live || !emittedDecls.insert(eq.declIndex).second) continue;
    const auto& pd = plan_.equationDecls[eq.declIndex];
    for (const auto& [kind, b] : pd.methods) {
      const bool host = kind == ast::Method::Converged || kind == ast::Method::HostReduce;
      const bool dev = bodyOnDevice(host);
      emitBodyFunction(plan_.bodies[b],
                       bodyFunctionName(eq.name, kind == ast::Method::HostReduce
                                                     ? "host_reduce"
                                                     : ast::methodKeyword(kind)),
                       kind == ast::Method::Reduce      ? "double"
                       : kind == ast::Method::Converged ? "int"
                                                        : "void",
                       eq.dest, dev ? device_ : host_, dev ? cl_ : out_);
      if (kind == ast::Method::Loop && !dev) emitSumsFunction(eq, out_);  // RegisterSums.cpp
      if (kind == ast::Method::Loop && !dev) emitSimdFunction(eq, out_);  // SimdPairs.cpp
    }
  }
  std::set<int> emittedSteppers;
  for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a) {
    int s = arr(a).stepper;
    if (s < 0 || !emittedSteppers.insert(s).second) continue;
    for (const auto& [m, b] : plan_.steppers[s].methods)
      emitBodyFunction(plan_.bodies[b], bodyFunctionName(plan_.steppers[s].decl->name.name, m),
                       "void", a, bodyOnDevice(false) ? device_ : host_,
                       bodyOnDevice(false) ? cl_ : out_);
  }
}

// The members of struct Scene that compute: groups and phases, steppers, the step, adaptive
// dt (with the OpenCL printer, their kernels too).
void ScenePrinter::emitSceneFunctions() {
  emitGroup(sched_.equations);
  steppers();
  if (splitPhases_) {
    // Split: what the run loop calls at every step is defined with the phases, so that
    // the time step's code (steppers, neighbour updates, inlined there) is compiled in
    // their unit (-O3) and the other unit holds only set-up, output and main.
    std::ostringstream members;
    scene_.swap(members);
    emitStep();
    if (hasZones()) emitInletOutlet();
    emitAdaptiveDt();
    scene_.swap(members);
    outOfClassMembers(members.str(), {"compute_accelerations", "step", "adaptive_dt"});
  } else {
    emitStep();
    if (hasZones()) emitInletOutlet();
    emitAdaptiveDt();
  }
  emitMetrics();
  distributedFunctions();
}


// struct Scene: the arrays, the neighbour search and ghosts, statistics.
void ScenePrinter::emitSceneMembers() {
  out_ << "// ---- The scene ----\n\n";
  out_ << "struct Scene {\n";
  for (const auto& a : plan_.arrays) out_ << "  sphc::ParticleArray " << a.name << ";\n";
  for (const auto& a : plan_.arrays)
    if (!a.decl->loads.empty())
      out_ << "  std::vector<sphc::ParticleArray> loaded_" << a.name << ";\n";
  searchMembers();
  if (hasDomain()) {
    out_ << "  sphc::Domain box;  // periodic and mirror boundaries\n";
    for (const auto& S : sourceArrays_)
      out_ << "  " << ghostsType() << " ghosts_" << S << ";\n";
  }
  extraMembers();
  if (hasZones())
    out_ << "  sphc::InletOutlet io;  // inlets and outlets (sphc/inlet_outlet.h)\n"
            "  double io_seconds = 0.0;  // in inlet_outlet, for --timing\n";
  distributedMembers();
  // Iterations per evaluation of each iterated group (--timing prints them).
  out_ << "  std::vector<sphc::IterationStats> iteration_stats{";
  for (std::size_t k = 0; k < sched_.iteratedGroups.size(); ++k)
    out_ << (k ? ", " : "") << "sphc::IterationStats{\"" << loc(sched_.iteratedGroups[k])
         << "\"}";
  out_ << "};\n";
  out_ << "  long step_count = 0;  // completed time steps (group option `every`)\n";
  if (timesNeighbourSearch()) out_ << "  double nnps_seconds = 0.0;  // in update_neighbours, for --timing\n";
  if (timesGroups())
    out_ << "  std::vector<double> group_seconds = std::vector<double>("
         << sched_.equations.calls.size() + sched_.postStep.size()
         << ", 0.0);  // per top-level group, then per post_step group, for --timing\n";
  if (!sourceArrays_.empty()) {
    out_ << "  static constexpr long REORDER_EVERY = 50;\n";
    out_ << "  long builds = 0;\n";
  }
  bool anyLoad = false;
  for (const auto& a : plan_.arrays) anyLoad |= !a.decl->loads.empty();
  if (anyLoad) {
    llvm::SmallString<256> dir(plan_.mainFile);
    llvm::sys::fs::make_absolute(dir);
    out_ << "  std::string source_dir = \"" << llvm::sys::path::parent_path(dir).str()
         << "\";  // where the .sph file is\n";
  }
}

std::string ScenePrinter::cellListBuildCall(
    const std::string& S, const std::string& count, const std::string& on,
    const std::function<std::string(int, const std::string&)>& coord) const {
  const char* axes[3] = {"x", "y", "z"};
  const int s = plan_.arrayIndex(S);
  std::string b = "cells_" + S + ".build(" + on;
  for (int k = 0; k < 3; ++k)
    b += ", " + (k >= plan_.dim ? std::string("nullptr") : coord(s, axes[k]));
  return b + ", " + count + ");";
}

}  // namespace sphc
