// sphc runtime, distributed runs (--mpi): the halo, remote particles within the interaction
// radius of a rank's particles, exchanged before every neighbour pass.
//
// The halo plays the part of the ghosts of a serial run (sphc/domain.h) and replaces them: a
// rank appends to each array that is a neighbour source, after its n real particles, copies of
//   - the particles of other ranks whose regions lie within `cutoff` of them, and
//   - the periodic and mirror images (the ghosts of domain.h: same images, same transforms)
//     of every rank's particles, its own included, that fall within `cutoff` of its region.
// A particle is sent, for each of its images (none, and those find_ghosts makes: within
// `cutoff` of a periodic or mirror side), to every rank whose region meets the box of half
// width `cutoff` around the image (sphc/mpi/decomposition.h, ranks_near), except its own rank
// without an image. So every particle within `cutoff` of a rank's real particle, real or
// image, is there during an evaluation, which is what a neighbour loop needs.
//
// Only the properties `carried` are sent (the compiler's ghost pass: what the loops read of a
// source, and what `real = false` groups read), transformed as ghosts are (positions shifted
// or reflected, the normal velocity negated at a mirror). `ParticleArray::n` stays the real
// count; remove_halo shrinks the storage back. refresh_halo sends the same particles again
// with other properties (after a phase wrote a carried property on the real particles).
// Collective: every rank calls these for the same arrays in the same order.
//
// Order: by sending rank, then by the sender's particle, then image: deterministic for a
// given rank count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "sphc/domain.h"
#include "sphc/mpi/decomposition.h"
#include "sphc/particle_array.h"

namespace sphc::mpi {

struct Halo {
  // Sender side, per destination rank: local particle and image bits (as sphc::Ghosts).
  std::vector<std::vector<std::uint32_t>> send_index;
  std::vector<std::vector<std::uint8_t>> send_image;
  // Receiver side: particles received from each rank, in rank order.
  std::vector<int> recv_count;
  std::size_t count = 0;       // halo particles now appended (sum of recv_count)
  std::size_t bytes_sent = 0;  // all exchanges since the last reset_bytes (measurement)
  std::size_t size() const { return count; }
};

// Finds what to send (as above), exchanges the properties `carried` (indices into a.props) and
// appends the received particles after a.n. Returns the halo size.
std::size_t exchange_halo(const Decomposition& dec, const Domain& d, ParticleArray& a,
                          double cutoff, Halo& h, const std::vector<int>& carried);

// Sends the properties `props` of the same particles again into the halo's storage.
void refresh_halo(const Domain& d, ParticleArray& a, Halo& h, const std::vector<int>& props);

// Storage back to a.n particles.
void remove_halo(ParticleArray& a, Halo& h);

// With SPHC_MPI_STATS set in the environment, prints one line per rank to stderr: evaluations,
// re-balances, particles migrated away, halo bytes sent (all exchanges and refreshes) in
// total and per evaluation, the latest halo size per array (`arrays`: the source arrays, with
// their `halos`); for `all` the arrays (in the decomposition's order): counts, the counted
// work of the last evaluation, the weights of the last cut (sphc/mpi/decomposition.h). Not
// collective (a measurement for docs/scaling.md; generated main calls it after the run).
void report_stats(const Decomposition& dec, const std::vector<const ParticleArray*>& arrays,
                  const std::vector<const Halo*>& halos,
                  const std::vector<const ParticleArray*>& all);

// The search domain of the real particles and halos of `arrays` (positions over n + halo),
// cells of cutoff = radius_scale * the largest h of any rank: the same cell size everywhere.
// Collective (the h maximum).
SearchDomain halo_search_domain(const std::vector<const ParticleArray*>& arrays,
                                const std::vector<std::size_t>& halo_sizes, int dim,
                                double radius_scale);
// The interaction radius of the whole job: radius_scale * max h over every rank's particles.
double global_cutoff(const std::vector<const ParticleArray*>& arrays, double radius_scale);

}  // namespace sphc::mpi
