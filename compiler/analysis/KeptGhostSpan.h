// Whether the domain is wide enough for the neighbour lists kept across steps on a periodic or
// mirror domain (analysis/KeptGhostSpan.cpp).
#pragma once

#include "sema/Plan.h"

#include <string>

namespace sphc {

// With kept lists a particle may sit up to kKeptWrapMargin supports outside a periodic box
// between permutations (the printer's WRAP_MARGIN), so the ghosts reach (1 + skin +
// kKeptWrapMargin) supports past each side, and the runtime makes one image per side: an axis
// with images on both sides must span that much (sphc::check_ghost_span at run time).
inline constexpr double kKeptWrapMargin = 0.5;

// With the parameter defaults (sema/ConstEval.h): why an axis is too narrow for kept lists
// with this skin ("...: x spans 0.0004 < 1.6 supports of 0.000375"), or "" when every such
// axis is wide enough or a span or h is not known before the run (then the solver checks).
std::string keptGhostSpanRefusal(const Plan& plan, double skin);

}  // namespace sphc
