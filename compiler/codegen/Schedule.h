// The schedule: what the generated solver does, in which order and over which particles,
// decided once from the analysed Plan and read by every backend's printer. It is the back
// half's counterpart of the Plan: the Plan says what the scene computes, the schedule how
// one evaluation and one time step run it — phases and their neighbour passes, reductions,
// iterated groups and their convergence tests, fused stepper runs, ghost refreshes, cell
// lists, the adaptive time step — with no backend in it. Printers (codegen/*Printer.cpp)
// decide only spellings: a loop marked parallel is an OpenMP `parallel for` on one backend,
// a kernel on another and a plain loop on the serial one.
#pragma once

#include "frontend/Diagnostics.h"
#include "sema/Plan.h"

#include "llvm/Support/raw_ostream.h"

#include <functional>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace sphc {

// How the iterations of a loop over particles may run (as Halide's ForType). Parallel: they
// are independent (each writes its own particle only: a gather), in any order and at once.
// Serial: in particle order (a sum whose result must not depend on the thread count).
enum class LoopOrder { Serial, Parallel };

// One neighbour pass: for every destination particle, every candidate of one source array,
// the pair quantities once, then the loop body of every equation that loops over that source.
struct NeighbourPass {
  int source = -1;                           // array index
  std::set<std::string> pairQuantities;      // closed under what they need (XIJ, RIJ, ...)
  std::vector<const PlanEquation*> equations;  // whose `loop` runs here, in group order
  // PySPH's order per source: every initialize_pair over the destination particles first;
  // then per destination particle the neighbour list, every loop_all with it, then the
  // loops over the same neighbours.
  std::vector<const PlanEquation*> initializePair;  // whose `initialize_pair` runs here
  std::vector<const PlanEquation*> loopAll;         // whose `loop_all` runs here
  // Whether the pass visits neighbours at all (not for initialize_pair alone).
  bool searches() const { return !equations.empty() || !loopAll.empty(); }
  std::set<std::string> sourceProps;         // s_* properties the bodies read
  // Read on both sides to compute the pair quantities: positions and h always, velocities
  // for VIJ, rho for RHOIJ.
  std::set<std::string> shared;
  LoopOrder order = LoopOrder::Parallel;
};

// A reduction of one equation over the real particles of its destination into a constant.
struct Reduction {
  const PlanEquation* equation = nullptr;
  std::string op;       // sum, mean, max, min
  std::string target;   // the destination's constant
  // sum and mean: the values may be computed in parallel, but they are added in particle
  // order, so that the result (and the iteration count a convergence test derives from it)
  // is the serial one bit for bit. max and min: any order.
  LoopOrder combine = LoopOrder::Parallel;
};

// Per-particle work of an earlier phase that the schedule moved into a later kernel of the
// same array (ScheduleFusion.cpp): its equation, its method (initialize or post_loop) and the
// phase it comes from (provenance).
struct MovedWork {
  const PlanEquation* equation = nullptr;
  ast::Method::Kind method = ast::Method::Initialize;
  std::string phase;
};

// What a phase does for one destination array.
struct DestinationWork {
  int array = -1;
  // A group with `real = false` runs on the ghosts too (they follow the real particles);
  // reductions still see the real particles only.
  bool onGhosts = false;
  std::vector<const PlanEquation*> equations;   // every live equation of the phase on it
  std::set<std::string> destProps;              // d_* properties any of their bodies use
  std::vector<const PlanEquation*> initialize;  // per particle, before the neighbour passes
  std::vector<NeighbourPass> passes;            // one per source, in order of first use
  std::vector<const PlanEquation*> postLoop;    // per particle, after them
  std::vector<Reduction> reductions;
  // `reduce { }` (PySPH's reduce(dst, t, dt)): on the host, after the reductions, in order.
  std::vector<const PlanEquation*> hostReduce;
  // Carried properties the phase wrote on the real particles: their ghosts are refreshed
  // after it (empty when the phase ran on the ghosts too).
  std::vector<std::string> ghostRefresh;
  LoopOrder perParticle = LoopOrder::Parallel;  // the initialize and post_loop loops
  // Kernel fusion (ScheduleFusion.cpp; a printer may use it or run the phases as listed):
  // per-particle work of earlier phases on this array that runs first, in order, in this
  // destination's initialize loop; this destination's initialize (with what it took in) or
  // post_loop moved into a later phase's initialize loop; its reductions' per-particle values
  // computed in its post_loop loop (the last per-particle loop on it).
  std::vector<MovedWork> initializeFirst;
  bool initializeMoved = false, postLoopMoved = false;
  bool reduceInPostLoop = false;
  // The group's `start_idx` / `stop_idx` (null: 0 / all particles): initialize, the
  // neighbour passes and post_loop run on destination particles start <= d_idx < stop only
  // (clamped to [0, n)); reductions on every real particle.
  ast::ExprPtr startIdx, stopIdx;
  bool ranged() const { return startIdx || stopIdx; }
};

