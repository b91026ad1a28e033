#include "codegen/Schedule.h"
#include "codegen/ScheduleDistribution.h"

#include "analysis/Access.h"
#include "analysis/PairQuantityTable.h"
#include "analysis/Passes.h"
#include "frontend/ASTPrinter.h"
#include "frontend/Diagnostics.h"

#include <algorithm>
#include <functional>
#include <map>

namespace sphc {

namespace {

class ScheduleBuilder {
 public:
  ScheduleBuilder(const Plan& plan, bool fuseGroups) : plan_(plan), fuseGroups_(fuseGroups) {}
  std::unique_ptr<Schedule> run();
  void postStepNeighbours();

 private:
  const PlanBody& body(const PlanEquation& eq, ast::Method::Kind kind) const {
    return plan_.bodies[plan_.equationDecls[eq.declIndex].methods.at(kind)];
  }
  bool has(const PlanEquation& eq, ast::Method::Kind kind) const {
    return plan_.equationDecls[eq.declIndex].methods.count(kind) > 0;
  }
  std::vector<const PlanEquation*> withMethod(const std::vector<const PlanEquation*>& eqs,
                                              ast::Method::Kind kind) const {
    std::vector<const PlanEquation*> with;
    for (const auto* eq : eqs)
      if (has(*eq, kind)) with.push_back(eq);
    return with;
  }
  bool hasGhosts(int a) const {
    return (plan_.domain.any() || plan_.distributed) && !plan_.arrays[a].ghostProps.empty();
  }
  using PairQuantityMap = std::map<std::pair<int, int>, std::set<std::string>>;
  // A phase is named after its first live equation (its first one if none is live).
  const PlanEquation& firstLive(const std::vector<int>& eqIds) const {
    for (int e : eqIds)
      if (plan_.equations[e].live) return plan_.equations[e];
    return plan_.equations[eqIds.front()];
  }
  void group(const PlanGroup& g, const std::string& name, ScheduleGroup& out);
  void fusedGroup(const std::vector<const PlanGroup*>& run, const std::string& name,
                  ScheduleGroup& out);
  Phase phase(const PlanGroup& g, const std::vector<int>& eqIds, const std::string& name,
              const PairQuantityMap& pq);
  DestinationWork destination(const PlanGroup& g, const std::vector<int>& eqIds, int d,
                              const PairQuantityMap& pq);
  std::vector<NeighbourPass> neighbourPasses(const std::vector<const PlanEquation*>& eqs, int d,
                                             const PairQuantityMap& pq);
  std::vector<std::string> ghostRefresh(int d, const std::vector<const PlanEquation*>& eqs) const;
  std::vector<const PlanEquation*> convergers(const PlanGroup& g) const;
  void step();
  void adaptiveDt();

  // A function name not used yet: `base`, else base_2, base_3, ...
  std::string unique(const std::string& base) {
    if (used_.insert(base).second) return base;
    for (int k = 2;; ++k)
      if (used_.insert(base + "_" + std::to_string(k)).second) return base + "_" + std::to_string(k);
  }

  const Plan& plan_;
  bool fuseGroups_ = true;
  std::set<std::string> used_;
  int groupsNamed_ = 0;  // the groups numbered so far (ScheduleBuilder::group)
  std::unique_ptr<Schedule> s_;
  std::set<std::string> sourceNames_, loopNames_;
};

std::unique_ptr<Schedule> ScheduleBuilder::run() {
  s_ = std::make_unique<Schedule>();
  s_->plan = &plan_;
  // --mpi: halos take the ghosts' place (the same code paths), with or without a domain.
  s_->domain = plan_.domain.any() || plan_.distributed;
  // Arrays are made in declaration order (each from its own geometry and files; initial
  // values read params only, so no array waits for another).
  for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a) s_->setupArrays.push_back(a);
  group(plan_.root, unique("equations"), s_->equations);
  for (const auto& n : sourceNames_) s_->cellLists.push_back(plan_.arrayIndex(n));
  walkPhases(s_->equations, [&](const Phase& ph) {
    for (const auto& w : ph.destinations)
      if (w.ranged()) s_->keepOrder.insert(w.array);
  });
  for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a)
    if (loopNames_.count(plan_.arrays[a].name)) s_->searchArrays.push_back(a);
  postStepNeighbours();
  step();
  adaptiveDt();
  s_->distribution = distributionOf(plan_, s_->cellLists);
  fusePerParticleWork(*s_);
  return std::move(s_);
}

