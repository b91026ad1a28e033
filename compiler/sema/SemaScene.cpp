// Semantic analysis of the scene block: kernel, integrator, steppers, settings, output,
// limits and domain. Groups and equation instances are in SemaGroups.cpp.
#include "sema/SemaImpl.h"

#include "sema/Geometry.h"
#include "sema/Metrics.h"

#include "llvm/ADT/StringExtras.h"

#include <cmath>

namespace sphc::sema_detail {

void SemaImpl::buildScene() {
  const ast::SceneDecl& s = *plan_->scene;
  std::set<std::string> seen;
  static const std::vector<std::string> known = {
      "dim",         "kernel",   "tf",        "dt",        "integrator", "output_landing",
      "sound_speed", "av_alpha", "viscosity", "body_force", "internal_flow_needs"};
  for (const auto& set : s.settings) {
    const std::string& k = set.key.name;
    if (!seen.insert(k).second) {
      diags_.error(set.key.loc, "scene setting '" + k + "' is given twice");
      continue;
    }
    const ast::Expr& v = *set.value;
    if (k == "dim") {
      if (v.kind != ast::Expr::Number || (v.number != 1 && v.number != 2 && v.number != 3))
        diags_.error(v.loc, "dim must be 1, 2 or 3");
      else
        plan_->dim = static_cast<int>(v.number);
    } else if (k == "kernel") {
      const auto& ks = kernelNames();
      if (v.kind != ast::Expr::Name || std::find(ks.begin(), ks.end(), v.text) == ks.end())
        diags_.error(v.loc, "unknown kernel" +
                                (v.kind == ast::Expr::Name ? " '" + v.text + "'" : "") +
                                "; kernels are: " + joinNames(ks));
      else {
        plan_->kernel = v.text;
        plan_->kernelRadiusScale = kernelRadius(v.text);
      }
    } else if (k == "tf") {
      if (checkSceneExpr(set.value, "tf")) plan_->tf = set.value;
    } else if (k == "dt") {
      if (checkSceneExpr(set.value, "dt")) plan_->dt = set.value;
    } else if (k == "sound_speed" || k == "av_alpha" || k == "viscosity" ||
               k == "body_force") {
      // What bounds a fixed time step (analysis/DtBound.cpp, docs/language.md "Time-step
      // bound"): the reference sound speed, Monaghan's artificial-viscosity alpha, the
      // kinematic viscosity and the magnitude of the body force per unit mass.
      if (!checkSceneExpr(set.value, k)) continue;
      (k == "sound_speed" ? plan_->soundSpeed
       : k == "av_alpha"  ? plan_->avAlpha
       : k == "viscosity" ? plan_->viscosity
                          : plan_->bodyForce) = set.value;
    } else if (k == "internal_flow_needs") {
      // The effect without which the scheme is unstable in an internal flow (a scene periodic
      // along every axis): analysis/InternalFlow.cpp warns when it is off.
      if (v.kind != ast::Expr::Name)
        diags_.error(v.loc, "internal_flow_needs must name an effect (e.g. shifting)");
      else {
        plan_->internalFlowNeeds = set.value;
        plan_->internalFlowNeedsLoc = set.key.loc;
      }
    } else if (k == "output_landing") {
      // exact: steps shortened to land on output times (the default, PySPH's rule);
      // nearest_step: whole steps, outputs at the nearest step end (docs/language.md).
      if (v.kind == ast::Expr::Name && (v.text == "exact" || v.text == "nearest_step"))
        plan_->outputNearestStep = v.text == "nearest_step";
      else
        diags_.error(v.loc, "output_landing must be 'exact' (steps end on the output times) "
                            "or 'nearest_step' (whole steps; outputs at the nearest step end)");
    } else if (k == "integrator") {
      integratorGiven_ = true;
      auto it = v.kind == ast::Expr::Name ? integrators_.find(v.text) : integrators_.end();
      if (it == integrators_.end()) {
        std::vector<std::string> names;
        for (const auto& [n, d] : integrators_) names.push_back(n);
        diags_.error(v.loc, "unknown integrator" +
                                (v.kind == ast::Expr::Name ? " '" + v.text + "'" : "") +
                                (names.empty() ? std::string("; none is declared (import "
                                                             "integrators;)")
                                               : "; integrators are: " + joinNames(names)));
      } else {
        plan_->integratorName = v.text;
        for (const auto& st : it->second->steps) plan_->integratorSteps.push_back(st.name);
      }
    } else {
      diags_.error(set.key.loc, "unknown scene setting '" + k + "'; settings are: " +
                                    joinNames(known) +
                                    ", and stepper, adaptive_dt, output, equations");
    }
  }
  if (!plan_->tf) diags_.error(s.name.loc, "scene '" + s.name.name + "' has no final time: "
                                            "add `tf = ...;`");
  if (!plan_->dt) diags_.error(s.name.loc, "scene '" + s.name.name + "' has no time step: "
                                            "add `dt = ...;` (the fixed or initial step)");

  for (const auto& st : s.steppers) {
    int a = arrayFromName(st.array, "the array of a stepper");
    auto it = steppers_.find(st.stepper.name);
    if (it == steppers_.end()) {
      std::vector<std::string> names;
      for (const auto& [n, d] : steppers_) names.push_back(n);
      diags_.error(st.stepper.loc, "unknown stepper '" + st.stepper.name + "'" +
                                       (names.empty() ? std::string("")
                                                      : "; steppers are: " + joinNames(names)));
      continue;
    }
    if (a < 0) continue;
    if (plan_->arrays[a].stepper >= 0) {
      diags_.error(st.array.loc, "array '" + st.array.name + "' already has a stepper");
      continue;
    }
    plan_->arrays[a].stepper = useStepper(it->second);
  }
  bool anyStepper = false;
  for (const auto& a : plan_->arrays) anyStepper |= a.stepper >= 0;
  if (anyStepper && !integratorGiven_)
    diags_.error(s.name.loc, "scene '" + s.name.name + "' has steppers but no integrator: add "
                             "`integrator = PECIntegrator;` (import integrators;)");
  // Integrator stages must exist in the steppers that are used.
  for (const auto& step : plan_->integratorSteps)
    if (step.rfind("stage", 0) == 0)
      for (const auto& a : plan_->arrays)
        if (a.stepper >= 0 && !plan_->steppers[a.stepper].methods.count(step))
          diags_.error(plan_->steppers[a.stepper].decl->name.loc,
                       "stepper '" + plan_->steppers[a.stepper].decl->name.name +
                           "' (used for array '" + a.name + "') has no '" + step +
                           "', which integrator '" + plan_->integratorName + "' calls");

  if (s.hasAdaptiveDt) {
    plan_->adaptiveDt = true;
    for (const auto& kw : s.adaptiveDt) {
      if (kw.isList) {
        diags_.error(kw.name.loc, "adaptive_dt arguments are numbers");
        continue;
      }
      if (!checkSceneExpr(kw.value, "adaptive_dt")) continue;
      if (kw.name.name == "cfl")
        plan_->cfl = kw.value;
      else if (kw.name.name == "force")
        plan_->forceFactor = kw.value;
      else if (kw.name.name == "viscous")
        plan_->viscousFactor = kw.value;
      else if (kw.name.name == "nu")
        plan_->nu = kw.value;
      else
        diags_.error(kw.name.loc, "unknown adaptive_dt argument '" + kw.name.name +
                                      "'; arguments are: cfl, force, viscous, nu");
    }
  }

  if (plan_->viscousFactor && !plan_->nu)
    diags_.error(s.adaptiveDtLoc, "adaptive_dt: the viscous limit needs the kinematic "
                                  "viscosity: nu = ...");

  for (const auto& out : s.outputs) {
    if (out.every) {
      if (plan_->outputEvery)
        diags_.error(out.loc, "output interval given twice");
      else if (checkSceneExpr(out.every, "the output interval"))
        plan_->outputEvery = out.every;
    }
    for (const auto& t : out.at)
      if (checkSceneExpr(t, "an output time")) plan_->outputAt.push_back(t);
    for (const auto& item : out.items) {
      int a = arrayFromName(item.array, "an output");
      if (a < 0) continue;
      for (const auto& p : item.props) plan_->arrays[a].outputProps.push_back(p.name);
    }
  }

  for (size_t i = 0; i < s.domains.size(); ++i) {
    if (i > 0) {
      diags_.error(s.domains[i].loc, "the scene has a second domain; give all boundaries in one "
                                     "`domain { ... }`");
      diags_.note(s.domains[0].loc, "first domain is here");
      continue;
    }
    buildDomain(s.domains[i]);
  }

  for (const auto& l : s.limits) buildLimits(l);
  buildMetrics(s, *plan_, diags_, [this](const std::string& n) { return isParam(n); });

  plan_->root.loc = s.equationsLoc;
  buildGroup(s.equations, plan_->root, 0);
}

// The value of an expression made of literals only (numbers, pi, e, arithmetic); nothing if
// it names a parameter (whose value is known only at run time) or calls a function.
std::optional<double> literalValue(const ast::Expr& e) {
  switch (e.kind) {
    case ast::Expr::Number: return e.number;
    case ast::Expr::Name:
      if (const BuiltinConstant* b = builtinConstant(e.text); b && b->number) return b->value;
      return std::nullopt;
    case ast::Expr::Unary: {
      auto v = literalValue(*e.args[0]);
      if (!v) return std::nullopt;
      if (e.op == "-") return -*v;
      if (e.op == "+") return *v;
      return std::nullopt;
    }
    case ast::Expr::Binary: {
      auto a = literalValue(*e.args[0]), b = literalValue(*e.args[1]);
      if (!a || !b) return std::nullopt;
      if (e.op == "+") return *a + *b;
      if (e.op == "-") return *a - *b;
      if (e.op == "*") return *a * *b;
      if (e.op == "/" && *b != 0) return *a / *b;
      return std::nullopt;
    }
    default: return std::nullopt;
  }
}

// limits { ARRAY.QUANTITY warn BOUND stop BOUND; }: the array exists, each quantity is limited
// once, the bounds are scene expressions, literal intervals are not empty and a literal warn
// bound lies within the stop bound. Whether the property exists is known after the property
// analysis (analysis/Properties.cpp reports a limit on a property nothing sets).
void SemaImpl::buildLimits(const ast::LimitsDecl& d) {
  for (const auto& item : d.items) {
    const int a = arrayFromName(item.array, "a limit");
    if (a < 0) continue;
    const std::string name = item.array.name + "." + item.quantity.name;
    bool ok = true;
    for (const auto& prev : plan_->limits) {
      if (prev.array == a && prev.quantity == item.quantity.name) {
        diags_.error(item.array.loc, "limit '" + name + "' is given twice");
        diags_.note(prev.loc, "first given here");
        ok = false;
        break;
      }
    }
    auto checkBound = [&](const ast::LimitBound& b, const char* kind) {
      for (const auto* e : {&b.lo, &b.hi})
        if (*e) ok &= checkSceneExpr(*e, "a limit (it may use params)");
      if (!ok || !b.lo || !b.hi) return;
      auto lo = literalValue(*b.lo), hi = literalValue(*b.hi);
      if (lo && hi && !(*lo <= *hi)) {
        diags_.error(b.lo->loc, std::string("empty ") + kind + " interval of limit '" + name +
                                    "': the low end must not be above the high end");
        ok = false;
      }
    };
    if (item.warn) checkBound(*item.warn, "warn");
    if (item.stop) checkBound(*item.stop, "stop");
    if (item.remove) {
      // Particles leave the run only by leaving a region of space: a position, and a
      // condition on another coordinate of the scene's dimension.
      static const char* kAxes[3] = {"x", "y", "z"};
      auto axis = [&](const std::string& q) {
        for (int k = 0; k < 3; ++k)
          if (q == kAxes[k]) return k;
        return -1;
      };
      const int qa = axis(item.quantity.name);
      if (qa < 0) {
        diags_.error(item.remove->loc,
                     "'remove' in limit '" + name + "' takes out the particles that leave a "
                     "region of space: its quantity is a position (x, y or z), not '" +
                         item.quantity.name + "' (a bound on '" + item.quantity.name +
                         "' is 'warn' or 'stop')");
        ok = false;
      } else if (qa >= plan_->dim) {
        diags_.error(item.quantity.loc, "'" + item.quantity.name + "' is beyond the scene's " +
                                            llvm::Twine(plan_->dim) + " dimension" +
                                            (plan_->dim == 1 ? "" : "s") + " (dim = " +
                                            llvm::Twine(plan_->dim) + ")");
        ok = false;
      }
      checkBound(*item.remove, "remove");
      if (!item.removeWhere.name.empty()) {
        const int wa = axis(item.removeWhere.name);
        if (wa < 0) {
          diags_.error(item.removeWhere.loc,
                       "the condition of 'remove' in limit '" + name + "' is on a coordinate "
                       "(x, y or z), not '" + item.removeWhere.name + "'");
          ok = false;
        } else if (wa == qa) {
          diags_.error(item.removeWhere.loc,
                       "the condition of 'remove' in limit '" + name + "' is on '" +
                           item.removeWhere.name + "' itself: give the bound of '" +
                           item.removeWhere.name + "' in 'remove [lo, hi]', and the condition "
                           "on another coordinate");
          ok = false;
        } else if (wa >= plan_->dim) {
          diags_.error(item.removeWhere.loc,
                       "'" + item.removeWhere.name + "' is beyond the scene's " +
                           llvm::Twine(plan_->dim) + " dimension" + (plan_->dim == 1 ? "" : "s") +
                           " (dim = " + llvm::Twine(plan_->dim) + ")");
          ok = false;
        }
        checkBound(*item.removeWhereBound, "'where'");
      }
    }
    if (!ok) continue;
    if (item.warn && item.stop) {
      // A warn bound outside the stop bound would never warn: said when both are literals.
      auto outside = [&](const ast::ExprPtr& w, const ast::ExprPtr& st, bool low) {
        if (!st || !w) return false;  // an unbounded side: no bound to compare
        auto wv = literalValue(*w), sv = literalValue(*st);
        return wv && sv && (low ? *wv < *sv : *wv > *sv);
      };
      if (outside(item.warn->lo, item.stop->lo, true) ||
          outside(item.warn->hi, item.stop->hi, false)) {
        diags_.error(item.warn->loc, "the warn bound of limit '" + name +
                                         "' reaches beyond its stop bound; it would never warn");
        diags_.note(item.stop->loc, "the stop bound is here");
        continue;
      }
    }
    PlanLimit l;
    l.loc = item.array.loc;
    l.array = a;
    l.quantity = item.quantity.name;
    if (item.warn) {
      l.hasWarn = true;
      l.warnLo = item.warn->lo;
      l.warnHi = item.warn->hi;
    }
    if (item.stop) {
      l.hasStop = true;
      l.stopLo = item.stop->lo;
      l.stopHi = item.stop->hi;
    }
    auto& props = plan_->arrays[a].limitProps;
    if (item.remove) {
      l.hasRemove = true;
      l.removeLoc = item.remove->loc;
      l.removeLo = item.remove->lo;
      l.removeHi = item.remove->hi;
      l.removeWhere = item.removeWhere.name;
      if (item.removeWhereBound) {
        l.whereLo = item.removeWhereBound->lo;
        l.whereHi = item.removeWhereBound->hi;
        props.push_back(l.removeWhere);
      }
    }
    if (l.quantity == "speed") {
      static const char* kVel[3] = {"u", "v", "w"};
      for (int k = 0; k < plan_->dim; ++k) props.push_back(kVel[k]);
    } else {
      props.push_back(l.quantity);
    }
    plan_->limits.push_back(std::move(l));
  }
}

void SemaImpl::buildDomain(const ast::DomainDecl& d) {
  PlanDomain& dom = plan_->domain;
  dom.loc = d.loc;
  static const char* kAxes[3] = {"x", "y", "z"};
  for (const auto& item : d.items) {
    const bool periodic = item.kind == ast::DomainItem::Periodic;
    const std::string what = periodic ? "periodic" : "mirror";
    int a = -1;
    for (int k = 0; k < 3; ++k)
      if (item.axis.name == kAxes[k]) a = k;
    if (a < 0) {
      diags_.error(item.axis.loc, "unknown axis '" + item.axis.name + "' in the domain; axes "
                                  "are x, y and z");
      continue;
    }
    if (a >= plan_->dim) {
      diags_.error(item.axis.loc, "axis '" + item.axis.name + "' is beyond the scene's " +
                                      llvm::Twine(plan_->dim) + " dimension" +
                                      (plan_->dim == 1 ? "" : "s") + " (dim = " +
                                      llvm::Twine(plan_->dim) + ")");
      continue;
    }
    if (periodic && (!item.lo || !item.hi)) {
      diags_.error(item.loc, "a periodic axis needs both ends: periodic " + item.axis.name +
                                 " in [lo, hi]");
      continue;
    }
    bool ok = true;
    for (const auto* e : {&item.lo, &item.hi})
      if (*e) ok &= checkSceneExpr(*e, "the domain (it may use params)");
    if (!ok) continue;
    if (item.lo && item.hi) {
      auto lo = literalValue(*item.lo), hi = literalValue(*item.hi);
      if (lo && hi && !(*lo < *hi)) {
        diags_.error(item.lo->loc, "empty interval for axis '" + item.axis.name +
                                       "': the low end must be below the high end");
        continue;
      }
    }
    // Each side of an axis has one boundary.
    auto setSide = [&](PlanBoundary& side, const ast::ExprPtr& at, const char* sideName) {
      if (side.kind != PlanBoundary::Open) {
        const bool same = (side.kind == PlanBoundary::Periodic) == periodic;
        diags_.error(item.loc, std::string("the ") + sideName + " side of axis '" +
                                   item.axis.name + "' " +
                                   (same ? "is given twice"
                                         : std::string("is both periodic and a mirror")));
        diags_.note(side.loc, "first given here");
        return;
      }
      side.kind = periodic ? PlanBoundary::Periodic : PlanBoundary::Mirror;
      side.at = at;
      side.loc = item.loc;
    };
    if (periodic && (dom.lo[a].kind != PlanBoundary::Open || dom.hi[a].kind != PlanBoundary::Open)) {
      const PlanBoundary& prev = dom.lo[a].kind != PlanBoundary::Open ? dom.lo[a] : dom.hi[a];
      const bool same = prev.kind == PlanBoundary::Periodic;
      diags_.error(item.loc, "axis '" + item.axis.name + "' " +
                                 (same ? std::string("is periodic twice")
                                       : std::string("is both periodic and a mirror")));
      diags_.note(prev.loc, "first given here");
      continue;
    }
    if (item.lo) setSide(dom.lo[a], item.lo, "low");
    if (item.hi) setSide(dom.hi[a], item.hi, "high");
  }
}

}  // namespace sphc::sema_detail
