// Whether the scene reads particle positions only as differences and increments
// (analysis/PositionReads.cpp): where it does, a periodic axis may wrap the particles lazily,
// between the permutations, and the neighbour lists be kept with the ghosts by default.
#pragma once

#include "sema/Plan.h"

#include <string>
#include <vector>

namespace sphc {

struct PositionReads {
  // "": positions are read only as copies and increments, or by the groups of wrapBefore;
  // else what reads them (for --report).
  std::string refusal;
  // Top-level groups of `equations` with a condition of t, dt and params that read positions:
  // every particle is wrapped into the box before an evaluation where the condition holds.
  std::vector<const PlanGroup*> wrapBefore;
  std::string reader;  // the first body reading a position (with wrapBefore)
};

PositionReads positionReads(const Plan& plan);

}  // namespace sphc