namespace {

ScheduleGroup* findGroup(ScheduleGroup& g, const PlanGroup* pg) {
  if (g.group == pg) return &g;
  for (auto& s : g.subgroups)
    if (ScheduleGroup* f = findGroup(*s, pg)) return f;
  return nullptr;
}

bool hasNeighbourPass(const ScheduleGroup& g) {
  if (g.rebuildNeighbours) return true;
  for (const auto& ph : g.phases)
    for (const auto& d : ph.destinations)
      if (!d.passes.empty()) return true;
  for (const auto& s : g.subgroups)
    if (hasNeighbourPass(*s)) return true;
  return false;
}

void dropGhostWork(ScheduleGroup& g) {
  for (auto& ph : g.phases)
    for (auto& d : ph.destinations) {
      d.ghostRefresh.clear();
      d.onGhosts = false;
    }
  for (auto& s : g.subgroups) dropGhostWork(*s);
}

}  // namespace

// The post_step groups rebuild the neighbour search (and with --mpi migrate, count the work
// and exchange the halo) only when one of them has a neighbour pass: a rebuild for
// per-particle work would cost a cell-list build per step and, with --mpi, close the work
// count of the decomposition's weights on an evaluation without pairs.
void ScheduleBuilder::postStepNeighbours() {
  bool needed = false;
  for (const auto& ps : s_->postStep) {
    const ScheduleGroup* g = findGroup(s_->equations, ps.group);
    needed |= !g || hasNeighbourPass(*g);
  }
  s_->postStepNeighbours = needed;
  if (needed) return;
  for (const auto& ps : s_->postStep)
    if (ScheduleGroup* g = findGroup(s_->equations, ps.group)) dropGhostWork(*g);
}

