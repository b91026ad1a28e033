// The smoothing length as one value per array (analysis/UniformH.h; stop 45).
#include "analysis/UniformH.h"

#include "sema/ConstEval.h"
#include "sema/Sema.h"

#include <cmath>
#include <optional>
#include <set>

namespace sphc {

std::string hPerParticleReason(const Plan& plan, int a) {
  const PlanArray& arr = plan.arrays[a];
  const PlanProperty* h = arr.find("h");
  if (!h) return "it has no h";
  if (h->written) return "an equation, stepper or group hook writes h";
  if (arr.decl && !arr.decl->loads.empty()) return "its particles are loaded from a file";
  for (const PlanZone& z : plan.zones)
    if (z.array == a || z.other == a)
      return std::string("the ") + (z.inlet ? "inlet" : "outlet") + " '" + z.name +
             "' adds or takes its particles";
  if (!h->init) return "h has no initial value of its own";
  std::set<std::string> names, params;
  namesOf(*h->init, names);
  for (const auto* p : plan.params) params.insert(p->name.name);
  for (const std::string& n : names)
    if (!params.count(n) && !builtinConstant(n))
      return "its initial h reads " + n;
  const std::optional<double> v = ConstEval(plan)(*h->init);
  if (!v || !std::isfinite(*v)) return "its initial h is not an expression of params";
  return "";
}

std::string uniformHNote(const Plan& plan, const std::string& off) {
  std::string uniform, perParticle;
  for (int a = 0; a < static_cast<int>(plan.arrays.size()); ++a) {
    if (!plan.arrays[a].find("h")) continue;  // (no h: in no pair loop)
    const std::string why = hPerParticleReason(plan, a);
    if (why.empty())
      uniform += (uniform.empty() ? "" : ", ") + plan.arrays[a].name;
    else
      perParticle += (perParticle.empty() ? "" : ", ") + plan.arrays[a].name + " (" + why + ")";
  }
  std::string note;
  if (!uniform.empty()) note = "h uniform: " + uniform;
  if (!perParticle.empty()) note += (note.empty() ? "" : "; ") + std::string("h per particle: ") + perParticle;
  if (!uniform.empty() && !off.empty())
    note += " (the pair loops read h per particle: " + off + ")";
  else if (!uniform.empty())
    note += " (the CPU pair loops read it once per pass)";
  return note;
}

}  // namespace sphc
