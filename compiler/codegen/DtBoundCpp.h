// The solver's own check of a fixed time step (analysis/DtBound.cpp): the set-up code that
// computes the stable bound with the actual parameters into SceneTimes (sphc/solver.h).
#pragma once

#include "codegen/CppText.h"
#include "sema/Plan.h"

#include <string>

namespace sphc {

// Statements for the scene's setup() (`times` in scope; parameters spelled by `names`), or ""
// when the plan has no bound (Plan::dtBoundH null).
std::string dtBoundSetupCpp(const Plan& plan, const NameMap& names, const std::string& indent);

}  // namespace sphc