// Runs of direct equations become fused phases; subgroups run in place, in order. A group's
// function is named by its position (docs/design.md): group_K for the K-th group of the
// scene's equations { } as the schemes and effects expand it, counted from 1 in source order
// with the groups inside groups and the post_step groups (group_1 ... group_5, group_3
// holding group_4 and group_5); a phase's by its group and first equation (group_1_TaitEOS),
// so that names say what the code computes (and OpenCL profiles, which list kernels named
// after phases, say what ran). No name depends on a source line, so reformatting a file
// moves none; the comments before the functions give the lines.
void ScheduleBuilder::group(const PlanGroup& g, const std::string& name, ScheduleGroup& out) {
  out.name = name;
  out.group = &g;
  out.rebuildNeighbours = g.updateNnps;
  std::vector<int> run;
  auto flush = [&] {
    if (run.empty()) return;
    std::string fn = unique(name + "_" + firstLive(run).name);
    out.members.push_back({true, static_cast<int>(out.phases.size())});
    out.phases.push_back(phase(g, run, fn, g.pairQuantities));
    out.calls.push_back(fn);
    run.clear();
  };
  std::vector<std::vector<int>> runs;
  if (fuseGroups_) {
    runs = groupFusionRuns(plan_, g);
  } else {
    for (size_t i = 0; i < g.order.size(); ++i) runs.push_back({static_cast<int>(i)});
  }
  for (const auto& groupRun : runs) {
    const int entry = g.order[groupRun.front()];
    if (groupRun.size() > 1) {  // consecutive subgroups run as one (ScheduleGroupFusion.cpp)
      flush();
      std::vector<const PlanGroup*> fused;
      for (int k : groupRun) fused.push_back(g.subgroups[-g.order[k] - 1].get());
      // The first group's number; the others' are not reused (the names of the groups
      // after them are those of --no-group-fusion).
      std::string fn = unique("group_" + std::to_string(groupsNamed_ + 1));
      groupsNamed_ += static_cast<int>(fused.size());
      out.members.push_back({false, static_cast<int>(out.subgroups.size())});
      out.subgroups.push_back(std::make_unique<ScheduleGroup>());
      fusedGroup(fused, fn, *out.subgroups.back());
      out.calls.push_back(fn);
      continue;
    }
    if (entry >= 0) {
      // A group's pre/post body is a phase of its own: it runs before (after) the whole
      // per-particle work of the group's other members.
      const bool hook = plan_.equations[g.equations[entry]].hook;
      if (hook) flush();
      run.push_back(g.equations[entry]);
      if (hook) flush();
      continue;
    }
    flush();
    const PlanGroup& sub = *g.subgroups[-entry - 1];
    std::string fn = unique("group_" + std::to_string(++groupsNamed_));
    out.members.push_back({false, static_cast<int>(out.subgroups.size())});
    out.subgroups.push_back(std::make_unique<ScheduleGroup>());
    group(sub, fn, *out.subgroups.back());
    // A post_step group (top level only) runs after the time step, not with the others.
    if (sub.postStep)
      s_->postStep.push_back({fn, &sub});
    else
      out.calls.push_back(fn);
  }
  flush();
  if (g.iterate) {
    out.convergers = convergers(g);
    // Numbered as the groups are completed (subgroups first).
    out.statsIndex = static_cast<int>(s_->iteratedGroups.size());
    s_->iteratedGroups.push_back(g.loc);
  }
}

// A run of fused groups (ScheduleGroupFusion.cpp): the first group's function with one phase
// of every group's equations, in order, and their pair quantities joined.
void ScheduleBuilder::fusedGroup(const std::vector<const PlanGroup*>& run,
                                 const std::string& name, ScheduleGroup& out) {
  const PlanGroup& first = *run.front();
  out.name = name;
  out.group = &first;
  out.fused.assign(run.begin() + 1, run.end());
  std::vector<int> eqIds;
  PairQuantityMap pq;
  for (const PlanGroup* g : run) {
    eqIds.insert(eqIds.end(), g->equations.begin(), g->equations.end());
    for (const auto& [key, q] : g->pairQuantities) pq[key].insert(q.begin(), q.end());
  }
  std::string fn = unique(name + "_" + firstLive(eqIds).name);
  out.members.push_back({true, 0});
  out.phases.push_back(phase(first, eqIds, fn, pq));
  out.calls.push_back(fn);
}

// The `converged` tests of an iterated group: those of its equations and of the equations in
// its subgroups, at any depth (as PySPH's Group), except inside a nested iterated group.
std::vector<const PlanEquation*> ScheduleBuilder::convergers(const PlanGroup& g) const {
  std::vector<const PlanEquation*> out;
  std::function<void(const PlanGroup&)> collect = [&](const PlanGroup& grp) {
    for (int entry : grp.order) {
      if (entry < 0) {
        const PlanGroup& sub = *grp.subgroups[-entry - 1];
        if (!sub.iterate) collect(sub);
        continue;
      }
      const auto& eq = plan_.equations[grp.equations[entry]];
      if (eq.live && has(eq, ast::Method::Converged)) out.push_back(&eq);
    }
  };
  collect(g);
  return out;
}

Phase ScheduleBuilder::phase(const PlanGroup& g, const std::vector<int>& eqIds,
                             const std::string& name, const PairQuantityMap& pq) {
  Phase ph;
  ph.name = name;
  ph.group = &g;
  ph.equations = eqIds;
  std::vector<int> dests;
  for (int e : eqIds) {
    const auto& eq = plan_.equations[e];
    if (eq.live && std::find(dests.begin(), dests.end(), eq.dest) == dests.end())
      dests.push_back(eq.dest);
  }
  for (int d : dests) ph.destinations.push_back(destination(g, eqIds, d, pq));
  return ph;
}

