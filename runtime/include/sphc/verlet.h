// sphc runtime: neighbour lists kept across time steps (Verlet lists with a skin; header only).
//
// `sphc --verlet-skin=F` (F > 0): each pair loop keeps, per destination particle, the
// candidates within (1 + F) times the support radius, radius_scale * max(h_i, h_j), found
// with the cell lists when the lists are built, in the cell lists' candidate order. Every
// evaluation then filters that list with the loop's usual cut-off test (the same
// R2IJ >= RADIUS2 * hmax * hmax as without lists), so the set of interacting pairs is the
// same. Each kept list is in increasing particle index (keep_in_index_order), so the
// neighbours come in that order whenever the lists were built: the sums over neighbours are
// a function of the particles now, not of the build (a run continued with --restart, which
// builds its lists anew, and runs with another skin give the same bits). Without lists the
// neighbours come in the cell lists' candidate order, so the sums may round differently.
//
// The lists stay complete while no pair can have come from beyond (1 + F) times its radius
// at the build to within its radius now. A pair's distance shrank by at most 2 d, d the
// largest displacement of any particle since the build, and its radius grew by at most
// radius_scale * g, g the largest growth of any h; its skin at the build was at least
// F * radius_scale * h_min (h_min the smallest h at the build). So the lists are rebuilt
// when 2 d + radius_scale * g > F * radius_scale * h_min, when an array's particle count
// changed, and at the first evaluation (VerletSkin::must_rebuild). The pair loops of one
// destination and source array share their lists and positions (VerletLists; a group with
// start_idx or stop_idx keeps its own): every loop checks them at each of its evaluations,
// so a loop that does not run at every evaluation (a group with `every` or a condition,
// post_step) measures from the last build, whichever loop made it.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <vector>

#include "sphc/float_arrays.h"
#include "sphc/particle_array.h"

namespace sphc {

// The positions and h of one array when kept lists were built (VerletSkin::mark), shared by
// the skins that marked it at the same positions within one phase (PhaseDisplacements).
struct MarkedPositions {
  std::size_t n = 0;
  std::vector<double> x, y, z, h;
  double hmin = HUGE_VAL;  // the smallest h (NaN skipped)
  bool hnan = false;       // a NaN among h
};

// One scan of each array's displacements per phase (docs/performance-log.md, "The dam break's
// step: one displacement check per array set"). The generated phase declares one where
// nothing in it writes positions, h or counts; each rebuild check of the phase's kept lists
// passes it to must_rebuild and mark: an array whose positions several lists marked within
// one phase is marked once (the skins share the saved copy), and its displacement from that
// copy is measured once per phase, however many lists' checks read it. The answers and
// last_moved() are those of a scan per check, bit for bit (the same doubles, max and min
// being exact).
class PhaseDisplacements {
 public:
  PhaseDisplacements() = default;
  // Out of line (src/verlet.cpp): the phases of a solver destroy one each.
  ~PhaseDisplacements();
  PhaseDisplacements(const PhaseDisplacements&) = default;
  PhaseDisplacements& operator=(const PhaseDisplacements&) = default;
  struct Moved {
    // Held so that no copy marked later in the phase can take its address.
    std::shared_ptr<const MarkedPositions> from;
    double d2max, growth;
    bool nan;
  };
  const Moved* find(const MarkedPositions* from) const {
    for (const Moved& m : moved_)
      if (m.from.get() == from) return &m;
    return nullptr;
  }
  void add(const Moved& m) { moved_.push_back(m); }
  std::size_t scans() const { return moved_.size(); }  // the arrays measured in this phase
  // The copy marked for `pa` in this phase (nullptr if none): the same positions now. `pa` is
  // a ParticleArray or (--precision=single) the FloatArray the scene computes on.
  template <class Array>
  std::shared_ptr<const MarkedPositions> marked(const Array* pa) const {
    for (const auto& m : marked_)
      if (m.first == pa && m.second->n == pa->n) return m.second;
    return nullptr;
  }
  void add(const void* pa, std::shared_ptr<const MarkedPositions> s) {
    marked_.emplace_back(pa, std::move(s));
  }

 private:
  std::vector<Moved> moved_;
  std::vector<std::pair<const void*, std::shared_ptr<const MarkedPositions>>> marked_;
};

class VerletSkin {
 public:
  // h_fixed: nothing writes the h of the arrays these lists are checked over (the compiler's
  // analysis/UniformH.cpp); must_rebuild then reads no h: its growth is 0 and a NaN among h
  // the one recorded at mark(), the same answers as from h read (stop 46).
  explicit VerletSkin(double skin, bool h_fixed = false) : skin_(skin), h_fixed_(h_fixed) {}
  bool h_fixed() const { return h_fixed_; }

  double skin() const { return skin_; }
  // --verlet-skin=auto (sphc/verlet_tune.h): the skin of the next mark().
  void set_skin(double skin) { skin_ = skin; }
  // Forgets the last mark(): the next must_rebuild says yes (after a sort, whose permutation
  // is no movement to measure).
  void forget() { saved_.clear(); }
  // What the last must_rebuild measured (2 d + radius_scale g; -1 where it answered without
  // measuring), the must_rebuild calls since the last mark(), and h_min at the last mark().
  double last_moved() const { return last_moved_; }
  // Whether the next must_rebuild is expected to say yes: before the first mark() (or after
  // forget()), or where the movement it measured last, extrapolated by one more evaluation
  // (x (checks + 1) / checks), passes the skin. A guess, for work done ahead of a rebuild
  // (the tiles' slot order, stop 40: sphc/cluster_pairs.h); must_rebuild still decides.
  bool rebuild_expected(double radius_scale) const {
    if (saved_.empty()) return true;
    if (!(last_moved_ > 0.0) || checks_ <= 0) return false;
    const double next = last_moved_ * static_cast<double>(checks_ + 1) / static_cast<double>(checks_);
    return !(next <= skin_ * radius_scale * hmin_);
  }
  long checks() const { return checks_; }
  double hmin() const { return hmin_; }

