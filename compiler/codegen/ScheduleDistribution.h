// The distributed part of the schedule (sphc --mpi): see Distribution in codegen/Schedule.h.
#pragma once

#include "codegen/Schedule.h"

namespace sphc {

// Every array migrates; every array with a cell list gets a halo carrying its ghost
// properties (analysis/Ghosts). Disabled unless plan.distributed.
Distribution distributionOf(const Plan& plan, const std::vector<int>& cellLists);

// Its lines in --dump-after=schedule (nothing when disabled).
void printDistribution(const Schedule& s, llvm::raw_ostream& os);

}  // namespace sphc
