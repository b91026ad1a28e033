// sphc runtime, distributed runs (--mpi): how a distributed run writes its output files.
//
// Two ways, both giving files with the serial layout (sphc/hdf5_io.h: root attributes t,
// step, dt, dim, scene; one group per array with attribute n, datasets x, y, z and the
// properties, a constants group), whatever the number of ranks:
//   - collective parallel HDF5 (MPI-IO), when sphc was built with parallel HDF5
//     (libhdf5-openmpi-dev): every rank opens the file, the groups, datasets and attributes
//     are created by all together, and each rank writes one contiguous slab of every dataset.
//     The particles are in gid order, as the gathered output and a serial run that does not
//     reorder: the gids of an array, [glo, ghi], are cut into P equal ranges, the selected
//     properties of each particle go to the rank of its range (one MPI_Alltoallv per array),
//     and rank r writes its range's particles, sorted by gid, after those of the lower
//     ranges. Where the gids are contiguous (set-up order) the ranges are equal blocks; with
//     inlets and outlets (particles created and removed, sphc/mpi/zones.h) they hold what they
//     hold, and the file is still in gid order, the same whatever the number of ranks.
//   - gathered to rank 0 (sphc/mpi/gather.h), which writes with the serial code: the fallback
//     when sphc was built without parallel HDF5, or chosen with SPHC_MPI_OUTPUT=gather in the
//     environment of the run (rank 0 then holds a copy of the whole scene at each output).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "sphc/hdf5_io.h"
#include "sphc/mpi/decomposition.h"
#include "sphc/particle_array.h"
#include "sphc/solver.h"

namespace sphc::mpi {

// Whether this build writes collectively (parallel HDF5 was found when sphc was built).
bool parallel_output_available();

// Sets prog's output to one of the two ways above. `arrays` gives this rank's arrays.
void set_output(SceneProgram& prog, std::function<std::vector<ParticleArray*>()> arrays);

// A limit's `remove` (sphc/solver.h, SceneProgram::gather_removed): each rank removes its
// own particles; the decomposition `d` of `arrays` forgets their counted work and they are
// gathered to rank 0 in gid order (sphc/mpi/gather.h), which logs them and writes the
// removed-particles file as a serial run does; the array's mass at the start is summed over
// the ranks.
void set_removal(SceneProgram& prog, Decomposition& d, std::vector<ParticleArray*> arrays);

// Collective: writes `path` (through path + ".tmp", renamed by rank 0 when complete) from
// every rank's particles of `arrays` (each rank passes its own, the same arrays and
// properties). Returns the XDMF entry of the whole file (global particle counts). Throws
// std::runtime_error without parallel HDF5.
XdmfEntry write_particles_parallel(const std::string& path, const std::string& file,
                                   const std::vector<OutputArray>& arrays,
                                   const OutputMeta& meta);

}  // namespace sphc::mpi
