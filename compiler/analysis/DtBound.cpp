// The stable bound of the time step, known before the run (docs/language.md, "Time-step
// bound"): from what the scene states of its equations, with every parameter at its default
// (sema/ConstEval.h),
//
//   acoustic  dt <= 0.25 h / (c0 (1 + 0.6 alpha))   sound_speed = c0, av_alpha = alpha
//   viscous   dt <= 0.125 h^2 / nu                  viscosity = nu (or adaptive_dt's nu)
//   force     dt <= 0.25 sqrt(h / |g|)              body_force = |g|
//
// with h the smallest initial smoothing length of the arrays that move. The factors are
// those of J. P. Morris, P. J. Fox, Y. Zhu, J. Comput. Phys. 136 (1997) 214-226 (0.25 for the
// acoustic and force limits, 0.125 for the viscous one), also those of S. Adami, X. Y. Hu,
// N. A. Adams, "A generalized wall boundary condition for SPH", J. Comput. Phys. 231 (2012)
// 7057-7075 (with the flow speed in the acoustic term); the artificial viscosity's share of
// the signal speed, 0.6 alpha c, is J. J. Monaghan's, Annu. Rev. Astron. Astrophys. 30 (1992)
// 543-574, who also gives the force limit. The flow speed is not in the acoustic term: a weakly compressible scene takes
// c0 >= 10 |v|max, so it moves the bound by 10% at most.
//
// --report states the bound and its limiting term; a fixed step (no adaptive_dt) above it is
// a warning at the `dt =` setting naming the term. The plan keeps the h it used
// (Plan::dtBoundH) so that the solver computes the same bound at start-up with the values of
// --set and reports a fixed step beyond it before it runs (codegen/DtBoundCpp.cpp).
#include "analysis/DtBound.h"
#include "analysis/Passes.h"
#include "frontend/FormatNumber.h"
#include "sema/ConstEval.h"

#include "llvm/Support/Format.h"

#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace sphc {

namespace {

// Four significant digits: a bound is an estimate.
std::string num(double v) { return formatNumber(v, 4); }

struct Term {
  std::string name;     // acoustic, viscous, force
  std::string formula;  // as the docs write it
  std::string values;   // the values it used
  std::string source;   // the literature
  double dt = HUGE_VAL;
};

}  // namespace

bool boundTimeStep(Plan& plan, DiagnosticEngine& diags) {
  if (!plan.dt) return true;
  const ast::ExprPtr nu = plan.viscosity ? plan.viscosity : plan.nu;
  if (!plan.soundSpeed && !nu && !plan.bodyForce) {
    plan.notes.push_back("time-step bound: none stated (the scene gives no sound_speed, "
                         "viscosity or body_force setting)");
    return true;
  }
  ConstEval eval(plan);

  // h: the smallest initial h of the arrays that move (an expression of params).
  std::optional<double> h;
  ast::ExprPtr hExpr;
  std::string hFrom;
  for (int a = 0; a < static_cast<int>(plan.arrays.size()); ++a) {
    const PlanArray& arr = plan.arrays[a];
    if (arr.stepper < 0 || !movesParticles(plan, a)) continue;
    const PlanProperty* p = arr.find("h");
    std::optional<double> v = p && p->init ? eval(*p->init) : std::nullopt;
    if (!v || !(*v > 0) || !std::isfinite(*v)) {
      plan.notes.push_back(
          "time-step bound: not known before the run (array '" + arr.name + "' " +
          (!p ? std::string("has no h") : !p->init ? std::string("has no initial h")
                : !v ? std::string("has an initial h that is not an expression of params")
                     : "has the initial h " + num(*v)) + ")");
      return true;
    }
    if (!h || *v < *h) hFrom = arr.name;
    h = h ? std::fmin(*h, *v) : *v;
    if (!hExpr) {
      hExpr = p->init;
    } else {
      auto call = std::make_shared<ast::Expr>();
      call->kind = ast::Expr::Call;
      call->text = "fmin";
      call->loc = p->init->loc;
      call->args = {hExpr, p->init};
      hExpr = call;
    }
  }
  if (!h) {
    plan.notes.push_back("time-step bound: none (no array moves)");
    return true;
  }

  std::vector<Term> terms;
  bool unknown = false;
  auto value = [&](const ast::ExprPtr& e) {
    std::optional<double> v = eval(e);
    if (e && (!v || !std::isfinite(*v))) {
      unknown = true;
      return std::optional<double>();
    }
    return v;
  };
  if (auto c0 = value(plan.soundSpeed)) {
    double alpha = plan.avAlpha ? value(plan.avAlpha).value_or(0.0) : 0.0;
    if (*c0 > 0)
      terms.push_back({"acoustic", dt_bound::kAcousticText,
                       "c0 = " + num(*c0) + ", alpha = " + num(alpha), dt_bound::kAcousticSource,
                       dt_bound::kAcoustic * *h / (*c0 * (1.0 + dt_bound::kAlpha * alpha))});
  }
  if (auto v = value(nu); v && *v > 0)
    terms.push_back({"viscous", dt_bound::kViscousText, "nu = " + num(*v),
                     dt_bound::kViscousSource, dt_bound::kViscous * *h * *h / *v});
  if (auto g = value(plan.bodyForce); g && std::fabs(*g) > 0)
    terms.push_back({"force", dt_bound::kForceText, "|g| = " + num(std::fabs(*g)),
                     dt_bound::kForceSource, dt_bound::kForce * std::sqrt(*h / std::fabs(*g))});
  if (unknown) {
    plan.notes.push_back("time-step bound: not known before the run (a sound_speed, av_alpha, "
                         "viscosity or body_force that is not a finite expression of params)");
    return true;
  }
  if (terms.empty()) {
    plan.notes.push_back("time-step bound: none (sound speed, viscosity and body force are 0)");
    return true;
  }
  plan.dtBoundH = hExpr;

  const Term* limiting = &terms[0];
  for (const auto& t : terms)
    if (t.dt < limiting->dt) limiting = &t;
  std::string line = "time-step bound (parameter defaults, h = " + num(*h) + " of '" + hFrom +
                     "'): dt <= " + num(limiting->dt) + ", limited by the " + limiting->name +
                     " term;";
  for (const auto& t : terms)
    line += " " + t.formula + " = " + num(t.dt) + " (" + t.values + "; " +
            t.source + ");";
  line.pop_back();
  plan.notes.push_back(line);

  std::optional<double> dt = eval(*plan.dt);
  if (!dt || !std::isfinite(*dt)) {
    plan.notes.push_back("time step: dt is not an expression of params; the solver checks it "
                         "against the bound at start-up");
    return true;
  }
  const double ratio = *dt / limiting->dt;
  if (plan.adaptiveDt) {
    plan.notes.push_back("time step: adaptive (adaptive_dt); the initial dt = " + num(*dt) +
                         " is " + num(ratio) + " of the bound");
    return true;
  }
  plan.notes.push_back("time step: fixed dt = " + num(*dt) + ", " + num(ratio) +
                       " of the bound");
  // Round-off: a scene that writes the bound itself as its dt must not be warned.
  if (ratio > 1.0 + 1e-9)
    diags.warning(plan.dt->loc,
                  "the fixed time step dt = " + num(*dt) + " is " + num(ratio) +
                      " times the stable bound " + num(limiting->dt) + " of the " +
                      limiting->formula + " (h = " + num(*h) +
                      ", " + limiting->values + "; " + limiting->source +
                      "): expect the run to blow up; take a smaller dt or adaptive_dt");
  return true;
}

}  // namespace sphc
