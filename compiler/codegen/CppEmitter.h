// The serial C++ code generator: a Plan to one readable C++ file that includes the runtime
// headers and defines `main`. Every equation and stepper body becomes an inline function
// holding the body as written (with `// from file.sph:line` provenance); each group becomes
// a function per destination with one fused neighbour pass per source.
#pragma once

#include "frontend/Diagnostics.h"
#include "sema/Plan.h"

#include <string>

namespace sphc {

struct EmitOptions {
  std::string backend = "serial";
};

std::string emitCpp(const Plan& plan, const DiagnosticEngine& diags, const EmitOptions& opts);

}  // namespace sphc
