// sphc runtime, distributed runs (--mpi): domain decomposition with Zoltan and migration of
// particles between ranks.
//
// Each rank owns the particles in its region of space. Zoltan (Sandia's load-balancing
// library, Debian libtrilinos-zoltan-dev) cuts space by recursive coordinate bisection (RCB,
// the default) or along a Hilbert space-filling curve (HSFC) into as many regions as ranks,
// with about equal particle counts (all arrays together, one weight per particle), and keeps
// the cuts, so that
//   - owner(point) (Zoltan_LB_Point_Assign) says which rank owns a position: migration moves
//     each particle that left its rank's region to the owner, with every property;
//   - ranks_near(box) (Zoltan_LB_Box_Assign) lists the ranks whose regions meet a box: the
//     halo exchange (sphc/mpi/halo.h) sends a particle to every rank whose region lies within
//     the interaction radius of it.
// The regions of RCB and HSFC cover all of space, so every position has an owner.
//
// Set-up is replicated: every rank runs the scene's set-up (the same particles in the same
// order), then distribute() numbers the particles (`gid`, a uint32 property: the set-up
// index, the same on every rank and in a serial run) and keeps a block of them per rank, and
// rebalance() cuts space and migrates. Between re-balances particles move and migrate() sends
// the leavers to their owners; a re-balance happens every `rebalance_every` evaluations and
// whenever the imbalance (largest rank's particle count over the mean) exceeds
// `imbalance_limit`.
//
// Order. Migration keeps the staying particles in their order and appends the arrivals by
// sending rank, each in the sender's order: for a given rank count, runs are deterministic.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "sphc/particle_array.h"

struct Zoltan_Struct;

namespace sphc::mpi {

struct Decomposition {
  Zoltan_Struct* zz = nullptr;
  int dim = 2;
  std::string method = "RCB";     // Zoltan's LB_METHOD: RCB or HSFC
  long rebalance_every = 100;     // evaluations between re-balances (0: only on imbalance)
  double imbalance_limit = 1.1;   // re-balance when max/mean particles per rank exceeds it
  long evaluations = 0;           // calls of update()
  long rebalances = 0;
  long migrated = 0;              // particles this rank sent by migration, all arrays
  bool cut = false;               // Zoltan has cuts (after the first rebalance)
  // Per array (in the order the arrays are passed): the work of one particle, Zoltan's object
  // weight (set_weights); empty: every particle weighs 1.
  std::vector<double> weights;
  // RCB: this rank's region, a box (Zoltan_RCB_Box; infinite on outer sides). A point strictly
  // inside it is this rank's without asking Zoltan, and a particle whose interaction box lies
  // strictly inside it is in no other rank's halo (the fast path of migrate and the halo).
  bool has_region = false;
  double region_lo[3] = {0, 0, 0}, region_hi[3] = {0, 0, 0};

  Decomposition() = default;
  Decomposition(const Decomposition&) = delete;
  Decomposition& operator=(const Decomposition&) = delete;
  ~Decomposition();
};

// Creates the Zoltan structure (MPI must be initialised). method: "RCB" or "HSFC" (else
// std::invalid_argument).
void init_decomposition(Decomposition& d, int dim, const std::string& method = "RCB");

// Weights the particles of each array by `per_array` (the compiler's work estimate: RCB then
// gives each rank about equal work, not equal particle counts; the imbalance that triggers a
// re-balance is measured in the same weights). Before distribute. SPHC_MPI_UNWEIGHTED=1 in
// the environment leaves the weights out (a measurement switch).
void set_weights(Decomposition& d, const std::vector<double>& per_array);

// After a replicated set-up: adds `gid` (U32, unique over the arrays in set-up order:
// sphc/global_ids.h) to every array, keeps the block [r n / P, (r + 1) n / P) of each array
// on rank r, then rebalance().
void distribute(Decomposition& d, const std::vector<ParticleArray*>& arrays);

// Cuts space anew from the current particles (Zoltan_LB_Partition) and migrates.
void rebalance(Decomposition& d, const std::vector<ParticleArray*>& arrays);

// Sends every particle whose owner is another rank to it (all properties), appends the
// arrivals. Returns the number of particles this rank sent.
std::size_t migrate(Decomposition& d, const std::vector<ParticleArray*>& arrays);

// The step of an evaluation: migrate, then rebalance when due (every rebalance_every
// evaluations, or the imbalance above the limit). Collective.
void update(Decomposition& d, const std::vector<ParticleArray*>& arrays);

// Largest particle count of a rank over the mean (1 = perfect balance). Collective.
double imbalance(const std::vector<ParticleArray*>& arrays);
// The same in d's weights (the particle count without weights).
double imbalance(const Decomposition& d, const std::vector<ParticleArray*>& arrays);

// Whether the box [lo, hi] lies strictly inside this rank's region (false without one).
bool inside_region(const Decomposition& d, const double lo[3], const double hi[3]);

// The rank owning a position (pos[0..dim-1]).
int owner(const Decomposition& d, const double pos[3]);
// The ranks whose regions meet the box [lo, hi] (into `ranks`, ascending).
void ranks_near(const Decomposition& d, const double lo[3], const double hi[3],
                std::vector<int>& ranks);

// Packs particle i's properties (every one, every component, integers as exact doubles) at
// the end of `buf`; unpack_particle writes particle j (storage already sized) from the
// packed_size(a) values at `buf`. Both sides have the same property list (the same scene).
void pack_particle(const ParticleArray& a, std::size_t i, std::vector<double>& buf);
void unpack_particle(ParticleArray& a, std::size_t j, const double* buf);
// Values per particle of pack_particle.
std::size_t packed_size(const ParticleArray& a);

}  // namespace sphc::mpi
