// The printing of restart support (--restart FILE, runtime sphc/restart.h): the scene's state
// beyond its particles that every output carries (prog.run_state), and what sets it again
// after the run loop has read a file's particles (prog.restore), and what a --restartable run
// starts afresh after each output (prog.restart_point). Kept apart so that the host
// program reads as before.
#include "codegen/Printer.h"

namespace sphc {

void ScenePrinter::emitRestart() {
  out_ << "  // --restart (sphc/restart.h): the state beyond the particles, in every output.\n";
  out_ << "  prog.run_state = [] {\n";
  out_ << "    sphc::RunState s{{\"step_count\", static_cast<double>(scene.step_count)}};\n";
  if (!sourceArrays_.empty())  // neighbour builds: every REORDER_EVERY-th reorders
    out_ << "    s.emplace_back(\"builds\", static_cast<double>(scene.builds));\n";
  if (hasZones()) out_ << "    sphc::inlet_outlet_state(scene.io, s);\n";
  out_ << "    return s;\n  };\n";
  out_ << "  prog.restore = [](const sphc::RunState& s) {\n";
  out_ << "    scene.step_count = static_cast<long>(sphc::state_value(s, \"step_count\"));\n";
  if (!sourceArrays_.empty())
    out_ << "    scene.builds = static_cast<long>(sphc::state_value(s, \"builds\"));\n";
  if (hasZones()) out_ << "    sphc::restore_inlet_outlet(scene.io, s);\n";
  out_ << restoreData();
  if (mpi_) {
    // The files of serial and distributed runs carry the same state: the re-balance schedule
    // (Decomposition::evaluations) is not in it, and restarts at 0.
    out_ << "    // Each rank read a block of the file: cut space anew and migrate.\n";
    out_ << "    sphc::mpi::rebalance(scene.decomposition, " << allArrays("scene.")
         << ");\n";
  }
  out_ << "  };\n";
  // --restartable (stop 43): what a restart cannot read from the file starts afresh after each
  // output, as in the restarted run (restartPoint: the cluster-pair tiles' layout).
  if (std::string r = restartPoint(); !r.empty())
    out_ << "  prog.restart_point = [] {  // --restartable: after each output, as in a run restarted from it\n"
         << r << "  };\n";
}

}  // namespace sphc
