// Inlets and outlets of a scene (docs/language.md, Inlets and outlets): the scene's
// `inlet NAME(...)` and `outlet NAME(...)` into Plan::zones, with their checks. Values are
// checked with the parameters' defaults (the runtime checks them again with the values of
// --set: sphc/inlet_outlet.h).
#pragma once

#include "frontend/AST.h"
#include "frontend/Diagnostics.h"
#include "sema/Plan.h"

namespace sphc {

// Fills plan.zones from scene.zones (after the arrays, params and steppers are in the plan);
// reports located errors. Returns false on an error.
bool buildZones(const ast::SceneDecl& scene, Plan& plan, DiagnosticEngine& diags);

}  // namespace sphc
