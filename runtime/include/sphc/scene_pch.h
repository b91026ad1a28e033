// sphc runtime: the headers a generated CPU solver (serial, openmp) may include, in one
// header that the build precompiles (runtime/CMakeLists.txt: scene_pch.h.gch/serial.gch and
// openmp.gch, with the default flags of buildinfo.txt). sphc passes `-include
// sphc/scene_pch.h` when it builds a solver with those flags (compiler/driver/Build.cpp):
// GCC then loads the precompiled state in place of parsing these headers and the standard
// library (~1 s of a cold build), and falls back to this text where the precompiled header
// does not match the compile (another compiler, CPU or flags). The generated code's own
// #include lines follow and find everything here already included. The object code is the
// same either way.
// cluster_pairs.h (the tiles' helpers) must be here too (stop 44): parsed in a solver's unit
// after the precompiled state, its <immintrin.h> (target pragmas that push and pop the
// options) left the unit without the pair loops at -O3 in spite of its -Og (its object code
// was -O3's byte for byte), and both units parsed the intrinsics: 0.8 and 0.4 s more CPU for
// the own dam break (docs/performance-log.md "Cold compile back under 3 s (stop 44)").
// An include guard, not #pragma once: GCC warns about the latter in a header compiled alone.
#ifndef SPHC_SCENE_PCH_H
#define SPHC_SCENE_PCH_H

#include "sphc/cluster_pairs.h"
#include "sphc/cross_pairs.h"
#include "sphc/domain.h"
#include "sphc/float_arrays.h"
#include "sphc/geometry.h"
#include "sphc/global_ids.h"
#include "sphc/inlet_outlet.h"
#include "sphc/kernels.h"
#include "sphc/load.h"
#include "sphc/metrics.h"
#include "sphc/nnps.h"
#include "sphc/particle_array.h"
#include "sphc/pow.h"
#include "sphc/restart.h"
#include "sphc/solver.h"
#include "sphc/verlet.h"
#include "sphc/verlet_tune.h"

#include <math.h>
#include <cmath>
#include <cstdint>
#include <vector>

#endif  // SPHC_SCENE_PCH_H