DestinationWork ScheduleBuilder::destination(const PlanGroup& g, const std::vector<int>& eqIds,
                                             int d, const PairQuantityMap& pq) {
  DestinationWork w;
  w.array = d;
  for (int e : eqIds)
    if (plan_.equations[e].live && plan_.equations[e].dest == d)
      w.equations.push_back(&plan_.equations[e]);
  w.onGhosts = !g.real && hasGhosts(d);
  w.startIdx = g.startIdx;
  w.stopIdx = g.stopIdx;
  for (const auto* eq : w.equations)
    for (const auto& [k, b] : plan_.equationDecls[eq->declIndex].methods) {
      for (const auto& r : plan_.bodies[b].facts.dReads) w.destProps.insert(r.prop);
      for (const auto& wr : plan_.bodies[b].facts.dWrites) w.destProps.insert(wr.prop);
    }
  w.initialize = withMethod(w.equations, ast::Method::Initialize);
  w.passes = neighbourPasses(w.equations, d, pq);
  w.postLoop = withMethod(w.equations, ast::Method::PostLoop);
  for (const auto* eq : withMethod(w.equations, ast::Method::Reduce)) {
    const auto& pd = plan_.equationDecls[eq->declIndex];
    Reduction r;
    r.equation = eq;
    r.op = pd.reduceOp;
    r.target = pd.reduceTarget;
    r.combine = r.op == "sum" || r.op == "mean" ? LoopOrder::Serial : LoopOrder::Parallel;
    w.reductions.push_back(r);
  }
  w.hostReduce = withMethod(w.equations, ast::Method::HostReduce);
  // --mpi: a `real = false` phase with neighbour loops runs on the real particles only and
  // the halo then receives the owners' values (a refresh): halo particles at a rank cut lack
  // the neighbours beyond it. Per-particle phases still run on the halo (same values).
  if (w.onGhosts && plan_.distributed && !w.passes.empty()) w.onGhosts = false;
  if (!w.onGhosts) w.ghostRefresh = ghostRefresh(d, w.equations);
  return w;
}

// One pass per source, in order of first use: every equation looping over that source shares
// its candidates and pair quantities.
std::vector<NeighbourPass> ScheduleBuilder::neighbourPasses(
    const std::vector<const PlanEquation*>& eqs, int d, const PairQuantityMap& pq) {
  std::vector<int> sources;
  for (const auto* eq : eqs)
    for (auto kind : {ast::Method::InitializePair, ast::Method::LoopAll, ast::Method::Loop})
      if (has(*eq, kind))
        for (int s : eq->sources)
          if (std::find(sources.begin(), sources.end(), s) == sources.end())
            sources.push_back(s);
  std::vector<NeighbourPass> passes;
  for (int s : sources) {
    NeighbourPass pass;
    pass.source = s;
    auto it = pq.find({d, s});
    if (it != pq.end()) pass.pairQuantities = it->second;
    pass.pairQuantities = pairQuantityClosure(pass.pairQuantities);
    for (auto kind : {ast::Method::InitializePair, ast::Method::LoopAll, ast::Method::Loop})
      for (const auto* eq : withMethod(eqs, kind)) {
        if (std::find(eq->sources.begin(), eq->sources.end(), s) == eq->sources.end()) continue;
        (kind == ast::Method::Loop      ? pass.equations
         : kind == ast::Method::LoopAll ? pass.loopAll
                                        : pass.initializePair)
            .push_back(eq);
        for (const auto& r : body(*eq, kind).facts.sReads) pass.sourceProps.insert(r.prop);
      }
    if (pass.searches()) {
      sourceNames_.insert(plan_.arrays[s].name);
      loopNames_.insert(plan_.arrays[s].name);
      loopNames_.insert(plan_.arrays[d].name);
    }
    for (const auto& p : pairQuantityProps(plan_.dim, pass.pairQuantities)) pass.shared.insert(p);
    passes.push_back(std::move(pass));
  }
  return passes;
}

