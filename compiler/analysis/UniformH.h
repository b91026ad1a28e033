// The smoothing length as one value per array (stop 45): an array whose particles all have the
// same h for the whole run, so that the CPU pair loops read it once per pass instead of per
// particle and compute hmax, the cut-off's radius and HIJ once (codegen/Bodies.cpp,
// beginUniformH; sphc --no-uniform-h: per particle, the same results bit for bit).
#pragma once

#include "sema/Plan.h"

#include <string>

namespace sphc {

// Why array `a`'s h may differ between its particles or over the run, or "" where it may not:
// its h is written by no live equation, stepper or group hook (PlanProperty::written), its
// initial value is an expression of params and constants only (no x, y, z, no other property,
// no particle index: every particle gets the same value, whatever --set gives the params), it
// loads no particles from a file, and no inlet or outlet adds, takes or changes its particles.
// (A restart restores the values written, the same for every particle; --mpi is left to the
// caller: its ghosts are not looked at.)
std::string hPerParticleReason(const Plan& plan, int a);

// The --report line: "h uniform: fluid, boundary; h per particle: inlet (why)"; `why` says
// when the pair loops read h per particle anyway (--no-uniform-h, --mpi, OpenCL).
std::string uniformHNote(const Plan& plan, const std::string& off);

}  // namespace sphc
