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
// whenever the imbalance (largest rank's work over the mean) exceeds `imbalance_limit`.
//
// Work (the weights of RCB). Three modes (Weights):
//   - Measured (the default): the generated neighbour passes count their work into the
//     decomposition (pass_work, count_work): per destination particle, the candidates it
//     tested and its neighbour pairs times the loops run over them; every particle counts
//     `particle_cost` more (its steppers, initialize loops, cell lists, halo and migration
//     tests); each at a fixed cost in about instructions (fitted to callgrind counts). A
//     rank's work in an evaluation is that count: an integer, the same on every run, whatever
//     the machine's load (unlike a timing). A re-balance on imbalance happens when the
//     counted work of the last evaluation is unbalanced (largest rank's over the mean, an
//     exact integer MPI_Allreduce, above the limit), at least min_rebalance_gap evaluations
//     after the last one; it happens before that evaluation's particles migrate, and RCB
//     weighs each particle by its own count (a wall next to the water tests many candidates,
//     one far from it none), scaled per array so that its particles' mean is the mean since the
//     last re-balance (a group that runs in some evaluations only weighs its average, not all
//     or nothing as in the last evaluation). Where an array changed since the passes (inlets, outlets), its
//     particles weigh the measured mean of its particles since the last re-balance instead,
//     as in the scheduled re-balances after a migration. The first cut (distribute, restart:
//     nothing counted yet) uses the compiler's estimate.
//   - Estimated (SPHC_MPI_WEIGHTS=estimated): the compiler's estimate only (1 + neighbour
//     passes as destination per particle), the imbalance in the same weights.
//   - None (SPHC_MPI_UNWEIGHTED=1, or SPHC_MPI_WEIGHTS=none): every particle weighs 1, the
//     imbalance is the particle count's.
// The work is counted in every mode (SPHC_MPI_STATS prints it), so the modes can be compared.
//
// Order. Migration keeps the staying particles in their order and appends the arrivals by
// sending rank, each in the sender's order; the decisions (when to re-balance, the weights)
// come from counts, not timings: for a given rank count, runs are deterministic.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "sphc/particle_array.h"

struct Zoltan_Struct;

namespace sphc::mpi {

enum class Weights { Measured, Estimated, None };

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
  // weight (set_weights; measured ones after a re-balance); empty: every particle weighs 1.
  std::vector<double> weights;
  Weights mode = Weights::Measured;
  std::vector<double> estimate;  // the compiler's estimate (set_weights)
  // Counted work (Measured; counted in every mode), in about instructions: the costs of one
  // particle outside the neighbour passes, of one candidate of a pass (the distance test) and
  // of one neighbour pair of one loop, fitted to callgrind counts of the 3D dam break
  // (docs/scaling.md, "Measured weights").
  long particle_cost = 1300;
  long candidate_cost = 30;
  long pair_cost = 10;
  std::vector<long> pairs_now;       // per array: pair loops of this evaluation so far
  std::vector<long> candidates_now;  // per array: candidates of this evaluation so far
  std::vector<long> work_since;      // per array: counted work since the last re-balance
  std::vector<long> particles_since; // per array: particles of those evaluations
  // Per array, per particle (in the order of the passes: the real particles, then the halo):
  // what the passes counted this evaluation (pass_work); pass_n: the real count then.
  std::vector<std::vector<long>> particle_work;
  std::vector<std::size_t> pass_n;
  long min_rebalance_gap = 10;       // evaluations between re-balances on imbalance (Measured)
  long last_rebalance = -(1L << 40);  // the evaluation of the last re-balance on counts
  long evaluations_counted = 0;      // evaluations in work_since
  double work_imbalance = 0;         // max/mean counted work of the last completed evaluation
  double work_imbalance_sum = 0;     // sum of work_imbalance over the evaluations (stats)
  long work_imbalance_count = 0;
  long imbalance_rebalances = 0;     // re-balances triggered by imbalance (not scheduled)
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

// The compiler's work estimate per array (`per_array`): the weights of the first cut, and of
// every cut with SPHC_MPI_WEIGHTS=estimated. Before distribute. The environment chooses the
// mode: SPHC_MPI_WEIGHTS=measured (the default), estimated or none; SPHC_MPI_UNWEIGHTED=1 is
// none (measurement switches).
void set_weights(Decomposition& d, const std::vector<double>& per_array);

// A neighbour pass of the generated code with destination array `array` (index in the order
// the arrays are passed) tested `candidates` candidates and ran `pair_loops` pair-loop
// bodies (neighbour pairs x loops).
inline void count_work(Decomposition& d, std::size_t array, long pair_loops, long candidates) {
  if (array >= d.pairs_now.size()) {
    d.pairs_now.resize(array + 1, 0);
    d.candidates_now.resize(array + 1, 0);
  }
  d.pairs_now[array] += pair_loops;
  d.candidates_now[array] += candidates;
}

// The per-particle counts of a pass over array `array`'s particles [0, count) (n real ones,
// then the halo): grown to count (zeros), for the pass to add each particle's work to.
inline long* pass_work(Decomposition& d, std::size_t array, std::size_t n, std::size_t count) {
  if (array >= d.particle_work.size()) {
    d.particle_work.resize(array + 1);
    d.pass_n.resize(array + 1, 0);
  }
  std::vector<long>& w = d.particle_work[array];
  if (w.size() < count) w.resize(count, 0);
  d.pass_n[array] = n;
  return w.data();
}

// The counted work of array k's n particles in this evaluation so far. Not collective.
inline long array_work(const Decomposition& d, std::size_t k, std::size_t n) {
  return d.particle_cost * static_cast<long>(n) +
         (k < d.pairs_now.size() ? d.pair_cost * d.pairs_now[k] : 0) +
         (k < d.candidates_now.size() ? d.candidate_cost * d.candidates_now[k] : 0);
}

// This rank's counted work in the evaluation since the last update (array_work summed).
// Not collective.
long counted_work(const Decomposition& d, const std::vector<ParticleArray*>& arrays);

// After a replicated set-up: adds `gid` (U32, unique over the arrays in set-up order:
// sphc/global_ids.h) to every array, keeps the block [r n / P, (r + 1) n / P) of each array
// on rank r, then rebalance().
void distribute(Decomposition& d, const std::vector<ParticleArray*>& arrays);

// Cuts space anew from the current particles (Zoltan_LB_Partition) and migrates.
void rebalance(Decomposition& d, const std::vector<ParticleArray*>& arrays);

// Sends every particle whose owner is another rank to it (all properties), appends the
// arrivals. Returns the number of particles this rank sent.
std::size_t migrate(Decomposition& d, const std::vector<ParticleArray*>& arrays);

// The step of an evaluation: closes the count of the last one, migrates, then re-balances
// when due (every rebalance_every evaluations, or the imbalance above the limit: see the
// modes above). Collective.
void update(Decomposition& d, const std::vector<ParticleArray*>& arrays);

// A limit's `remove` took the particles `removed` (removed[i] != 0, over the real particles
// before it) out of array k (in the order the arrays are passed) between evaluations: the
// work the last passes counted for them goes with them, so a re-cut before the next passes
// weighs the others by their own counts (as without the removal). Not collective.
void forget_particles(Decomposition& d, std::size_t k, const std::vector<std::uint8_t>& removed);

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
