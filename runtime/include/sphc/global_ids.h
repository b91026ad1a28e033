// sphc runtime: global particle ids.
//
// Scenes whose arrays grow and shrink (inlets and outlets, sphc/inlet_outlet.h) give every
// particle a global id: the uint32 property `gid`, unique over all arrays of the scene. A
// particle keeps its gid when it moves from one array to another (an inlet particle becoming
// fluid, a fluid particle entering an outlet) and through reorders into cell order; a created
// particle takes the next unused id, and the id of a removed particle is never reused. Outputs
// carry gid, so a particle can be followed from snapshot to snapshot (for instance to count
// the particles crossing a section).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "sphc/particle_array.h"

namespace sphc {

// The ids handed out so far: the next one is `next`.
struct GlobalIds {
  std::uint32_t next = 0;
  // A fresh id; throws std::overflow_error when 2^32 ids have been used.
  std::uint32_t take();
  // The first of `count` consecutive fresh ids (next moves on by count); the same overflow.
  std::uint32_t take(std::size_t count);
};

// Adds the property gid (uint32) to every array (if absent) and numbers their particles
// 0, 1, ... array after array, in order; ids.next follows the last one.
void assign_global_ids(const std::vector<ParticleArray*>& arrays, GlobalIds& ids);

}  // namespace sphc
