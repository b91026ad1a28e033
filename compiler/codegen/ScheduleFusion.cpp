// Kernel fusion, a schedule decision: per-particle loops (initialize, post_loop) of
// consecutive phases on one array run as one loop where the schedule proves it legal, and a
// destination's reductions take their per-particle values in its post_loop loop. A printer
// that launches a kernel per loop (OpenCL) saves the launches; the CPU printers may use it to
// save passes over memory.
//
// Legality. An initialize or post_loop body reads and writes its own particle of its
// destination only (and the array's constants, and its equation's values). Such a loop P on
// array A may therefore run later, at the start of the next initialize loop K on A, when
// nothing between P and K reads or writes A, from the access analysis (analysis/Access.h, as
// group fusion: ScheduleGroupFusion.cpp; every method of the neighbour passes and
// initialize_pair, implicit reads of the pair quantities and the neighbour search included):
// no neighbour pass with A as destination or source, no reduction or ghost refresh of A, no
// host `reduce`, no group boundary that tests, repeats or skips (iterate, every, condition,
// update_nnps), no neighbour update. Loops on other arrays in between touch other data, so
// moving P past them changes nothing, bit for bit. (Per property it would be legal more often,
// e.g. past a pass that reads only A's positions: the cavity's OpenCL solver would save a
// launch per step; not done: the launches stay those of the array rule.) P and K must run
// over the same particles (both on the real particles or both with the ghosts, neither ranged
// by start_idx/stop_idx) in parallel order.
#include "codegen/Schedule.h"

#include "analysis/Access.h"

#include <map>
#include <set>
#include <utility>

namespace sphc {

namespace {

using Key = std::pair<int, std::string>;  // (array, property)

struct Accesses {
  std::set<Key> reads, writes;
};

class Fusion {
 public:
  explicit Fusion(const Plan& plan) : plan_(plan) {}

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
  const Plan& plan_;
  std::map<int, Pending> pending_;

  // The accesses of the equations' methods of the given kinds.
  void add(const std::vector<const PlanEquation*>& eqs, std::set<ast::Method::Kind> kinds,
           Accesses& out) const {
    for (const PlanEquation* eq : eqs)
      for (const Access& a : equationAccesses(plan_, *eq))
        if (kinds.count(a.method)) (a.write ? out.writes : out.reads).insert({a.array, a.prop});
  }
  // Drops the pending loops on the arrays that work with accesses `x` reads or writes.
  void touched(const Accesses& x) {
    for (const std::set<Key>* keys : {&x.reads, &x.writes})
      for (const Key& k : *keys) pending_.erase(k.first);
  }

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
    // Neighbour passes read the source's particles and write the destination's (their
    // bodies; the pass itself reads the positions and h of both: the neighbour search, or
    // initialize_pair's loop over the destination with the source's data).
    for (const NeighbourPass& pass : w.passes) {
      Accesses x;
      add(pass.initializePair, {ast::Method::InitializePair}, x);
      add(pass.loopAll, {ast::Method::LoopAll}, x);
      add(pass.equations, {ast::Method::Loop}, x);
      for (int arr : {a, pass.source}) {
        for (const std::string& p : positionProps(plan_.dim)) x.reads.insert({arr, p});
        x.reads.insert({arr, "h"});
      }
      touched(x);
    }
    if (!w.postLoop.empty()) {
      pending_[a] = {&w, true, phase};
      // The reductions' values in the post_loop loop (over the same, real, particles).
      if (!w.reductions.empty() && !w.onGhosts && !w.ranged() &&
          w.perParticle == LoopOrder::Parallel)
        w.reduceInPostLoop = true;
      if (w.reduceInPostLoop) pending_.erase(a);  // it computes the reductions' values
    }
    // Reductions read what their bodies read; ghost refreshes read the real particles'
    // properties and write the ghosts'; host code may change anything.
    if (!w.reductions.empty() || !w.ghostRefresh.empty()) {
      Accesses x;
      for (const Reduction& r : w.reductions) add({r.equation}, {ast::Method::Reduce}, x);
      for (const std::string& p : w.ghostRefresh) {
        x.reads.insert({a, p});
        x.writes.insert({a, p});
      }
      touched(x);
    }
    if (!w.hostReduce.empty()) pending_.clear();
  }
};

}  // namespace

void fusePerParticleWork(Schedule& s) { Fusion(*s.plan).run(s); }

}  // namespace sphc