// Ghosts copy the values a phase computed on the real particles, where they carry them.
std::vector<std::string> ScheduleBuilder::ghostRefresh(
    int d, const std::vector<const PlanEquation*>& eqs) const {
  std::vector<std::string> refresh;
  if (!hasGhosts(d)) return refresh;
  std::set<std::string> written;
  for (const auto* eq : eqs)
    for (const auto& [k, b] : plan_.equationDecls[eq->declIndex].methods)
      for (const auto& w : plan_.bodies[b].facts.dWrites) written.insert(w.prop);
  for (const auto& p : plan_.arrays[d].ghostProps)
    if (written.count(p)) refresh.push_back(p);
  return refresh;
}

static bool isStepperStatement(const std::string& s) {
  return s != "compute_accelerations" && s != "update_domain";
}

void ScheduleBuilder::step() {
  const auto& steps = plan_.integratorSteps;
  for (const auto& st : steps) s_->stages += st.rfind("stage", 0) == 0;
  int done = 0;
  for (size_t k = 0; k < steps.size();) {
    if (steps[k] == "compute_accelerations") {
      s_->step.push_back({StepStatement::ComputeAccelerations, -1, {done}});
      ++k;
      continue;
    }
    if (steps[k] == "update_domain") {
      s_->step.push_back({StepStatement::UpdateDomain, -1, {done}});
      ++k;
      continue;
    }
    // A run of consecutive stepper statements.
    StepperRun run;
    run.name = "stepper";
    StepStatement st;
    st.kind = StepStatement::Stepper;
    for (; k < steps.size() && isStepperStatement(steps[k]); ++k) {
      run.methods.push_back(steps[k]);
      run.name += "_" + steps[k];
      st.stagesDone.push_back(done);
      if (steps[k].rfind("stage", 0) == 0) ++done;
    }
    auto same = std::find_if(s_->stepperRuns.begin(), s_->stepperRuns.end(),
                             [&](const StepperRun& r) { return r.name == run.name; });
    if (same == s_->stepperRuns.end()) {
      for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a) {
        const PlanArray& A = plan_.arrays[a];
        if (A.stepper < 0) continue;
        StepperRun::Part part;
        part.array = a;
        part.stepper = &plan_.steppers[A.stepper];
        for (size_t j = 0; j < run.methods.size(); ++j) {
          auto it = part.stepper->methods.find(run.methods[j]);
          if (it == part.stepper->methods.end()) continue;
          const PlanBody* b = &plan_.bodies[it->second];
          part.bodies.push_back({j, b});
          for (const auto& r : b->facts.dReads) part.destProps.insert(r.prop);
          for (const auto& w : b->facts.dWrites) part.destProps.insert(w.prop);
        }
        if (!part.bodies.empty()) run.parts.push_back(std::move(part));
      }
      st.run = static_cast<int>(s_->stepperRuns.size());
      s_->stepperRuns.push_back(std::move(run));
    } else {
      st.run = static_cast<int>(same - s_->stepperRuns.begin());
    }
    s_->step.push_back(std::move(st));
  }
  if (!plan_.zones.empty()) {  // the inlet/outlet manager, at the end of the step
    s_->step.push_back({StepStatement::InletOutlet, -1, {s_->stages}});
    std::set<int> resized;
    for (const auto& z : plan_.zones) resized.insert({z.array, z.other});
    s_->resized.assign(resized.begin(), resized.end());
  }
}