  // Whether the lists built at the last mark() may miss a pair now (see above): true before
  // the first mark(), when the arrays or their counts differ, or when the particles moved
  // (or h grew) too far. NaN positions also give true. With `phase`, an array's displacement
  // already measured in this phase from the same marked copy is not scanned again.
  // Defined in the runtime library (src/verlet.cpp), as mark: a solver calls them, it does
  // not compile them (docs/performance-log.md, "Compile time: the runtime's code in its library").
  bool must_rebuild(const std::vector<const ParticleArray*>& arrays, double radius_scale,
                    PhaseDisplacements* phase = nullptr) const;
  // --precision=single: the same over the float copies the scene computes on (their floats
  // read as doubles, exactly; the bound as above). An initializer list, not a vector: a
  // vector's constructor from two iterators would make `{&a, &b}` of two ParticleArrays
  // match it too (ambiguous).
  bool must_rebuild(std::initializer_list<const FloatArray*> arrays, double radius_scale,
                    PhaseDisplacements* phase = nullptr) const;

  // Records the positions and h of the arrays the lists are built from now (with `phase`: the
  // copy another skin marked in this phase, the same positions, where there is one).
  void mark(const std::vector<const ParticleArray*>& arrays,
            PhaseDisplacements* phase = nullptr);
  void mark(std::initializer_list<const FloatArray*> arrays, PhaseDisplacements* phase = nullptr);

 private:
  // ParticleArray or FloatArray (src/verlet.cpp).
  template <class Array>
  bool must_rebuild_of(const std::vector<const Array*>& arrays, double radius_scale,
                       PhaseDisplacements* phase) const;
  template <class Array>
  void mark_of(const std::vector<const Array*>& arrays, PhaseDisplacements* phase);

  double skin_;
  bool h_fixed_ = false;
  double hmin_ = 0.0;
  std::vector<std::shared_ptr<const MarkedPositions>> saved_;
  mutable double last_moved_ = -1.0;  // measurements for sphc/verlet_tune.h
  mutable long checks_ = 0;
};

// The kept lists of the pair loops of one destination and source array: per destination
// particle its candidates, and the positions they were built from. Each loop checks them at
// every evaluation (skin.must_rebuild over its destination and source arrays) and rebuilds
// them from the cell lists when due; a permutation of the particles into cell order moves
// them far and so rebuilds them too.
struct VerletLists {
  explicit VerletLists(double skin_fraction, bool h_fixed = false) : skin(skin_fraction, h_fixed) {}
  VerletSkin skin;
  std::vector<std::vector<std::uint32_t>> lists;
  // The destination particles [begin, end) the lists were built for (a group with start_idx
  // or stop_idx builds its range only; another range rebuilds them).
  long begin = 0, end = -1;
  bool built_for(long b, long e) const { return b == begin && e == end; }
  // The loops over each pair once (destination = source): per particle i, where j >= i
  // starts in its kept list (upper_start), found once per build; cleared at every build.
  std::vector<std::uint32_t> upper;
  // The loops over pairs of two arrays: the destinations of [begin, end) whose kept list is
  // not empty, in increasing index (find_occupied), found once per build by the first such
  // loop after it; `occupied_found` cleared at every build. Those loops visit only them: a
  // destination without candidates adds nothing to its sums.
  std::vector<std::uint32_t> occupied;
  bool occupied_found = false;
};

// lists.occupied = the destinations [begin, end) with a candidate, in increasing index.
void find_occupied(VerletLists& lists);  // src/verlet.cpp

// The position of the first j >= i in the kept list of particle i (in increasing index).
inline std::uint32_t upper_start(const std::vector<std::uint32_t>& kept, std::uint32_t i) {
  return static_cast<std::uint32_t>(std::lower_bound(kept.begin(), kept.end(), i) - kept.begin());
}

// keep_in_index_order: lists up to this length are sorted by insertion.
constexpr std::size_t kInsertionSortMax = 64;

// kept = the candidates cand[0, n) (one destination particle's, within the lists' radius)
// in increasing particle index: the order in which the filtered neighbours are summed does
// not depend on when, or from which cells, the lists were built.
void keep_in_index_order(std::vector<std::uint32_t>& kept, const std::uint32_t* cand,
                         std::size_t n);  // src/verlet.cpp

// out[0, count) = the candidates j of cand[0, n) with keep(j), in their order; returns count.
// Branch-free like CellList::gather_neighbours: every candidate is written, the count
// advances only for those kept.
template <class Keep>
inline std::size_t filter_neighbours(const std::uint32_t* cand, std::size_t n,
                                     std::vector<std::uint32_t>& out, Keep&& keep) {
  if (out.size() < n) out.resize(2 * n + 64);
  std::uint32_t* o = out.data();
  std::size_t count = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t j = cand[k];
    o[count] = j;
    count += keep(j) ? 1 : 0;
  }
  return count;
}

}  // namespace sphc
