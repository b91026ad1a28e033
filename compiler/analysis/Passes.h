// The analysis passes, one per file, each `bool pass(Plan&, DiagnosticEngine&)` returning
// false when it reported errors. The driver runs them in this order.
#pragma once

#include "analysis/PlanQueries.h"  // helpers the passes share
#include "frontend/Diagnostics.h"
#include "sema/Plan.h"

namespace sphc {

// analysis/Dimensions.cpp: in a 1D or 2D scene, rewrites the bodies so that the components
// the dimension leaves out (z, w, az, aw, z0, w0, ...) are read as 0 and never stored;
// foldZeros: and drops the multiply-adds' terms with such a zero factor (sphc
// --no-fold-zero-terms: false).
bool dropAbsentComponents(Plan& plan, DiagnosticEngine& diags, bool foldZeros = true);
// analysis/Pruning.cpp: marks equations whose results never reach integrated state (what
// steppers read), output, the adaptive time step or a convergence test as not live.
bool pruneEquations(Plan& plan, DiagnosticEngine& diags);
// analysis/Properties.cpp: the exact property set of every array; errors for reads that
// nothing sets, warnings for writes nothing reads and declarations nothing uses; errors for
// a body that sees a property with another type than it was checked with (each body is one
// function, one type per property name), and for `converged` writing particle properties.
bool inferProperties(Plan& plan, DiagnosticEngine& diags);
// analysis/Hazards.cpp: within one group, a loop reading a source property that an equation
// of the same group writes is an error (the result would depend on evaluation order).
bool checkHazards(Plan& plan, DiagnosticEngine& diags);
// analysis/PairQuantities.cpp: which pair quantities each (group, dest, source) loop computes.
bool selectPairQuantities(Plan& plan, DiagnosticEngine& diags);
// analysis/Ghosts.cpp: with a periodic or mirror domain, the properties ghost copies of each
// source array carry (PlanArray::ghostProps).
bool selectGhostProperties(Plan& plan, DiagnosticEngine& diags);
// analysis/DtBound.cpp: the stable bound of the time step from the scene's sound_speed,
// av_alpha, viscosity and body_force at the parameters' defaults: a --report note, and a
// warning at `dt =` for a fixed step above it; Plan::dtBoundH for the solver's own check.
bool boundTimeStep(Plan& plan, DiagnosticEngine& diags);
// analysis/InternalFlow.cpp: a warning at the scheme's use when a scene periodic along every
// axis (an internal flow) leaves off the effect its scheme names in internal_flow_needs.
bool checkInternalFlow(Plan& plan, DiagnosticEngine& diags);

}  // namespace sphc
