// sphc runtime, distributed runs (--mpi): inlets and outlets (sphc/inlet_outlet.h) over the
// ranks.
//
// Each rank runs the inlet/outlet manager's steps on its own particles: inlet particles that
// crossed the face join the fed array on their rank, source particles that entered an outlet
// move to the outlet array there, and so on (migration, sphc/mpi/decomposition.h, sends them to
// their owners at the next evaluation). What must agree between ranks goes through
// collectives, so that a run gives the serial run's particles whatever the number of ranks:
//   - fresh ids: the old gids of every particle that crossed an inlet are gathered to every
//     rank (MPI_Allgatherv) and sorted; each crossing particle takes next + its place among
//     them, inlet after inlet: the serial numbering (old-id order, sphc/inlet_outlet.h), and
//     GlobalIds::next moves on alike on every rank;
//   - the counters (created, entered, returned, removed) count every rank's particles
//     (this rank's changes summed over the ranks), as a serial run's do, so restart files and
//     the progress line say the same whatever the number of ranks;
//   - mirror, characteristic and hybrid outlets: the band of the source array their image points can
//     reach is gathered from every rank and put in gid order (the order a serial run adds it
//     in), so each outlet particle is interpolated from the same particles in the same order
//     wherever it lives; the characteristic outlet's per-bin sums of the normal velocity are
//     added over the ranks (MPI_Allreduce), so every rank holds the same running mean u_ref;
//     the hybrid outlet's means are of the fluid at the face, in the gathered band: every
//     rank adds the same particles in the same order.
// Collective: every rank calls it at the same time with the same zones.
#pragma once

#include <cstdint>
#include <vector>

#include "sphc/inlet_outlet.h"

namespace sphc::mpi {

// sphc::update_inlet_outlet over the ranks (above). Returns whether any array of this rank
// changed size.
bool update_inlet_outlet(InletOutlet& io, double t);

// The old gids of every rank's crossing particles of one inlet, ascending (collective).
std::vector<std::uint32_t> all_entering(const std::vector<std::uint32_t>& mine);

// Every rank's part of an outlet's image band, in gid order (collective).
ImageBand all_band(const ImageBand& mine);

}  // namespace sphc::mpi
