// sphc runtime, distributed runs (--mpi): output with the serial layout, gathered to rank 0.
//
// A first step towards collective parallel HDF5 output: before each output the particles of
// every array are gathered to rank 0 (MPI_Gatherv of every property) and sorted by their
// global id `gid` (the set-up order), and rank 0 writes the usual files (sphc/hdf5_io.h), so
// post-processing does not care how many ranks ran. Rank 0 then holds a copy of the whole
// scene at each output, which bounds the scenes this suits by rank 0's memory.
#pragma once

#include <vector>

#include "sphc/particle_array.h"

namespace sphc::mpi {

// Collective. On rank 0 `out` receives one array per input array (every property, the
// particles of all ranks in gid order); on the other ranks the arrays are empty (n = 0, same
// properties). `out` keeps its storage between calls.
void gather_arrays(const std::vector<ParticleArray*>& arrays, std::vector<ParticleArray>& out);

}  // namespace sphc::mpi