void ScheduleBuilder::adaptiveDt() {
  AdaptiveDt& a = s_->adaptiveDt;
  a.enabled = plan_.adaptiveDt;
  if (!a.enabled) return;
  for (int i = 0; i < static_cast<int>(plan_.arrays.size()); ++i)
    if (movesParticles(plan_, i)) a.arrays.push_back(i);
  a.cfl = plan_.cfl || !plan_.forceFactor;
  a.force = plan_.forceFactor != nullptr;
  a.viscous = plan_.nu != nullptr;
}

}  // namespace

std::unique_ptr<Schedule> buildSchedule(const Plan& plan, bool fuseGroups) {
  return ScheduleBuilder(plan, fuseGroups).run();
}

// ---- --dump-after=schedule ------------------------------------------------------------------

namespace {

class SchedulePrinter {
 public:
  SchedulePrinter(const Schedule& s, const DiagnosticEngine& diags, llvm::raw_ostream& os)
      : s_(s), p_(*s.plan), diags_(diags), os_(os) {}
  void print();

 private:
  const std::string& name(int a) const { return p_.arrays[a].name; }
  std::string eqName(const PlanEquation* eq) const {
    return eq->name + " (eq " + std::to_string(eq->id) + ")";
  }
  std::string eqList(const std::vector<const PlanEquation*>& eqs) const {
    std::string s;
    for (const auto* eq : eqs) s += (s.empty() ? "" : ", ") + eqName(eq);
    return s;
  }
  static std::string order(LoopOrder o) { return o == LoopOrder::Parallel ? "parallel" : "serial"; }
  static std::string list(const std::set<std::string>& xs) {
    std::string s;
    for (const auto& x : xs) s += (s.empty() ? "" : " ") + x;
    return s.empty() ? "-" : s;
  }
  void group(const ScheduleGroup& g, int indent);
  void phase(const Phase& ph, int indent);
  std::string time(int stagesDone) const {
    return stagesDone == 0 ? "t"
                           : "t + " + std::to_string(stagesDone) + "/" +
                                 std::to_string(s_.stages) + " dt";
  }