// A fused evaluation of consecutive direct equations of a group (PySPH's Group): per
// destination, every initialize, the neighbour passes, then post_loop and reduce.
struct Phase {
  // The generated function: its group's name and its first equation's, e.g.
  // group_1_TaitEOS (equations_TaitEOS for direct members of the scene's equations { }).
  std::string name;
  const PlanGroup* group = nullptr;
  std::vector<int> equations;  // equation ids, live or not, in group order
  std::vector<DestinationWork> destinations;  // in order of first use
};

// A group of the scene's equations { }: its phases and subgroups run in order.
struct ScheduleGroup {
  // The generated function: `equations` for the scene's equations { }, group_K for its K-th
  // group (from 1, in source order, groups inside groups and post_step groups counted); a
  // run of fused groups is named after its first (ScheduleBuilder::group).
  std::string name;
  const PlanGroup* group = nullptr;
  struct Member {
    bool isPhase = true;
    int index = 0;  // into phases or subgroups
  };
  std::vector<Member> members;  // in order (post_step subgroups included)
  std::vector<Phase> phases;
  std::vector<std::unique_ptr<ScheduleGroup>> subgroups;
  // The function names this group calls, in order: its phases and subgroups, except
  // subgroups with post_step = true (those run after the time step).
  std::vector<std::string> calls;
  // Iterated groups: the `converged` tests (of its equations and those of its subgroups at
  // any depth, except inside a nested iterated group, which tests its own) and the index of
  // its iteration statistics.
  std::vector<const PlanEquation*> convergers;
  int statsIndex = -1;
  // `update_nnps = true`: after the calls (in each iteration of an iterated group), the
  // neighbour search is rebuilt from the current positions (wrapping into a periodic box,
  // search domain, cell lists, ghosts), as at the start of an evaluation.
  bool rebuildNeighbours = false;
  // Group fusion (ScheduleGroupFusion.cpp): the later consecutive groups of the parent whose
  // equations run in this group's one phase (this group is the first of the run).
  std::vector<const PlanGroup*> fused;
};

// Calls fn for every phase of g and of its subgroups at any depth, in order.
void walkPhases(const ScheduleGroup& g, const std::function<void(const Phase&)>& fn);

// Calls fn for every neighbour pass of g's phases and of its subgroups at any depth, in order.
void walkPasses(const ScheduleGroup& g,
                const std::function<void(const Phase&, const DestinationWork&,
                                         const NeighbourPass&)>& fn);

// Consecutive stepper statements (initialize, stageN) of the integrator's step, fused: one
// pass per array doing all the run's methods per particle. Steppers read and write their own
// particle only, so this equals running each method on all particles in turn, bit for bit.
struct StepperRun {
  std::string name;  // stepper_initialize_stage1
  std::vector<std::string> methods;  // initialize, stage1, ...
  struct Part {
    int array = -1;
    const PlanStepper* stepper = nullptr;
    // (position in methods, body) for the methods this array's stepper has.
    std::vector<std::pair<size_t, const PlanBody*>> bodies;
    std::set<std::string> destProps;
  };
  std::vector<Part> parts;  // arrays with at least one of the run's methods
  LoopOrder order = LoopOrder::Parallel;
};

// One statement of the integrator's step.
struct StepStatement {
  // InletOutlet: after the integrator's statements, the inlet/outlet manager moves particles
  // between arrays, creates and removes them (Schedule::resized): arrays change size between
  // steps only, never within an evaluation.
  enum Kind { Stepper, ComputeAccelerations, UpdateDomain, InletOutlet } kind = Stepper;
  int run = -1;  // Stepper: index into Schedule::stepperRuns (a whole run of statements)
  // The stages completed before each statement (a run: one per method): its time is
  // t + stagesDone/stages dt.
  std::vector<int> stagesDone;
};

// The adaptive time step: per-particle limits over the arrays that move.
struct AdaptiveDt {
  bool enabled = false;
  std::vector<int> arrays;  // stepped arrays whose stepper moves them
  bool cfl = false;         // h / (cs + |v|)
  bool force = false;       // sqrt(h / |a|)
  bool viscous = false;     // h^2 / nu
  LoopOrder order = LoopOrder::Parallel;  // a min reduction: any order
};

