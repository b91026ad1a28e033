#include "analysis/PlanQueries.h"

#include "analysis/Access.h"

namespace sphc {

std::vector<std::string> adaptiveDtProps(const Plan& plan) {
  std::vector<std::string> props;
  if (!plan.adaptiveDt) return props;
  props = {"h"};
  std::vector<std::string> vel = {"u", "v", "w"}, acc = {"au", "av", "aw"};
  vel.resize(plan.dim);
  acc.resize(plan.dim);
  if (plan.cfl || !plan.forceFactor) {
    props.push_back("cs");
    props.insert(props.end(), vel.begin(), vel.end());
  }
  if (plan.forceFactor) props.insert(props.end(), acc.begin(), acc.end());
  return props;
}

bool movesParticles(const Plan& plan, int array) {
  for (const auto& a : stepperAccesses(plan, array))
    if (a.write && a.prop == "x") return true;
  return false;
}

}  // namespace sphc