  const Schedule& s_;
  const Plan& p_;
  const DiagnosticEngine& diags_;
  llvm::raw_ostream& os_;
};

void SchedulePrinter::print() {
  os_ << "schedule of scene " << p_.sceneName << "\n";
  os_ << "set-up: params, equation constants, arrays";
  for (int a : s_.setupArrays) {
    const auto* decl = p_.arrays[a].decl;
    os_ << " " << name(a) << " (" << decl->geometry.size() << " geometry, " << decl->loads.size()
        << " files)";
  }
  os_ << (p_.domain.any() ? ", domain" : "") << "\n";
  os_ << "neighbour search:";
  if (s_.searchArrays.empty()) os_ << " none";
  os_ << "\n";
  if (!s_.searchArrays.empty()) {
    os_ << "  search domain over:";
    for (int a : s_.searchArrays) os_ << " " << name(a);
    os_ << "\n  cell lists:";
    for (int a : s_.cellLists) os_ << " " << name(a);
    os_ << "\n";
    if (!s_.keepOrder.empty()) {
      os_ << "  never reordered (start_idx / stop_idx):";
      for (int a : s_.keepOrder) os_ << " " << name(a);
      os_ << "\n";
    }
    if (s_.domain && !s_.distribution.enabled)  // distributed: the halo lines below
      for (int a : s_.cellLists) {
        os_ << "  ghosts of " << name(a) << " carry:";
        for (const auto& p : p_.arrays[a].ghostProps) os_ << " " << p;
        os_ << "\n";
      }
  }
  os_ << "evaluation (compute_accelerations):"
      << (s_.distribution.enabled
              ? " update_domain, update_neighbours (migrate, halo exchange), equations, remove halo"
          : s_.domain ? " update_domain, update_neighbours, equations, remove ghosts"
                      : " update_neighbours, equations")
      << "\n";
  group(s_.equations, 1);
  if (!s_.postStep.empty()) {
    os_ << "post_step (after each time step, when one is due):";
    for (const auto& ps : s_.postStep)
      os_ << " " << ps.function << (ps.group->every ? " (every)" : "");
    os_ << "\n";
  }
  os_ << "step (integrator " << (p_.integratorName.empty() ? "none" : p_.integratorName)
      << ", " << s_.stages << " stages):\n";
  for (const auto& st : s_.step) {
    if (st.kind == StepStatement::ComputeAccelerations) {
      os_ << "  compute_accelerations at " << time(st.stagesDone[0]) << "\n";
    } else if (st.kind == StepStatement::UpdateDomain) {
      os_ << "  update_domain" << (p_.domain.any() ? "" : " (no periodic or mirror domain: nothing)")
          << "\n";
    } else if (st.kind == StepStatement::InletOutlet) {
      os_ << "  inlet_outlet at " << time(st.stagesDone[0]) << " [serial, on the host]:";
      for (const auto& z : p_.zones)
        os_ << " " << (z.inlet ? "inlet " : "outlet ") << z.name << " ("
            << name(z.array) << (z.inlet ? " -> " : " <- ") << name(z.other) << ")";
      os_ << "; resizes";
      for (int a : s_.resized) os_ << " " << name(a);
      os_ << "\n";
    } else {
      const StepperRun& r = s_.stepperRuns[st.run];
      os_ << "  stepper run " << r.name << " [fused, " << order(r.order) << "]:";
      for (size_t j = 0; j < r.methods.size(); ++j)
        os_ << (j ? "," : "") << " " << r.methods[j] << " at " << time(st.stagesDone[j]);
      os_ << "\n";
      if (r.parts.empty()) os_ << "    no array has these methods: nothing\n";
      for (const auto& part : r.parts) {
        os_ << "    " << name(part.array) << ": " << part.stepper->decl->name.name;
        for (size_t i = 0; i < part.bodies.size(); ++i)
          os_ << (i ? ", " : ".") << r.methods[part.bodies[i].first];
        os_ << "\n";
      }
    }
  }
  if (!s_.postStep.empty()) os_ << "  post_step\n";
  const AdaptiveDt& a = s_.adaptiveDt;
  if (a.enabled) {
    os_ << "adaptive dt [" << order(a.order) << " min]: limits";
    if (a.cfl) os_ << " cfl";
    if (a.force) os_ << " force";
    if (a.viscous) os_ << " viscous";
    os_ << " over";
    for (int i : a.arrays) os_ << " " << name(i);
    if (a.arrays.empty()) os_ << " no moving array";
    os_ << (s_.distribution.enabled ? ", then the minimum over all ranks (MPI_Allreduce)" : "")
        << "\n";
  }
  printDistribution(s_, os_);
}

void SchedulePrinter::group(const ScheduleGroup& g, int indent) {
  std::string pad(2 * indent, ' ');
  const PlanGroup& pg = *g.group;
  os_ << pad << "group " << g.name << ", from " << diags_.lineInfo(pg.loc);
  if (!pg.real) os_ << ", real = false";
  if (pg.every) os_ << ", every";
  if (pg.condition) os_ << ", condition";
  if (pg.postStep) os_ << ", post_step";
  os_ << "\n";
  if (!g.fused.empty()) {
    os_ << pad << "  fused with the groups from";
    for (const PlanGroup* f : g.fused) os_ << " " << diags_.lineInfo(f->loc);
    os_ << " (one phase: none reads or writes what an earlier one writes, nor writes what it "
           "reads)\n";
  }
  if (pg.iterate) {
    os_ << pad << "  iterated " << pg.minIterations << ".." << pg.maxIterations
        << " times (statistics " << g.statsIndex << "), converged when: "
        << (g.convergers.empty() ? "always" : eqList(g.convergers))
        << (s_.distribution.enabled ? " (on every rank: MPI_Allreduce)" : "") << "\n";
  }
  for (const auto& m : g.members) {
    if (m.isPhase)
      phase(g.phases[m.index], indent + 1);
    else
      group(*g.subgroups[m.index], indent + 1);
  }
  if (g.rebuildNeighbours)
    os_ << pad << "  then rebuild the neighbour search (update_nnps)"
        << (pg.iterate ? ", in each iteration" : "") << "\n";
}

void SchedulePrinter::phase(const Phase& ph, int indent) {
  std::string pad(2 * indent, ' ');
  os_ << pad << "phase " << ph.name << "\n";
  for (const auto& w : ph.destinations) {
    os_ << pad << "  destination " << name(w.array)
        << (w.onGhosts ? " (real particles and ghosts)" : " (real particles)") << "\n";
    if (w.ranged())
    {
      os_ << pad << "    particles ";
      if (w.startIdx) printExpr(*w.startIdx, os_); else os_ << "0";
      os_ << " <= d_idx < ";
      if (w.stopIdx) printExpr(*w.stopIdx, os_); else os_ << "n";
      os_ << " (initialize, neighbours, post_loop)\n";
    }
    if (!w.initialize.empty())
      os_ << pad << "    initialize [" << order(w.perParticle) << "]: " << eqList(w.initialize)
          << "\n";
    for (const auto& pass : w.passes) {
      if (!pass.initializePair.empty())
        os_ << pad << "    initialize_pair " << name(w.array) << " <- " << name(pass.source)
            << " [" << order(pass.order) << "]: " << eqList(pass.initializePair) << "\n";
      if (!pass.searches()) {
        os_ << pad << "      source properties: " << list(pass.sourceProps) << "\n";
        continue;
      }
      os_ << pad << "    neighbours " << name(w.array) << " <- " << name(pass.source) << " ["
          << order(pass.order) << "]: " << eqList(pass.equations) << "\n";
      if (!pass.loopAll.empty())
        os_ << pad << "      loop_all (neighbour list NBRS, N_NBRS): " << eqList(pass.loopAll)
            << "\n";
      os_ << pad << "      pair quantities: " << list(pass.pairQuantities) << "\n";
      os_ << pad << "      source properties: " << list(pass.sourceProps) << "\n";
    }
    if (!w.postLoop.empty())
      os_ << pad << "    post_loop [" << order(w.perParticle) << "]: " << eqList(w.postLoop)
          << "\n";
    if (!w.hostReduce.empty())
      os_ << pad << "    reduce on the host: " << eqList(w.hostReduce) << "\n";
    for (const auto& r : w.reductions)
      os_ << pad << "    reduce " << r.op << " into " << name(w.array) << "." << r.target
          << " [values parallel, combined " << order(r.combine) << "]: " << eqName(r.equation)
          << (w.onGhosts ? " (real particles only)" : "")
          << (s_.distribution.enabled ? ", then over all ranks (MPI_Allreduce)" : "") << "\n";
    if (!w.ghostRefresh.empty()) {
      os_ << pad << (s_.distribution.enabled ? "    refresh halo:" : "    refresh ghosts:");
      for (const auto& p : w.ghostRefresh) os_ << " " << p;
      os_ << "\n";
    }
  }
}

}  // namespace

void printSchedule(const Schedule& s, const DiagnosticEngine& diags, llvm::raw_ostream& os) {
  SchedulePrinter(s, diags, os).print();
}

void walkPhases(const ScheduleGroup& g, const std::function<void(const Phase&)>& fn) {
  for (const Phase& ph : g.phases) fn(ph);
  for (const auto& sub : g.subgroups) walkPhases(*sub, fn);
}

void walkPasses(const ScheduleGroup& g,
                const std::function<void(const Phase&, const DestinationWork&,
                                         const NeighbourPass&)>& fn) {
  walkPhases(g, [&](const Phase& ph) {
    for (const DestinationWork& w : ph.destinations)
      for (const NeighbourPass& pass : w.passes) fn(ph, w, pass);
  });
}

}  // namespace sphc
