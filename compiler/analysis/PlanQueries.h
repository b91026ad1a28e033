// Questions about the plan that several passes (and the emitter) ask: one definition each.
#pragma once

#include <string>
#include <vector>

#include "sema/Plan.h"

namespace sphc {

// What the adaptive time step reads of a stepped, moving array (h, cs, velocities for the
// CFL limit; accelerations for the force limit). Empty without an adaptive time step.
std::vector<std::string> adaptiveDtProps(const Plan& plan);
// Arrays the adaptive time step looks at: those whose stepper moves them (writes x).
bool movesParticles(const Plan& plan, int array);

}  // namespace sphc
