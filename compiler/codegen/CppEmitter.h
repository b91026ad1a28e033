// The serial C++ code generator: a Plan to one readable C++ file that includes the runtime
// headers and defines `main`. Every equation and stepper body becomes an inline function
// holding the body as written (with `// from file.sph:line` provenance); each group becomes
// a function per destination with one fused neighbour pass per source. --backend=opencl
// shares all of it but the execution of phases, steppers, neighbour search and adaptive dt:
// those become OpenCL C kernels (the same bodies, typed `real`) launched from the host code.
#pragma once

#include "codegen/Schedule.h"
#include "frontend/Diagnostics.h"
#include "sema/Plan.h"

#include <string>

namespace sphc {

// The backends: each is a printer of the schedule (codegen/*Printer.cpp).
enum class Backend { Serial, OpenMP, OpenCL };
// What the scene computes in: double, or single (float).
enum class Precision { Double, Single };
// "serial", "openmp", "opencl": as on the command line, in prog.backend and the build.
const char* backendName(Backend b);

struct EmitOptions {
  Backend backend = Backend::Serial;
  Precision precision = Precision::Double;
};

// The solver's C++ for a schedule (codegen/Schedule.h) of an analysed plan.
std::string emitCpp(const Schedule& sched, const DiagnosticEngine& diags,
                    const EmitOptions& opts);
// --backend=opencl: the OpenCL C of the scene's kernels alone (what --emit=opencl prints).
std::string emitOpenCL(const Schedule& sched, const DiagnosticEngine& diags, EmitOptions opts);

}  // namespace sphc
