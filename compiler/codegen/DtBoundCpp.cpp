// The set-up code of the stable time-step bound (codegen/DtBoundCpp.h): the same terms as
// analysis/DtBound.cpp, from the same expressions, evaluated with the values of --set.
#include "codegen/DtBoundCpp.h"

#include "analysis/DtBound.h"
#include "frontend/FormatNumber.h"

namespace sphc {

namespace {

std::string quoted(const std::string& s) { return "\"" + s + "\""; }

}  // namespace

std::string dtBoundSetupCpp(const Plan& plan, const NameMap& names, const std::string& indent) {
  if (!plan.dtBoundH) return "";
  const std::string in = indent + "  ";
  std::string s = indent + "{  // the stable bound of a fixed step (analysis/DtBound.cpp)\n";
  s += in + "const double h = " + exprCpp(*plan.dtBoundH, names) + ";\n";
  auto term = [&](const char* text, const char* source, const std::string& dt,
                  const std::string& values) {
    s += in + "sphc::bound_dt(times, " + dt + ", sphc::dt_bound_text(" + quoted(text) + ", " +
         quoted(source) + ", h, {" + values + "}));\n";
  };
  if (plan.soundSpeed) {
    std::string c0 = exprCpp(*plan.soundSpeed, names);
    std::string alpha = plan.avAlpha ? exprCpp(*plan.avAlpha, names) : "0.0";
    s += in + "const double c0 = " + c0 + ", alpha = " + alpha + ";\n";
    term(dt_bound::kAcousticText, dt_bound::kAcousticSource,
         exactNumber(dt_bound::kAcoustic) + " * h / (c0 * (1.0 + " +
             exactNumber(dt_bound::kAlpha) + " * alpha))",
         "{\"c0\", c0}, {\"alpha\", alpha}");
  }
  const ast::ExprPtr nu = plan.viscosity ? plan.viscosity : plan.nu;
  if (nu) {
    s += in + "const double nu = " + exprCpp(*nu, names) + ";\n";
    term(dt_bound::kViscousText, dt_bound::kViscousSource,
         "nu > 0 ? " + exactNumber(dt_bound::kViscous) + " * h * h / nu : HUGE_VAL",
         "{\"nu\", nu}");
  }
  if (plan.bodyForce) {
    s += in + "const double g = std::fabs(" + exprCpp(*plan.bodyForce, names) + ");\n";
    term(dt_bound::kForceText, dt_bound::kForceSource,
         "g > 0 ? " + exactNumber(dt_bound::kForce) + " * std::sqrt(h / g) : HUGE_VAL",
         "{\"|g|\", g}");
  }
  s += indent + "}\n";
  return s;
}

}  // namespace sphc
