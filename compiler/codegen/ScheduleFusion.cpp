// Kernel fusion, a schedule decision: per-particle loops (initialize, post_loop) of
// consecutive phases on one array run as one loop where the schedule proves it legal, and a
// destination's reductions take their per-particle values in its post_loop loop. A printer
// that launches a kernel per loop (OpenCL) saves the launches; the CPU printers may use it to
// save passes over memory.
//
// Legality. An initialize or post_loop body reads and writes its own particle of its
// destination only (and the array's constants, and its equation's values). Such a loop P on
// array A may therefore run later, at the start of the next initialize loop K on A, when
// nothing between P and K reads or writes A: no neighbour pass with A as destination or
// source, no initialize_pair, no reduction or ghost refresh of A, no host `reduce`, no group
// boundary that tests, repeats or skips (iterate, every, condition, update_nnps), no neighbour
// update. Loops on other arrays in between touch other data, so moving P past them changes
// nothing, bit for bit. P and K must run over the same particles (both on the real particles
// or both with the ghosts, neither ranged by start_idx/stop_idx) in parallel order.
#include "codegen/Schedule.h"

#include <map>

namespace sphc {

namespace {

class Fusion {
 public:
  // Sequences of calls with no test between them: the evaluation (the root's calls), then
  // the post_step groups (after their own neighbour update).
  void run(Schedule& s) {
    walk(s.equations);
    pending_.clear();
    for (auto& sub : s.equations.subgroups)
      if (sub->group->postStep) group(*sub);
    pending_.clear();
  }

 private:
  // The last per-particle loop on an array that may still move: its work, which loop, and
  // its phase (provenance).
  struct Pending {
    DestinationWork* work = nullptr;
    bool postLoop = false;
    std::string phase;
  };
  std::map<int, Pending> pending_;

  static bool plain(const ScheduleGroup& g) {
    const PlanGroup& pg = *g.group;
    return !pg.iterate && !pg.every && !pg.condition && !g.rebuildNeighbours;
  }
  static bool sameParticles(const DestinationWork& a, const DestinationWork& b) {
    return a.onGhosts == b.onGhosts && !a.ranged() && !b.ranged() &&
           a.perParticle == LoopOrder::Parallel && b.perParticle == LoopOrder::Parallel;
  }

  // A subgroup: within the sequence when it is plain; otherwise (it tests, repeats or skips)
  // fusion inside it only, never across its edges.
  void group(ScheduleGroup& g) {
    if (plain(g)) return walk(g);
    pending_.clear();
    walk(g);
    pending_.clear();
  }
  // Members in call order; the root's post_step groups run after the step (run()).
  void walk(ScheduleGroup& g) {
    for (const auto& m : g.members) {
      if (m.isPhase) {
        Phase& ph = g.phases[m.index];
        for (DestinationWork& w : ph.destinations) destination(w, ph.name);
      } else if (!g.subgroups[m.index]->group->postStep) {
        group(*g.subgroups[m.index]);
      }
    }
  }

  void destination(DestinationWork& w, const std::string& phase) {
    const int a = w.array;
    // The initialize loop takes in the pending loop on the array, where it may.
    if (!w.initialize.empty()) {
      auto it = pending_.find(a);
      if (it != pending_.end() && sameParticles(*it->second.work, w)) {
        DestinationWork& p = *it->second.work;
        std::vector<MovedWork> first;
        if (it->second.postLoop) {
          for (const auto* eq : p.postLoop)
            first.push_back({eq, ast::Method::PostLoop, it->second.phase});
          p.postLoopMoved = true;
        } else {
          first = std::move(p.initializeFirst);
          p.initializeFirst.clear();
          for (const auto* eq : p.initialize)
            first.push_back({eq, ast::Method::Initialize, it->second.phase});
          p.initializeMoved = true;
        }
        first.insert(first.end(), w.initializeFirst.begin(), w.initializeFirst.end());
        w.initializeFirst = std::move(first);
      }
      pending_[a] = {&w, false, phase};
    }
    // Neighbour passes read the source's particles and write the destination's.
    for (const NeighbourPass& pass : w.passes) pending_.erase(pass.source);
    if (!w.passes.empty()) pending_.erase(a);
    if (!w.postLoop.empty()) {
      pending_[a] = {&w, true, phase};
      // The reductions' values in the post_loop loop (over the same, real, particles).
      if (!w.reductions.empty() && !w.onGhosts && !w.ranged() &&
          w.perParticle == LoopOrder::Parallel)
        w.reduceInPostLoop = true;
    }
    // Reductions and ghost refreshes read the array; host code may change anything.
    if (!w.reductions.empty() || !w.ghostRefresh.empty()) pending_.erase(a);
    if (!w.hostReduce.empty()) pending_.clear();
  }
};

}  // namespace

void fusePerParticleWork(Schedule& s) { Fusion().run(s); }

}  // namespace sphc
