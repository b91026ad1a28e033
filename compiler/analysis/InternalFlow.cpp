// The internal-flow check: a warning when a scheme is used in an internal flow without the
// effect it states it needs there (docs/stability.md, "Internal flows: the compile-time
// warning").
//
// A scheme states the effect with the setting `internal_flow_needs = EFFECT;`
// (stdlib/wcsph_scheme.sph: `shifting`). An internal flow is, for sphc, a scene whose domain
// is periodic along every axis of its dimension: no wall, inlet, outlet or mirror bounds the
// fluid, so no free surface forms at the domain's edges and nothing but the scheme's own
// terms reorders the particles (the Taylor-Green vortex, a periodic shear layer). A fluid
// that fills only part of a periodic box (a drop in vacuum) is taken for one as well: the
// warning is then a false alarm, and a warning only.
#include "analysis/Passes.h"

#include <string>

namespace sphc {

bool checkInternalFlow(Plan& plan, DiagnosticEngine& diags) {
  if (!plan.internalFlowNeeds) return true;
  const std::string& name = plan.internalFlowNeeds->text;
  const ChosenOption* effect = nullptr;
  for (const auto& o : plan.options)
    if (o.isEffect && o.name == name) effect = &o;
  if (!effect) {
    diags.error(plan.internalFlowNeeds->loc,
                "internal_flow_needs names '" + name + "', which is not an effect (effects "
                "are declared with `effect NAME \"doc\";`, stdlib/effects.sph)");
    return false;
  }
  if (effect->on()) return true;
  static const char* axes[] = {"x", "y", "z"};
  std::string along;
  for (int a = 0; a < plan.dim; ++a) {
    if (plan.domain.lo[a].kind != PlanBoundary::Periodic) return true;
    along += std::string(a == 0 ? "" : a + 1 == plan.dim ? " and " : ", ") + axes[a];
  }
  diags.warning(plan.internalFlowNeedsLoc,
                "an internal flow (the domain is periodic along " + along +
                    ": no wall, open boundary or free surface) without the effect '" + name +
                    "', which this scheme needs there: nothing else reorders the particles, "
                    "the flow's strain lines them up until they clump, and the run loses its "
                    "accuracy (docs/stability.md, \"Internal flows\")");
  diags.note(plan.internalFlowNeedsLoc,
             "add it to the scene's effects, `effects = [..., " + name +
                 "];` (or compile with `-D " + name + "=on`): " + effect->doc +
                 "; the scheme declares the properties its equations need");
  diags.note(plan.internalFlowNeeds->loc,
             "the scheme names '" + name + "' as needed in an internal flow here");
  return true;
}

}  // namespace sphc
