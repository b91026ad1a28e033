// The entry points of code generation: the printer of the chosen backend prints the schedule.
#include "codegen/CppEmitter.h"

#include "codegen/Printer.h"

namespace sphc {

const char* backendName(Backend b) {
  switch (b) {
    case Backend::Serial: return "serial";
    case Backend::OpenMP: return "openmp";
    case Backend::OpenCL: return "opencl";
  }
  return "serial";
}

std::string emitCpp(const Schedule& sched, const DiagnosticEngine& diags,
                    const EmitOptions& opts) {
  auto printer = opts.backend == Backend::OpenCL ? makeOpenCLPrinter(sched, diags, opts)
                                                 : makeCpuPrinter(sched, diags, opts);
  return printer->run();
}

std::vector<std::string> pairLoopNotes(const Schedule& sched, const DiagnosticEngine& diags,
                                       const EmitOptions& opts) {
  auto printer = opts.backend == Backend::OpenCL ? makeOpenCLPrinter(sched, diags, opts)
                                                 : makeCpuPrinter(sched, diags, opts);
  return printer->pairLoopNotes(opts);
}

std::string emitOpenCL(const Schedule& sched, const DiagnosticEngine& diags, EmitOptions opts) {
  opts.backend = Backend::OpenCL;
  return makeOpenCLPrinter(sched, diags, opts)->kernelSource();
}

}  // namespace sphc