// sphc --mpi: how the scene runs on several ranks (runtime/include/sphc/mpi/). Each
// evaluation's neighbour update starts with `migrate` (particles that left their rank's
// region go to its owner, every property; a re-balance every `rebalanceEvery` evaluations or
// when the imbalance passes `imbalanceLimit`), then a halo exchange per source array (remote
// particles and periodic/mirror images within the interaction radius, carrying `halo`: the
// ghost pass's properties) replaces the ghosts; a ghost refresh becomes a halo refresh;
// reductions, the adaptive dt and the convergence of iterated groups are global
// (MPI_Allreduce); output is gathered to rank 0 in global-id order.
struct Distribution {
  bool enabled = false;
  std::string method = "RCB";        // Zoltan's LB_METHOD
  long rebalanceEvery = 100;         // evaluations
  double imbalanceLimit = 1.1;       // largest rank's particles / mean
  std::vector<int> migrate;          // every array (all properties move)
  std::vector<std::pair<int, std::vector<std::string>>> halo;  // source array, properties sent
  // Per array (plan order): the estimated work of one of its particles, Zoltan's object
  // weight (ScheduleDistribution.cpp, workWeights).
  std::vector<double> weights;
};

struct Schedule {
  const Plan* plan = nullptr;
  Distribution distribution;
  // Set-up, in order: parameters (declaration order), equation constants, then each array
  // (geometry, files, properties, initial values) in `setupArrays` order, then the domain.
  std::vector<int> setupArrays;
  ScheduleGroup equations;  // the root group: compute_accelerations' `equations(t, dt)`
  // Top-level groups with post_step = true, in order: (function, condition) pairs; the
  // condition is the group's `every` test (null: always).
  struct PostStep {
    std::string function;
    const PlanGroup* group = nullptr;
  };
  std::vector<PostStep> postStep;
  // Whether the post_step groups need the neighbour search (cell lists, ghosts or the halo;
  // with --mpi the migration and the work count): only when one has a neighbour pass or
  // rebuilds it. Without, they are per-particle work on the real particles (e.g. the walls'
  // density floor after each step), and their ghost refreshes are dropped: no ghost exists
  // between the evaluation and the next.
  bool postStepNeighbours = false;
  // Source locations of the iterated groups, by statistics index.
  std::vector<llvm::SMLoc> iteratedGroups;
  // Neighbour search: arrays in a neighbour pass as destination or source (the search
  // domain spans them), in array order; arrays that are a source (they need a cell list,
  // and with a periodic or mirror domain ghosts), by name.
  std::vector<int> searchArrays;
  std::vector<int> cellLists;
  // Arrays never permuted into cell order: destinations of a group with start_idx or
  // stop_idx, whose indices then name the same particles all run long (the set-up order).
  std::set<int> keepOrder;
  bool domain = false;  // periodic or mirror sides: wrapping, ghosts
  // The integrator's step.
  std::vector<StepperRun> stepperRuns;  // one per distinct run name, in order of first use
  std::vector<StepStatement> step;
  int stages = 0;
  // Arrays whose particle count changes in the InletOutlet statement (zones and the arrays
  // they feed or take from), in array order; empty without inlets and outlets. Their data
  // is on the host for the manager (printers: arraysToHost / arraysFromHost).
  std::vector<int> resized;
  AdaptiveDt adaptiveDt;
};

// Kernel fusion over a built schedule (ScheduleFusion.cpp): per-particle loops of consecutive
// phases on one array joined where nothing between them reads or writes that array (see
// DestinationWork::initializeFirst), and reductions' values computed in the post_loop loop.
void fusePerParticleWork(Schedule& s);

// Group fusion (ScheduleGroupFusion.cpp): whether a group may be joined with its neighbours
// (plain: direct equations only, nothing that tests, repeats, skips, ranges or reduces), and
// the parent's order split into runs (positions in PlanGroup::order): a run of two or more
// consecutive subgroups runs as one phase, each one proved not to read or write what the
// earlier ones of its run write, nor to write what they read.
bool fusibleGroup(const Plan& plan, const PlanGroup& g);
std::vector<std::vector<int>> groupFusionRuns(const Plan& plan, const PlanGroup& parent);

// The schedule of an analysed plan (after the ghost pass). Pure: reads the plan only.
// fuseGroups = false (--no-group-fusion): every group on its own.
std::unique_ptr<Schedule> buildSchedule(const Plan& plan, bool fuseGroups = true);

// --dump-after=schedule.
void printSchedule(const Schedule& s, const DiagnosticEngine& diags, llvm::raw_ostream& os);

}  // namespace sphc
