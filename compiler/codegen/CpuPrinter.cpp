// The CPU backends: a phase's destination as loops over particles, neighbour passes over a
// CellList, fused stepper runs, the neighbour search and ghosts on the host, the adaptive
// time step's limits. Serial and OpenMP differ by pragmas only: a loop that the schedule
// marks parallel gets `#pragma omp parallel for` on OpenMP and nothing on serial. Loops over
// destination particles only write their own particle (gather), so they need no atomics and
// give the serial result bit for bit.
#include "codegen/CpuLazyCells.h"
#include "codegen/CpuVerletTune.h"
#include "codegen/Printer.h"
#include "analysis/KeptGhostSpan.h"
#include "analysis/PositionReads.h"
#include "codegen/SymmetricPairs.h"
#include "frontend/FormatNumber.h"

#include <cstdio>
#include <functional>
#include <stdexcept>
#include <set>

namespace sphc {

namespace {

class CpuPrinter : public ScenePrinter {
 public:
  CpuPrinter(const Schedule& sched, const DiagnosticEngine& diags, const EmitOptions& opts)
      : ScenePrinter(sched, diags, opts),
        openmp_(opts.backend == Backend::OpenMP),
        ompMinParticles_(opts.ompMinParticles),
        verletSkin_(opts.verletSkin > 0 && !mpi_ && !ghostPairLoops() && !hasZones()
                        ? opts.verletSkin
                        : 0.0),
        tuned_(verletSkin_ > 0 && opts.verletAuto && !hasDomain()),
        symmetric_(opts.symmetricPairs),
        lazyCells_(opts.lazyCells) {}

 private:
  std::string backendComment() const override {
    return std::string(openmp_ ? "openmp (loops over particles in parallel)" : "serial") +
           (cpuSingle_ ? "; single precision (float copies of the arrays)" : "");
  }
  void runtimeIncludes() override {
    if (cpuSingle_) out_ << "#include \"sphc/float_arrays.h\"\n";
    if (verlet()) out_ << "#include \"sphc/verlet.h\"\n";
    if (tuned_) out_ << "#include \"sphc/verlet_tune.h\"\n";
    if (openmp_ && anyCrossPair()) out_ << "#include \"sphc/cross_pairs.h\"\n";
    if (anyClusterTiles()) out_ << "#include \"sphc/cluster_pairs.h\"\n";
  }
  // --simd-pairs=cluster (codegen/ClusterPairs.cpp): the base's conditions, then the CPU
  // printer's: serial, the fixed skin, kept lists of the pass's own.
  std::string clusterTilesFormRefusal(const DestinationWork& w,
                                      const NeighbourPass& pass) const override;
  // Slot order (stop 40): the pass over its own array, which is sorted (no ranged group
  // names its particles by index), double, without ghosts or halos.
  bool clusterSlotOrder(const DestinationWork& w, const NeighbourPass& pass) const override {
    return clusterSlotOrder_ && !mpi_ && !cpuSingle_ && !hasDomain() && !hasZones() &&
           w.array == pass.source && !w.ranged() && reorders(arr(w.array).name);
  }
  std::string slotOrderLists(const std::string& S) const;
  bool slotOrdered(const std::string& S) const { return !slotOrderLists(S).empty(); }
  void emitSlotOrder(const std::string& S);
  std::pair<int, int> clusterListsShare(const DestinationWork& w,
                                        const NeighbourPass& pass) const override;
  // The passes over the same kept lists as `pass` (walk order) with their phases.
  std::vector<std::pair<const DestinationWork*, const NeighbourPass*>> listUsers(
      const DestinationWork& w, const NeighbourPass& pass, std::vector<std::string>* phases = nullptr) const;
  mutable bool sharedListsCheck_ = false;  // clusterTilesFormRefusal asking for another user
  bool anyClusterTiles() const {
    bool any = false;
    walkPasses(sched_.equations, [&](const Phase&, const DestinationWork& w,
                                     const NeighbourPass& pass) {
      any |= pass.searches() && clusterTilesRefusal(w, pass).empty();
    });
    return any;
  }
  void systemIncludes() override {
    if (openmp_) out_ << "\n#include <omp.h>\n";
  }
  void searchMembers() override;
  std::string ghostsType() const override { return mpi_ ? "sphc::mpi::Halo" : "sphc::Ghosts"; }
  void extraMembers() override {
    if (openmp_)
      out_ << "  std::vector<" << real_ << "> reduce_scratch;  // reduce sum/mean, OpenMP\n";
    if (openmp_ && ompMinParticles_ > 0)
      out_ << "  // --omp-min-particles: loops without neighbours over fewer particles run on the\n"
              "  // calling thread (waking the team costs more than their few ns per particle).\n"
              "  static constexpr long OMP_MIN_PARTICLES = "
           << ompMinParticles_ << ";\n";
    // The neighbour list of the destination particle in hand (pair loops, loop_all), one per
    // thread, reused from particle to particle (CellList::gather_neighbours).
    out_ << "  std::vector<std::vector<std::uint32_t>> nbrs_lists;\n";
    if (verlet()) verletMembers();
    emitHoistMembers(out_);
    if (verlet() && symmetric_) emitSymmetricMembers(out_);
  }
  // --verlet-skin: the lists are kept across evaluations (sphc/verlet.h).
  bool verlet() const { return verletSkin_ > 0; }
  void verletMembers();
  // The rebuild check of the kept lists `lists` of w's pass over source s (verlet_build).
  void listsRebuildCheck(const std::string& lists, const DestinationWork& w, int s,
                         bool cells = true);
  // One displacement scan per array and phase (sphc::PhaseDisplacements): declared where the
  // phase checks two kept lists or more and nothing in it writes positions or h; its checks
  // then pass it.
  void phasePrologue(const Phase& ph) override;
  bool phaseDisplacements_ = false;
  // The loop bodies called both ways by the each-pair-once loops (codegen/PairShared.cpp).
  std::set<const PlanBody*> pairSharedBodies() const override;
  // Whether the pass over w's own array is printed each pair once (emitSymmetricPass).
  bool symmetricPass(const DestinationWork& w, const NeighbourPass& pass) const;
  // The destinations {A, B} of w's phase whose pair loops A <- B and B <- A run as one pass
  // (crossPairsRefusal; kept lists; OpenMP in blocks), where w is A or B; {} elsewhere.
  std::pair<const DestinationWork*, const DestinationWork*> crossPair(
      const DestinationWork& w) const;
  // OpenMP: the kept lists of the A <- B loops run with B <- A as one pass, each with the
  // name of B (their member LISTS_by_source, sphc/cross_pairs.h, found again after a build).
  std::map<std::string, std::string> crossSourceLists() const {
    std::map<std::string, std::string> out;
    walkPhases(sched_.equations, [&](const Phase& ph) {
      for (const DestinationWork& w : ph.destinations)
        if (openmp_ && crossPair(w).first == &w)
          out.emplace(verletLists(ph.name, w, w.passes.back().source),
                      arr(w.passes.back().source).name);
    });
    return out;
  }
  bool anyCrossPair() const {
    bool any = false;
    walkPhases(sched_.equations, [&](const Phase& ph) {
      for (const DestinationWork& w : ph.destinations) any |= crossPair(w).first != nullptr;
    });
    return any;
  }
  // --verlet-skin=auto: the skin and the re-sort chosen at run time (sphc/verlet_tune.h;
  // CpuVerletTune.cpp); --verlet-skin=F keeps the code of a fixed skin.
  bool tuned() const { return tuned_; }
  void tunedMembers();
  // The arrays of a pair loop whose positions or h something may change (the others are
  // static: the lists' rebuild check skips them).
  std::vector<int> movingArrays(int d, int s) const;
  void tunedRebuildCheck(const std::string& lists, const DestinationWork& w, int d, int s);
  // The kept lists whose destination or source is array S (forgotten after S is sorted).
  std::vector<std::string> listsOf(const std::string& S) const;
  void tunedUpdateNeighbours();
  // --verlet-skin without a periodic or mirror domain: the search domain and the moving
  // sources' cell lists are built only where a pair loop rebuilds its kept lists
  // (CpuLazyCells.cpp; docs/performance-log.md, "Cell lists only when a kept list is rebuilt").
  bool lazyCells() const { return lazyCells_ && verlet() && !hasDomain(); }
  void emitLazyCells();
  void lazyCellsMembers();
  void lazyCellsDue();  // end of update_neighbours: the domain and cells out of date
  std::vector<std::string> movingSources() const;  // the sources that are not static
  // `const std::vector<const sphc::ParticleArray*> all = {...};`: the arrays of the
  // neighbour loops (the search domain's).
  std::string loopArraysDecl() const;
  // Calls f(lists, phase, w, pass) for every pair loop that keeps lists (verletLists).
  void forEachVerletLists(
      const std::function<void(const std::string&, const Phase&, const DestinationWork&,
                               const NeighbourPass&)>& f) const;
  // Whether a neighbour pass runs on ghosts too (a `real = false` group with a domain): no
  // kept lists there (the driver's ghostPairLoops on the plan).
  bool ghostPairLoops() const {
    bool any = false;
    walkPasses(sched_.equations, [&](const Phase&, const DestinationWork& w,
                                     const NeighbourPass& pass) {
      any |= w.onGhosts && pass.searches();
    });
    return any;
  }
  // --verlet-skin with a periodic or mirror domain (the lists and ghosts kept together).
  void updateNeighboursKeptGhosts();
  // sphc::add_ghosts of every source array within `cutoff` (a local of the generated code),
  // carrying its ghost properties.
  void addGhosts(const std::string& indent);
  // The member holding the kept lists of the pass of destination work w over source s in a
  // phase. The pair loops of every phase with the same destination and source share one set
  // of lists (the support radius is the scene's), rebuilt by whichever loop finds them stale;
  // a group with start_idx or stop_idx keeps lists of its own (its range, its phase).
  std::string verletLists(const std::string& phase, const DestinationWork& w, int s) const {
    return "verlet_" + (w.ranged() ? phase + "_" : std::string()) + arr(w.array).name + "_" +
           arr(s).name;
  }
  bool timesNeighbourSearch() const override { return true; }
  void dataMovement() override;
  void destination(const DestinationWork& w, const std::string& phase) override;
  void reduction(const DestinationWork& w, const Reduction& r);
  void ghostRefresh(const DestinationWork& w);
  void steppers() override;
  std::string stepperIf(const StepperRun& run) const;
  void stepperCall(const StepStatement& st,
                   const std::function<std::string(int)>& timeAfter) override;
  void wrapPeriodic(int a) override {
    if (verlet()) {  // the particles near the box keep their ghosts (updateNeighboursKeptGhosts)
      scene_ << "    sphc::wrap_periodic_far(box, " << hostData(a)
             << ", WRAP_MARGIN * Kernel::radius_scale);\n";
      return;
    }
    scene_ << "    sphc::wrap_periodic(box, " << hostData(a) << ");\n";
  }
  void updateNeighbours() override;
  void staticCellLists() override {
    if (anyStatic()) emitStaticCells();
    if (lazyCells()) emitLazyCells();  // CpuLazyCells.cpp
  }
  void updateNeighboursWithGhosts() override;
  std::string removeGhosts() const override;
  std::string wrapBeforeEvaluation() const override {
    if (!verlet() || !hasDomain()) return "";
    std::string r;
    for (const PlanGroup* g : positionReads(plan_).wrapBefore)
      r += "    if (" + groupOptionCpp(*g->condition) + ") wrap_into_box();  // a group reading "
           "positions runs now (condition = " + exprText(*g->condition) + "): every particle "
           "into the box (analysis/PositionReads.cpp)\n";
    return r;
  }
  void timedNeighbourUpdate() override;
  void adaptiveDtArray(int a) override;
  void mainPrologue() override {
    if (openmp_)
      out_ << "  sphc::choose_omp_wait(argc, argv);  // spin or sleep at barriers "
              "(sphc/solver.h)\n";
  }
  void mainBackendOptions() override {
    // Single precision: the host doubles the output writes taken again after the wrap.
    if (verlet() && hasDomain())
      out_ << (cpuSingle_ ? "  prog.before_output = [] {\n    scene.wrap_into_box();\n"
                            "    scene.to_host();\n  };\n"
                          : "  prog.before_output = [] { scene.wrap_into_box(); };\n");
    if (openmp_)
      out_ << "  prog.set_threads = [](int n) {\n"
              "    if (n > 0) omp_set_num_threads(n);\n"
              "    return omp_get_max_threads();\n  };\n";
  }
  std::string afterSetup() const override {
    return cpuSingle_ ? "    if (!sphc::counting_particles()) scene.to_single();\n" : "";
  }
  bool hasToHost() const override { return cpuSingle_; }
  std::string restoreData() const override {
    std::string r =
        cpuSingle_ ? "    scene.to_single();  // the float copies of the restored arrays\n" : "";
    if (anyStatic())
      r += "    scene.static_cells_built = false;  // the file's particles: their cells anew\n";
    return r;
  }
  // Stop 43: the tiles' layout, outer list and slot order are built from the positions at
  // their builds and sorts, whose times follow from the particles' history (the kept lists'
  // marks, the cluster pairs at the last sort): none of it is in a restart file. At each
  // restart file a --restartable run starts it afresh as a restarted run does (the lists
  // forgotten, the slot order due; the next evaluation sorts and builds them from the
  // particles now), so both go on bitwise. Without tiles nothing: the scalar loops' kept
  // lists are in index order (sphc/verlet.h).
  std::string restartPoint() const override {
    std::string r;
    if (!verlet()) return r;
    forEachVerletLists([&](const std::string& lists, const Phase&, const DestinationWork& w,
                           const NeighbourPass& pass) {
      if (!clusterTilesRefusal(w, pass).empty()) return;  // as clusterTilesMembers
      r += "    scene." + lists + ".skin.forget();  // " + arr(w.array).name + " <- " +
           arr(pass.source).name + " in tiles: built again at the next evaluation\n";
      r += clusterSortFresh("scene." + lists, "    ");
    });
    return r;
  }
  std::string afterRemoval(int a) const override {
    const std::string& A = arr(a).name;
    std::string r;
    if (cpuSingle_) r += "      scene.f32_" + A + ".upload(scene." + A + ");  // its float copy\n";
    if (isStatic(A)) r += "      scene.static_cells_built = false;  // its cells anew\n";
    return r;
  }
  // --precision=single: the manager works on the host doubles; the float copies follow.
  void arraysToHost(const std::vector<int>& arrays) override {
    if (!cpuSingle_) return;
    for (int a : arrays) scene_ << "    f32_" << arr(a).name << ".download(" << arr(a).name << ");\n";
  }
  void arraysFromHost(const std::vector<int>& arrays) override {
    if (!cpuSingle_) return;
    for (int a : arrays) scene_ << "    f32_" << arr(a).name << ".upload(" << arr(a).name << ");\n";
  }

  // `#pragma omp parallel for` (with `clauses`) before a loop the schedule marks parallel,
  // on the OpenMP backend; nothing for serial.
  std::string parallelFor(const std::string& indent, LoopOrder order,
                          const std::string& clauses = "") const {
    if (!openmp_ || order != LoopOrder::Parallel) return "";
    return indent + "#pragma omp parallel for schedule(static)" +
           (clauses.empty() ? "" : " " + clauses) + "\n";
  }
  // --omp-min-particles: the `if` clause of a loop without neighbours over `count`
  // particles ("" when the option is 0). Each particle's result is the same on one thread.
  std::string ompIf(const std::string& count) const {
    return ompMinParticles_ > 0 ? "if (" + count + " >= OMP_MIN_PARTICLES)" : "";
  }
  std::string ompMinIf(const std::string& count) const override { return openmp_ ? ompIf(count) : ""; }
  // ompIf after `clauses`.
  static std::string withIf(const std::string& clauses, const std::string& cond) {
    return clauses.empty() ? cond : cond.empty() ? clauses : clauses + " " + cond;
  }
  // The number of particles of a destination's loops: its range or n.
  static std::string rangeCount(const DestinationWork& w) {
    return w.ranged() ? rangeEnd(w) + " - " + rangeBegin(w) : rangeEnd(w);
  }
  // The data the CPU domain functions work on: "a" (the host array) or, with
  // --precision=single, "f32_a, a" (its float copy, and the host array for the integers).
  std::string hostData(int a) const {
    return (cpuSingle_ ? "f32_" + arr(a).name + ", " : std::string()) + arr(a).name;
  }
  // The array whose positions and h the kept lists' displacement checks read: the host
  // array, or (--precision=single) its float copy, which the scene computes on.
  std::string positions(int a) const { return (cpuSingle_ ? "f32_" : "") + arr(a).name; }
  // The statement that makes order_domain, the support's grid that permutations sort on
  // (--verlet-skin): from `all` (loopArraysDecl), or (single) from the float positions.
  std::string orderDomain() const;
  // `domain` = the search domain of every array in a neighbour loop, from its doubles or
  // (single) floats; with `only`, `dom` = the box of that array alone.
  void searchDomain(const std::string& only = "", const std::string& dom = "domain");
  // --precision=single: the statement `dom = make_search_domain_float(...)` (its newline
  // included) over `only` or every array of a neighbour loop, with cells of `radius`.
  std::string floatDomain(const std::string& only, const std::string& dom,
                          const std::string& radius) const;
  // Whether source S is static: nothing moves, adds or removes its particles, nor changes h
  // of any array in a neighbour loop (so the cell size is fixed), and it has no ghosts. Its
  // cell list is built once (build_static_cells), on a grid of its own box.
  bool isStatic(const std::string& S) const;
  bool anyStatic() const {
    for (const auto& S : sourceArrays_)
      if (isStatic(S)) return true;
    return false;
  }
  void emitStaticCells();
  // Reorders source S into the cell order of cells_S.
  std::string permuteInCellOrder(const std::string& S) const {
    return cpuSingle_ ? "f32_" + S + ".permute(cells_" + S + ".cell_order(), " + S + ");"
                      : S + ".permute(cells_" + S + ".cell_order());";
  }
  // The statement that builds the cell list of source S over its first `count` particles
  // on the grid of search domain `dom`.
  std::string cellListBuild(const std::string& S, const std::string& count,
                            const std::string& dom = "domain") const;

  bool openmp_ = false;
  long ompMinParticles_ = 0;  // --omp-min-particles (0: every loop parallel)
  double verletSkin_ = 0.0;  // --verlet-skin (0: lists gathered at every evaluation)
  bool tuned_ = false;       // --verlet-skin=auto: skin and re-sort chosen at run time
  bool symmetric_ = true;    // each pair once where it may (--no-symmetric-pairs: false)
  bool lazyCells_ = true;    // cells only where kept lists are rebuilt (--no-lazy-cells: false)
};

// --verlet-skin: the skin and, per pair loop (phase, destination, source), each destination
// particle's candidate list with the positions it was built from.
void CpuPrinter::verletMembers() {
  char skin[64];
  std::snprintf(skin, sizeof skin, "%.17g", verletSkin_);
  out_ << "  // --verlet-skin: candidates within (1 + VERLET_SKIN) times the support, kept across\n"
          "  // evaluations and rebuilt when particles moved too far (sphc/verlet.h).\n";
  if (tuned()) {
    tunedMembers();
  } else {
    out_ << "  static constexpr double VERLET_SKIN = " << skin << ";\n";
    out_ << "  static constexpr double VERLET_RADIUS2 = RADIUS2 * (1.0 + VERLET_SKIN) * "
            "(1.0 + VERLET_SKIN);\n";
  }
  forEachVerletLists([&](const std::string& lists, const Phase& ph, const DestinationWork& w,
                         const NeighbourPass& pass) {
    // h fixed (analysis/UniformH.cpp) in every array the lists' check reads: the check reads
    // no h (sphc/verlet.h, VerletSkin's h_fixed; stop 46).
    const std::vector<int> moving = movingArrays(w.array, pass.source);
    bool hFixed = !tuned() && !moving.empty();
    for (int a : moving) hFixed = hFixed && hUniform_[a];
    out_ << "  sphc::VerletLists " << lists
         << (tuned() ? "{verlet_skin};  // " : hFixed ? "{VERLET_SKIN, true};  // h fixed; " : "{VERLET_SKIN};  // ")
         << arr(w.array).name
         << " <- " << arr(pass.source).name
         << (w.ranged() ? " (" + ph.name + ", its range)" : std::string(", every phase")) << "\n";
    if (clusterTilesRefusal(w, pass).empty())  // codegen/ClusterPairs.cpp
      clusterTilesMembers(out_, lists, arr(w.array).name + " <- " + arr(pass.source).name,
                          clusterListsShare(w, pass).second);
  });
  for (const auto& [lists, B] : crossSourceLists())
    out_ << "  sphc::CrossSources " << lists << "_by_source;  // the same lists from " << B
         << "'s side (sphc/cross_pairs.h)\n";
  if (hasDomain())
    out_ << "  // The ghosts are kept with the lists: found again when the particles moved too far\n"
            "  // (ghost_skin, over every array of a pair loop) or at a permutation, else made\n"
            "  // again in the same order from their originals (update_neighbours). Between\n"
            "  // permutations a periodic axis wraps only the particles further than\n"
            "  // WRAP_MARGIN supports outside the box (update_domain).\n"
            "  sphc::VerletSkin ghost_skin{VERLET_SKIN};\n"
            "  static constexpr double WRAP_MARGIN = " << formatNumber(kKeptWrapMargin, 17) << ";\n";
}

void CpuPrinter::forEachVerletLists(
    const std::function<void(const std::string&, const Phase&, const DestinationWork&,
                             const NeighbourPass&)>& f) const {
  std::set<std::string> declared;  // one member per set of lists (verletLists)
  walkPasses(sched_.equations, [&](const Phase& ph, const DestinationWork& w,
                                   const NeighbourPass& pass) {
    // B <- A run in A <- B's pass (crossPair) reads A <- B's lists: none of its own.
    if (crossPair(w).second == &w && &pass == &w.passes.front()) return;
    const std::string lists = verletLists(ph.name, w, pass.source);
    if (pass.searches() && declared.insert(lists).second) f(lists, ph, w, pass);
  });
}

void CpuPrinter::searchMembers() {
  out_ << "  sphc::SearchDomain domain;\n";
  if (verlet())
    out_ << "  sphc::SearchDomain order_domain;  // the support's grid: the cell order of "
            "permutations (--verlet-skin)\n";
  for (const auto& S : sourceArrays_)
    if (isStatic(S))
      out_ << "  sphc::SearchDomain domain_" << S << ";  // its own grid (build_static_cells)\n";
  if (anyStatic()) out_ << "  bool static_cells_built = false;\n";
  if (cpuSingle_)
    for (const auto& a : plan_.arrays)
      out_ << "  sphc::FloatArray f32_" << a.name << ";  // what the scene computes on\n";
  for (const auto& S : sourceArrays_) out_ << "  sphc::CellList cells_" << S << ";\n";
  if (lazyCells()) lazyCellsMembers();
}

void CpuPrinter::dataMovement() {
  if (verlet() && hasDomain()) {
    // Kept lists: between rebuilds particles may be up to WRAP_MARGIN supports outside a
    // periodic box (update_domain); an output holds them wrapped into it (the lists and
    // ghosts are then rebuilt: the particles moved by a period).
    scene_ << "  // Every particle into the periodic box: at a permutation (update_neighbours) and\n"
              "  // before each output (prog.before_output).\n";
    scene_ << "  void wrap_into_box() {\n";
    for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a)
      scene_ << "    sphc::wrap_periodic(box, " << hostData(a) << ");\n";
    scene_ << "  }\n\n";
  }
  if (!cpuSingle_) return;
  // The float copies: made after set-up; the host doubles updated for output and checks.
  scene_ << "  void to_single() {\n";
  for (const auto& a : plan_.arrays) scene_ << "    f32_" << a.name << ".upload(" << a.name << ");\n";
  scene_ << "  }\n\n";
  scene_ << "  void to_host() {\n";
  for (const auto& a : plan_.arrays)
    scene_ << "    f32_" << a.name << ".download(" << a.name << ");\n";
  scene_ << "  }\n\n";
}

// One destination of a phase: every initialize, one neighbour pass per source with every
// loop, then post_loop and the reductions; the ghosts refreshed after.
void CpuPrinter::destination(const DestinationWork& w, const std::string& phase) {
  const int d = w.array;
  const std::string& D = arr(d).name;
  const bool onGhosts = w.onGhosts;
  // Pointers of every destination property the bodies use.
  for (const auto& p : w.destProps)
    scene_ << "      " << hostType(d, p) << "* d_" << p << " = " << propPtr(d, p) << ";\n";
  auto perParticle = [&](ast::Method::Kind kind, const char* what) {
    const std::vector<const PlanEquation*>& with =
        kind == ast::Method::Initialize ? w.initialize : w.postLoop;
    if (with.empty()) return;
    std::string loop = "      for (int d_idx = " + rangeBegin(w) + "; d_idx < " + rangeEnd(w) +
                       "; ++d_idx) {  // " + what + "\n";
    for (const auto* eq : with) loop += "        " + equationCall(*eq, kind, d);
    loop += "      }\n";
    // (kept for one region with the first pass's hoisted values where a queue is open)
    ompLoop(scene_, parallelFor("      ", w.perParticle, ompIf(rangeCount(w))), loop,
            w.ranged() ? D + "|" + rangeBegin(w) + ":" + rangeEnd(w) : ompSpace(w));
  };
  // Pair loops A <- B and B <- A as one pass (codegen/SymmetricPairs.cpp, crossPairsRefusal):
  // A's last pass runs in B's first's place.
  const auto cross = crossPair(w);
  // The initialize per particle in the add-back of the first pass's tiles (ClusterPairs.cpp,
  // initInAddBackRefusal), else in its own loop here.
  const NeighbourPass* first = w.passes.empty() ? nullptr : &w.passes.front();
  const bool initInTiles = first && first->searches() && verlet() && !mpi_ &&
                           !(cross.second == &w) && !(cross.first == &w && w.passes.size() == 1) &&
                           symmetricPass(w, *first) && onceLanes(w, *first) &&
                           clusterTilesRefusal(w, *first).empty() &&
                           initInAddBackRefusal(w, *first).empty();
  // OpenMP (stop 46; --no-omp-regions): the initialize and the first pass's source-only and
  // destination-only values in one parallel region (OmpRegions.cpp), printed just before the
  // pass's pair loop. They move past the pass's pointers, h where uniform, the scratch
  // arrays' resize and the kept lists' rebuild check, none of which reads what they write:
  // not where the initialize writes the positions or h, nor before an initialize_pair (it may
  // index as it likes) or a pass of two arrays printed as one (emitCrossPass).
  bool initMoves = false;
  for (const PlanEquation* eq : w.initialize)
    for (const PropAccess& x : methodBody(*eq, ast::Method::Initialize).facts.dWrites)
      initMoves = initMoves || x.prop == "x" || x.prop == "y" || x.prop == "z" || x.prop == "h";
  const bool oneRegion = openmp_ && !mpi_ && first && first->searches() &&
                         first->initializePair.empty() && !initMoves && !(cross.second == &w) &&
                         !(cross.first == &w && w.passes.size() == 1);
  if (oneRegion) ompQueueOpen(openmp_, "        ");
  if (initInTiles)
    scene_ << "      // (initialize: in the add-back of the tiles of " << arr(first->source).name
           << ", per particle)\n";
  else
    perParticle(ast::Method::Initialize, "initialize");
  initInAddBack_ = initInTiles ? &w : nullptr;
  // One neighbour pass per source.
  for (const NeighbourPass& pass : w.passes) {
    endUniformH();  // (a pass that sets it: its own)
    if (cross.first == &w && &pass == &w.passes.back()) continue;  // in cross.second's
    if (cross.second == &w && &pass == &w.passes.front()) {
      const DestinationWork& A = *cross.first;
      const std::string lists = verletLists(phase, A, w.array);
      emitCrossPass(A, A.passes.back(), w, pass, lists,
                    tuned() ? "verlet_radius2" : "VERLET_RADIUS2",
                    [&] { listsRebuildCheck(lists, A, w.array); },
                    parallelFor("        ", pass.order, ompIf("n_src")));  // OpenMP: in blocks
      continue;
    }
    const int s = pass.source;
    const std::string& S = arr(s).name;
    const std::set<std::string>& q = pass.pairQuantities;
    scene_ << "      {  // " << (pass.searches() ? "neighbours: " : "initialize_pair: ") << D
           << " <- " << S << "\n";
    if (pass.searches())
      for (const auto& p : pass.shared) {
        scene_ << "        const " << real_ << "* di_" << p << " = " << propPtr(d, p) << ";\n";
        scene_ << "        const " << real_ << "* sj_" << p << " = " << propPtr(s, p) << ";\n";
      }
    for (const auto& p : pass.sourceProps)
      scene_ << "        const " << hostType(s, p) << "* s_" << p << " = " << propPtr(s, p)
             << ";\n";
    // h once per pass where it is one value (Bodies.cpp, beginUniformH; stop 45).
    if (pass.searches() && pass.shared.count("h")) beginUniformH(d, s, "        ");
    // PySPH's initialize_pair: per destination particle, before this source's neighbours.
    if (!pass.initializePair.empty()) {
      scene_ << parallelFor("        ", w.perParticle, ompIf(rangeCount(w)));
      scene_ << "        for (int d_idx = " << rangeBegin(w) << "; d_idx < " << rangeEnd(w)
             << "; ++d_idx) {  // initialize_pair\n";
      for (const auto* eq : pass.initializePair)
        scene_ << "          " << equationCall(*eq, ast::Method::InitializePair, d);
      scene_ << "        }\n";
    }
    if (!pass.searches()) {
      scene_ << "      }\n";
      continue;
    }
    // Source-only values of the loop bodies, once per source particle (codegen/Hoist.cpp).
    emitHoistedValues(scene_, pass, hasDomain() ? S + ".n + ghosts_" + S + ".size()" : S + ".n",
                      parallelFor("        ", pass.order, ompIf("n_src")),
                      S + (hasDomain() ? "|all+ghosts" : "|all"));
    scene_ << "        const sphc::CellList& cells = cells_" << S << ";\n";
    const std::string lists = verlet() ? verletLists(phase, w, s) : "";
    // A pass in cluster-pair tiles searches its own layout (ClusterPairs.cpp): no cells.
    const bool tiles = symmetricPass(w, pass) && onceLanes(w, pass) &&
                       clusterTilesRefusal(w, pass).empty();
    listsRebuildCheck(lists, w, s, !tiles);
    // The loops kept for one region (oneRegion): here, before the pair loop; the tiles print
    // them after their destination-only values (ClusterPairs.cpp).
    if (!tiles) ompQueueFlush(scene_);
    if (symmetricPass(w, pass)) {
      emitSymmetricPass(w, pass, lists, openmp_,
                        tuned() ? "verlet_radius2" : "VERLET_RADIUS2");  // codegen/SymmetricPairs.cpp
      if (!ompQueue_.empty()) throw std::logic_error("codegen: per-particle loops kept past a pair loop");
      scene_ << "      }\n";
      continue;
    }
    scene_ << "        nbrs_lists.resize(std::max<std::size_t>(nbrs_lists.size(), "
           << (openmp_ ? "omp_get_max_threads()" : "1") << "));\n";
    // Each thread works on its own copies of the array pointers and scalars
    // (default(firstprivate)): shared, the outlined loop reads them through the
    // captured frame at every neighbour, ~4% slower than the serial build (dam break,
    // ~100k particles, 1 thread). The cell list stays shared: a copy would be a waste.
    // --mpi: the pass counts its work, candidates and neighbour pairs x loops over them,
    // for the weights of the decomposition (sphc/mpi/decomposition.h, count_work).
    const size_t loops = pass.equations.size() + pass.loopAll.size();
    if (mpi_) {
      scene_ << "        long n_pairs = 0, n_candidates = 0;  // this pass's work (--mpi)\n";
      scene_ << "        long* const pass_work = sphc::mpi::pass_work(decomposition, " << d << ", "
             << D << ".n, " << rangeEnd(w) << ");  // per particle\n";
      scene_ << "        const long candidate_cost = decomposition.candidate_cost;\n";
      scene_ << "        const long pair_cost = " << loops << " * decomposition.pair_cost;\n";
    }
    // The kept list walked once with the support's test inline (as the each-pair-once loops,
    // SymmetricPairs.cpp): XIJ and R2IJ once per candidate, no filtered list. Where nothing
    // needs that list (no loop_all, not in SIMD lanes, not --mpi's counts); the same
    // candidates in the same order, the same test and arithmetic: the same bits.
    // --filtered-lists prints the filtered list and the loop over it.
    const bool inlineTest = verlet() && !mpi_ && !filteredLists_ && pass.loopAll.empty() &&
                            !pass.equations.empty() &&
                            (!simdPairs_ || !simdPairsRefusal(w, pass).empty());
    // Pairs of two arrays (fluid <- wall): most destinations have no candidate; after a
    // build only those with one are visited (occupiedRefusal).
    const bool occupied = inlineTest && occupiedRefusal(w, pass).empty();
    const std::string pragma =
        parallelFor("        ", pass.order,
                    std::string("default(firstprivate) shared(cells)") +
                        (mpi_ ? " reduction(+ : n_pairs, n_candidates)" : ""));
    if (occupied) {
      emitOccupiedHead(lists, rangeBegin(w), rangeEnd(w), pragma);
    } else {
      scene_ << pragma;
      scene_ << "        for (int d_idx = " << rangeBegin(w) << "; d_idx < " << rangeEnd(w)
             << "; ++d_idx) {\n";
    }
    emitDestLocals(scene_, "          ", q, host_);
    emitDestinationHoisted(scene_, pass, "          ");  // codegen/Hoist.cpp
    // The neighbour list first (in candidate order; CellList::gather_neighbours), then every
    // loop_all with it, then the loops over the same neighbours.
    scene_ << "          std::vector<std::uint32_t>& nbrs_list = nbrs_lists["
           << (openmp_ ? "omp_get_thread_num()" : "0") << "];\n";
    if (mpi_) scene_ << "          long candidates = 0;\n";
    // The kept list of d_idx, built first if due (in the thread's scratch list, within the
    // list's radius, kept in increasing index at its exact size).
    auto emitKeptList = [&] {
      scene_ << "          std::vector<std::uint32_t>& kept = " << lists << ".lists[d_idx];\n";
      scene_ << "          if (verlet_build) {\n";
      scene_ << "            const std::size_t n_kept = cells.gather_neighbours(xi, yi, zi, "
                "nbrs_list, [&](std::uint32_t j) {\n";
      scene_ << "              const int s_idx = static_cast<int>(j);\n";
      emitNeighbourTest(scene_, host_, "return false;", "              ",
                        tuned() ? "verlet_radius2" : "VERLET_RADIUS2");
      scene_ << "              return true;\n            });\n";
      scene_ << "            sphc::keep_in_index_order(kept, nbrs_list.data(), n_kept);\n";
      scene_ << "          }\n";
    };
    if (inlineTest) {
      emitKeptList();
      const RegisterSums sums = registerSums(w, pass);  // codegen/RegisterSums.cpp
      emitSumsLoad(scene_, "          ", sums);
      if (simdPairs_ && !simdAuto_)  // as emitSimdNeighbours says it (auto: --report does)
        scene_ << "          // Not in SIMD lanes (codegen/SimdPairs.cpp): " << simdPairsRefusal(w, pass)
               << ".\n";
      scene_ << "          for (const std::uint32_t* k = kept.data(), *const k_end = k + kept.size(); "
                "k != k_end; ++k) {  // the support's test inline\n";
      scene_ << "            const int s_idx = static_cast<int>(*k);\n";
      emitCandidate(scene_, q, pass.equations, d, host_, /*test=*/true, &sums, "continue;");
      scene_ << "          }\n";
      emitSumsStore(scene_, "          ", sums);
      scene_ << "        }\n";
      if (occupied)
        scene_ << "        if (occ_all) sphc::find_occupied(" << lists
               << ");  // the destinations with a candidate, for the next evaluations\n";
      scene_ << "      }\n";
      continue;
    }
    if (verlet()) {
      // The kept list of d_idx (built first if due, in the thread's scratch list, kept in
      // increasing index at its exact size), filtered with the support's test.
      emitKeptList();
      scene_ << "          const int n_nbrs = static_cast<int>(sphc::filter_neighbours(kept.data(), "
                "kept.size(), nbrs_list, [&](std::uint32_t j) {\n";
    } else {
      scene_ << "          const int n_nbrs = static_cast<int>(cells.gather_neighbours(xi, yi, zi, "
                "nbrs_list, [&](std::uint32_t j) {\n";
    }
    if (mpi_) scene_ << "            ++candidates;\n";
    scene_ << "            const int s_idx = static_cast<int>(j);\n";
    emitNeighbourTest(scene_, host_, "return false;", "            ");
    scene_ << "            return true;\n          }));\n";
    scene_ << "          const std::uint32_t* NBRS = nbrs_list.data();\n";
    if (mpi_)
      scene_ << "          n_pairs += n_nbrs;\n"
                "          n_candidates += candidates;\n"
                "          pass_work[d_idx] += candidate_cost * candidates + pair_cost * n_nbrs;\n";
    if (!pass.loopAll.empty()) {
      scene_ << "          {\n";
      scene_ << "            const int N_NBRS = n_nbrs;\n";
      for (const auto* eq : pass.loopAll)
        scene_ << "            " << equationCall(*eq, ast::Method::LoopAll, d);
      scene_ << "          }\n";
    }
    if (!pass.equations.empty()) {
      const RegisterSums sums = registerSums(w, pass);  // codegen/RegisterSums.cpp
      emitSumsLoad(scene_, "          ", sums);
      if (!emitSimdNeighbours(scene_, w, pass, sums)) {  // codegen/SimdPairs.cpp (--simd-pairs)
        scene_ << "          for (int k_nbr = 0; k_nbr < n_nbrs; ++k_nbr) {\n";
        scene_ << "            const int s_idx = static_cast<int>(NBRS[k_nbr]);\n";
        emitCandidate(scene_, q, pass.equations, d, host_, /*test=*/false, &sums);
        scene_ << "          }\n";
      }
      emitSumsStore(scene_, "          ", sums);
    }
    scene_ << "        }\n";
    if (mpi_)
      scene_ << "        sphc::mpi::count_work(decomposition, " << d << ", n_pairs * " << loops
             << ", n_candidates);  // " << loops << " loop(s) over the pairs\n";
    scene_ << "      }\n";
  }
  initInAddBack_ = nullptr;
  endUniformH();
  // OpenMP (stop 46; --no-omp-regions): the post_loop and the max and min reductions after
  // it in one parallel region (OmpRegions.cpp), each reduction's value in a local of its own
  // (acc_K), the reductions `omp for reduction(...) nowait`: complete at the region's end.
  std::vector<const Reduction*> joined;
  if (openmp_ && ompRegions_on_ && !mpi_ && !w.onGhosts && !w.ranged())
    for (const Reduction& r : w.reductions) {
      const std::string& op = plan_.equationDecls[r.equation->declIndex].reduceOp;
      if (r.combine != LoopOrder::Parallel || (op != "max" && op != "min")) break;
      joined.push_back(&r);
    }
  if (joined.size() < 2 && (joined.empty() || w.postLoop.empty())) joined.clear();
  if (!joined.empty()) {
    std::set<std::string> postWrites;  // a reduction reading one: a barrier before it
    for (const PlanEquation* eq : w.postLoop)
      for (const PropAccess& x : methodBody(*eq, ast::Method::PostLoop).facts.dWrites)
        postWrites.insert(x.prop);
    scene_ << "      {  // the post_loop and the reductions after it in one parallel region\n";
    for (size_t k = 0; k < joined.size(); ++k) {
      const PlanEquation* eq = joined[k]->equation;
      const auto& pd = plan_.equationDecls[eq->declIndex];
      scene_ << "        " << real_ << " acc_" << k << " = "
             << (pd.reduceOp == "max" ? "-HUGE_VAL" : "HUGE_VAL") << ";  // reduce "
             << pd.reduceOp << " into " << D << "." << pd.reduceTarget << ": " << eq->name
             << ", from " << loc(eq->loc) << "\n";
    }
    ompQueueOpen(openmp_, "        ");
    perParticle(ast::Method::PostLoop, "post_loop");
    for (size_t k = 0; k < joined.size(); ++k) {
      const PlanEquation* eq = joined[k]->equation;
      const auto& pd = plan_.equationDecls[eq->declIndex];
      const PlanBody& b = plan_.bodies[pd.methods.at(ast::Method::Reduce)];
      const std::string acc = "acc_" + std::to_string(k);
      bool reads = false;
      for (const PropAccess& x : b.facts.dReads) reads = reads || postWrites.count(x.prop);
      const std::string loop =
          "        for (int d_idx = 0; d_idx < n; ++d_idx) {\n          const " + real_ + " v = " +
          callBody(bodyFunctionName(eq->name, "reduce"), b, d, eqStruct(*eq), "t") +
          ";\n          " + acc + " = v " + (pd.reduceOp == "max" ? ">" : "<") + " " + acc +
          " ? v : " + acc + ";\n        }\n";
      ompLoop(scene_,
              parallelFor("        ", LoopOrder::Parallel,
                          withIf("reduction(" + pd.reduceOp + " : " + acc + ")", ompIf("n"))),
              loop, reads ? D + "|reduce" + std::to_string(k) : ompSpace(w));
    }
    ompQueueFlush(scene_);
    for (size_t k = 0; k < joined.size(); ++k) {
      const auto& pd = plan_.equationDecls[joined[k]->equation->declIndex];
      scene_ << "        " << propPtr(d, pd.reduceTarget) << "[0] = acc_" << k << ";\n";
    }
    scene_ << "      }\n";
    for (size_t k = joined.size(); k < w.reductions.size(); ++k) reduction(w, w.reductions[k]);
  } else {
    perParticle(ast::Method::PostLoop, "post_loop");
    // Reductions over the destination array into its constants.
    for (const Reduction& r : w.reductions) reduction(w, r);
  }
  emitHostReduces(w);
  ghostRefresh(w);
}

void CpuPrinter::listsRebuildCheck(const std::string& lists, const DestinationWork& w, int s,
                                   bool cells) {
  const int d = w.array;
  const std::string& D = arr(d).name;
  const std::string& S = arr(s).name;
  if (tuned()) {
    tunedRebuildCheck(lists, w, d, s);
  } else if (verlet()) {
    // Rebuilt when particles of either array moved too far since the lists' last build
    // (by this loop or another one sharing them). A static array (isStatic: never moves, h
    // constant) is left out of the check and of the positions kept, as with
    // --verlet-skin=tuned (CpuVerletTune.cpp's rebuildCheck); with neither array moving the
    // lists are built once.
    std::string arrays;
    for (int a : movingArrays(d, s)) arrays += (arrays.empty() ? "{&" : ", &") + positions(a);
    const std::string range = rangeBegin(w) + ", " + rangeEnd(w);
    const std::string phase = phaseDisplacements_ ? ", &phase_moved" : "";
    if (arrays.empty()) {
      scene_ << "        // Neither array moves: the lists are built once.\n";
      scene_ << "        const bool verlet_build = !" << lists << ".built_for(" << range << ");\n";
    } else {
      arrays += "}";
      if (arrays != (d == s ? "{&" + positions(d) + "}"
                            : "{&" + positions(d) + ", &" + positions(s) + "}"))
        scene_ << "        // Checked over the array that moves (the other is static).\n";
      scene_ << "        const bool verlet_build = !" << lists << ".built_for(" << range << ") || "
             << lists << ".skin.must_rebuild(" << arrays << ", Kernel::radius_scale" << phase
             << ");\n";
    }
    scene_ << "        if (verlet_build) {\n";
    if (!arrays.empty())
      scene_ << "          " << lists << ".skin.mark(" << arrays << phase << ");\n";
    scene_ << "          " << lists << ".begin = " << rangeBegin(w) << ";\n";
    scene_ << "          " << lists << ".end = " << rangeEnd(w) << ";\n";
    scene_ << "          " << lists << ".lists.resize(" << D << ".n);\n";
    if (d == s && symmetric_ && (!hasDomain() || !cpuSingle_)) scene_ << "          " << lists << ".upper.clear();  // found again by the loops over each pair once\n";
    if (crossSourceLists().count(lists))
      scene_ << "          " << lists << "_by_source.clear();  // found again by the pass over pairs of two arrays once\n";
    if (d != s && skipEmptyLists_)
      scene_ << "          " << lists << ".occupied_found = false;  // found again by the loops over two arrays\n";
    scene_ << "        }\n";
  }
  if (lazyCells() && !isStatic(S) && cells)  // CpuLazyCells.cpp
    scene_ << "        if (verlet_build) build_cells_" << S << "();  // the cells of this update, once\n";
  else if (lazyCells() && !isStatic(S))  // (stop 41: they cost ~1 ms per rebuild at 100k)
    scene_ << "        // (no cells: the tiles search their own layout's columns)\n";
}

std::pair<const DestinationWork*, const DestinationWork*> CpuPrinter::crossPair(
    const DestinationWork& w) const {
  if (!symmetric_ || !verlet() || hasDomain()) return {};
  std::pair<const DestinationWork*, const DestinationWork*> found{};
  walkPhases(sched_.equations, [&](const Phase& ph) {
    for (size_t a = 0; a + 1 < ph.destinations.size(); ++a) {
      const DestinationWork& A = ph.destinations[a];
      const DestinationWork& B = ph.destinations[a + 1];
      if ((&w == &A || &w == &B) && A.array != B.array && !A.passes.empty() &&
          !B.passes.empty() && A.passes.back().source == B.array &&
          B.passes.front().source == A.array && A.passes.back().searches() &&
          B.passes.front().searches() && crossPairsRefusal(plan_, ph, a, a + 1, true).empty() &&
          !simdPairsRefusal(A, A.passes.back()).empty() &&  // --simd-pairs: per destination,
          !simdPairsRefusal(B, B.passes.front()).empty())   // as the OpenMP backend's
        found = {&A, &B};
    }
  });
  return found;
}

std::string CpuPrinter::clusterTilesFormRefusal(const DestinationWork& w,
                                                const NeighbourPass& pass) const {
  std::string why = ScenePrinter::clusterTilesFormRefusal(w, pass);
  if (!why.empty()) return why;
  if (tuned()) return "--verlet-skin=auto (the tiles take the fixed skin's radius)";
  if (!verlet()) return "no kept lists";
  // The tiles build no kept lists: a pass sharing them must be in tiles too (stop 40: the
  // passes in tiles share the layout and the cluster-pair lists, each its slot buffer), in
  // a phase of its own.
  std::vector<std::string> phases;
  const auto users = listUsers(w, pass, &phases);
  if (users.size() < 2 || sharedListsCheck_) return "";
  std::string refusal;
  sharedListsCheck_ = true;
  for (size_t u = 0; u < users.size() && refusal.empty(); ++u) {
    if (std::count(phases.begin(), phases.end(), phases[u]) > 1)
      refusal = "its kept lists are shared with another pass of " + phases[u];
    else if (users[u].second != &pass) {
      const std::string why = clusterTilesRefusal(*users[u].first, *users[u].second);
      if (!why.empty())
        refusal = "its kept lists are shared with a pass not in tiles (" + phases[u] + ": " + why + ")";
    }
  }
  sharedListsCheck_ = false;
  return refusal;
}

std::vector<std::pair<const DestinationWork*, const NeighbourPass*>> CpuPrinter::listUsers(
    const DestinationWork& w, const NeighbourPass& pass, std::vector<std::string>* phases) const {
  std::string phase;
  walkPasses(sched_.equations, [&](const Phase& ph, const DestinationWork& x, const NeighbourPass&) {
    if (&x == &w) phase = ph.name;
  });
  const std::string lists = verletLists(phase, w, pass.source);
  std::vector<std::pair<const DestinationWork*, const NeighbourPass*>> users;
  walkPasses(sched_.equations, [&](const Phase& ph, const DestinationWork& x,
                                   const NeighbourPass& p) {
    if (p.searches() && verletLists(ph.name, x, p.source) == lists) {
      users.push_back({&x, &p});
      if (phases) phases->push_back(ph.name);
    }
  });
  return users;
}

std::pair<int, int> CpuPrinter::clusterListsShare(const DestinationWork& w,
                                                  const NeighbourPass& pass) const {
  const auto users = listUsers(w, pass);
  for (size_t u = 0; u < users.size(); ++u)
    if (users[u].second == &pass) return {static_cast<int>(u), static_cast<int>(users.size())};
  return {0, 1};
}

// Whether the pass over w's own array is printed each pair once (SymmetricPairs.cpp): not in
// SIMD lanes per destination (--simd-pairs; under --simd-pairs=once each pair once in the
// lanes, SimdPairs.cpp). With periodic or mirror ghosts (kept with the lists: verlet()) in
// the scalar loops of double precision only, the pairs with a ghost per destination
// (emitSymmetricPass).
bool CpuPrinter::symmetricPass(const DestinationWork& w, const NeighbourPass& pass) const {
  if (!symmetric_ || !symmetricPairsRefusal(plan_, w, pass, verlet()).empty()) return false;
  if (hasDomain()) return !cpuSingle_ && !simdPairsRefusal(w, pass).empty() && !onceLanes(w, pass);
  return !simdPairsRefusal(w, pass).empty() || onceLanes(w, pass);
}

// The bodies the each-pair-once loops call both ways (the conditions of the printing above):
// those of a pass over its own array, and those of one declaration on both sides of a cross
// pass.
std::set<const PlanBody*> CpuPrinter::pairSharedBodies() const {
  std::set<const PlanBody*> bodies;
  walkPasses(sched_.equations, [&](const Phase&, const DestinationWork& w, const NeighbourPass& pass) {
    if (symmetricPass(w, pass))
      for (const PlanEquation* eq : pass.equations) bodies.insert(&methodBody(*eq, ast::Method::Loop));
    const auto [A, B] = crossPair(w);
    if (A && &w == A)
      for (const PlanEquation* eq : A->passes.back().equations)
        for (const PlanEquation* m : B->passes.front().equations)
          if (m->declIndex == eq->declIndex) bodies.insert(&methodBody(*eq, ast::Method::Loop));
  });
  return bodies;
}

// A reduction of the destination's real particles into one of its constants.
void CpuPrinter::reduction(const DestinationWork& w, const Reduction& r) {
  const int d = w.array;
  const std::string& D = arr(d).name;
  const bool onGhosts = w.onGhosts;
  const PlanEquation* eq = r.equation;
  const auto& pd = plan_.equationDecls[eq->declIndex];
  const PlanBody& b = plan_.bodies[pd.methods.at(ast::Method::Reduce)];
  // mean: the sum, divided by the number of particles (0 for an empty array).
  const bool sum = pd.reduceOp == "sum" || pd.reduceOp == "mean";
  std::string init = sum ? "0.0"
                     : pd.reduceOp == "max" ? "-HUGE_VAL"
                                            : "HUGE_VAL";
  std::string combine = sum ? "acc += v"
                         : pd.reduceOp == "max" ? "acc = v > acc ? v : acc"
                                                : "acc = v < acc ? v : acc";
  scene_ << "      {  // reduce " << pd.reduceOp << " into " << D << "." << pd.reduceTarget
         << ": " << eq->name << ", from " << loc(eq->loc) << "\n";
  scene_ << "        " << real_ << " acc = " << init << ";\n";
  // Reductions see the real particles only (never the ghosts of a non-real group).
  const std::string nReal =
      onGhosts ? "static_cast<int>(" + D + ".n)" : std::string("n");
  const std::string value =
      callBody(bodyFunctionName(eq->name, "reduce"), b, d, eqStruct(*eq), "t");
  if (openmp_ && r.combine == LoopOrder::Serial) {
    // A sum in the serial order, so that the result (and an iteration count that a
    // convergence test derives from it) is bitwise the serial one: the values in
    // parallel, the sum on one thread (n additions, cheap next to a neighbour pass).
    const std::string loopHead = "        for (int d_idx = 0; d_idx < " + nReal +
                                 "; ++d_idx)" +
                                 (onGhosts ? "  // real particles only" : "") + "\n";
    scene_ << "        std::vector<" << real_ << ">& values = reduce_scratch;\n";
    scene_ << "        values.resize(" << nReal << ");\n";
    scene_ << parallelFor("        ", LoopOrder::Parallel, ompIf(nReal));
    scene_ << loopHead;
    scene_ << "          values[d_idx] = " << value << ";\n";
    scene_ << loopHead << "          acc += values[d_idx];\n";
    if (pd.reduceOp == "mean" && !mpi_)
      scene_ << "        acc = " << nReal << " > 0 ? acc / " << nReal << " : 0.0;\n";
  } else {
    scene_ << parallelFor("        ", LoopOrder::Parallel,
                          withIf(std::string("reduction(") + (sum ? "+" : pd.reduceOp) + " : acc)",
                                 ompIf(nReal)));
    scene_ << "        for (int d_idx = 0; d_idx < " << nReal << "; ++d_idx) {"
           << (onGhosts ? "  // real particles only" : "") << "\n";
    scene_ << "          const " << real_ << " v = " << value << ";\n          " << combine
           << ";\n        }\n";
    if (pd.reduceOp == "mean" && !mpi_)
      scene_ << "        acc = " << nReal << " > 0 ? acc / " << nReal << " : 0.0;\n";
  }
  if (mpi_) scene_ << globalReduction(pd.reduceOp, nReal);  // every rank's particles
  scene_ << "        " << propPtr(d, pd.reduceTarget) << "[0] = acc;\n      }\n";
}

// Ghosts copy the values a phase computed on the real particles, where they carry them.
void CpuPrinter::ghostRefresh(const DestinationWork& w) {
  if (!ghostsFollow(w)) return;
  const int d = w.array;
  const std::string& D = arr(d).name;
  const std::vector<std::string>& refresh = w.ghostRefresh;
  scene_ << (mpi_ ? "\n      sphc::mpi::refresh_halo(box, " : "\n      sphc::refresh_ghosts(box, ")
         << hostData(d) << ", ghosts_" << D << ", "
           << propIndexList(d, refresh) << ");\n";
}

// --omp-min-particles: the `if` clause of a stepper run's parallel region, on the particles
// of all its arrays (" if (...)", or "").
std::string CpuPrinter::stepperIf(const StepperRun& run) const {
  std::string count;
  for (const StepperRun::Part& part : run.parts)
    count += (count.empty() ? "" : " + ") + arr(part.array).name + ".n";
  const std::string cond = ompIf("static_cast<long>(" + count + ")");
  return cond.empty() ? "" : " " + cond;
}

// Steppers are per particle (a body reads and writes its own particle d_idx only, as the
// parallel loops of the OpenMP backend already require), so running the methods of a run
// one after the other on each particle, in one pass, gives what running each method on all
// particles in turn gives, bit for bit, with less memory traffic (PECIntegrator's
// initialize and stage1 both read and write x, u, rho, ...). The arrays' passes share one
// parallel region (`omp for nowait`: each array's particles are its own).
void CpuPrinter::steppers() {
  for (const StepperRun& run : sched_.stepperRuns) {
    if (run.parts.empty()) continue;
    const bool parallel = openmp_ && run.order == LoopOrder::Parallel;
    scene_ << "  void " << run.name << "(";
    for (size_t k = 0; k < run.methods.size(); ++k) scene_ << "double t_" << k << ", ";
    scene_ << "double dt) {\n";
    // A statement's time is unused when no array's stepper has its method.
    std::string unused;
    for (size_t k = 0; k < run.methods.size(); ++k) {
      bool used = false;
      for (const auto& part : run.parts)
        for (const auto& [j, b] : part.bodies) used |= j == k;
      if (!used) unused += " (void)t_" + std::to_string(k) + ";";
    }
    if (!unused.empty()) scene_ << "   " << unused << "\n";
    if (parallel) scene_ << "    #pragma omp parallel" << stepperIf(run) << "\n";
    scene_ << "    {\n";
    for (const StepperRun::Part& part : run.parts) {
      const PlanArray& A = arr(part.array);
      scene_ << "      {  // " << A.name << ": " << part.stepper->decl->name.name;
      for (size_t i = 0; i < part.bodies.size(); ++i)
        scene_ << (i ? ", " : ".") << run.methods[part.bodies[i].first];
      scene_ << "\n        const int n = static_cast<int>(" << A.name << ".n);\n";
      for (const auto& p : part.destProps)
        scene_ << "        " << hostType(part.array, p) << "* d_" << p << " = "
               << propPtr(part.array, p) << ";\n";
      if (parallel) scene_ << "        #pragma omp for schedule(static) nowait\n";
      scene_ << "        for (int d_idx = 0; d_idx < n; ++d_idx) {\n";
      for (const auto& [k, b] : part.bodies) {
        scene_ << "          "
               << callBody(bodyFunctionName(part.stepper->decl->name.name, run.methods[k]), *b,
                           part.array, "", "t_" + std::to_string(k))
               << ";\n";
      }
      scene_ << "        }\n      }\n";
    }
    scene_ << "    }\n  }\n\n";
  }
}

void CpuPrinter::searchDomain(const std::string& only, const std::string& dom) {
  if (cpuSingle_ && verlet()) {
    // Kept lists: cells as large as the lists' radius, as in double below (the static
    // sources' grids and order_domain: the support's).
    scene_ << "    " << floatDomain(only, dom,
                                    only.empty() ? std::string("Kernel::radius_scale * (1.0 + ") +
                                                       (tuned() ? "verlet_skin" : "VERLET_SKIN") + ")"
                                                 : "Kernel::radius_scale");
    return;
  }
  if (cpuSingle_) {
    scene_ << "    " << floatDomain(only, dom, "Kernel::radius_scale");
    return;
  }
  // The search domain spans every array that takes part in a neighbour loop.
  if (!only.empty()) {
    scene_ << "    " << dom << " = sphc::make_search_domain({&" << only
           << "}, DIM, Kernel::radius_scale);\n";
    return;
  }
  scene_ << loopArraysDecl();
  if (verlet()) {
    // Cells as large as the lists' radius (each pair loop rebuilds its lists when due).
    scene_ << "    domain = sphc::make_search_domain(all, DIM, Kernel::radius_scale * (1.0 + "
           << (tuned() ? "verlet_skin" : "VERLET_SKIN") << "));\n";
    return;
  }
  scene_ << "    domain = sphc::make_search_domain(all, DIM, Kernel::radius_scale);\n";
}

std::string CpuPrinter::floatDomain(const std::string& only, const std::string& dom,
                                    const std::string& radius) const {
  auto spans = [&](const std::string& a) {
    return only.empty() ? loopArrays_.count(a) != 0 : a == only;
  };
  // The search domain spans every array that takes part in a neighbour loop (float data).
  const char* axes[3] = {"x", "y", "z"};
  std::string r = dom + " = sphc::make_search_domain_float({";
  bool first = true;
  for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a) {
    if (!spans(arr(a).name)) continue;
    r += std::string(first ? "" : ",\n                                             ") + "{";
    for (int k = 0; k < 3; ++k)
      r += (k < plan_.dim ? propPtr(a, axes[k]) : std::string("nullptr")) + ", ";
    r += propPtr(a, "h") + ", " + arr(a).name + ".n}";
    first = false;
  }
  return r + "}, DIM, " + radius + ");\n";
}

std::string CpuPrinter::orderDomain() const {
  if (cpuSingle_) {
    std::string r = floatDomain("", "order_domain", "Kernel::radius_scale");
    return r.substr(0, r.size() - 1);  // one statement, without its newline
  }
  return "order_domain = sphc::make_search_domain(all, DIM, Kernel::radius_scale);";
}

std::string CpuPrinter::cellListBuild(const std::string& S, const std::string& count,
                                      const std::string& dom) const {
  return cellListBuildCall(S, count, dom,
                           [&](int a, const std::string& axis) { return propPtr(a, axis); });
}

// update_neighbours of a scene with a periodic or mirror domain: the search domain of the
// real particles, the cell-order permutation (of real particles), then the ghosts of every
// source array, and the cell lists over real particles and ghosts.
void CpuPrinter::updateNeighboursWithGhosts() {
  if (verlet()) return updateNeighboursKeptGhosts();
  if (mpi_) emitMigration();  // --mpi: particles that left this rank's region go first
  searchDomain();
  if (sourceArrays_.empty()) return;
  scene_ << "    // Every REORDER_EVERY builds the real particles are sorted in cell order.\n";
  scene_ << "    if (builds++ % REORDER_EVERY == 0) {\n";
  for (const auto& S : sourceArrays_)
    if (reorders(S))
      scene_ << "      " << cellListBuild(S, S + ".n") << "\n      " << permuteInCellOrder(S)
             << "\n";
  scene_ << "    }\n";
  if (mpi_) {
    emitHaloExchange();  // --mpi: remote particles and images replace the ghosts
  } else {
    scene_ << "    // Ghosts within the largest interaction radius of a periodic or mirror side.\n";
    scene_ << "    const double cutoff = domain.cell_size;\n";
    addGhosts("    ");
    scene_ << "    sphc::extend_for_ghosts(domain, box, cutoff);\n";
  }
  for (const auto& S : sourceArrays_)
    scene_ << "    " << cellListBuild(S, S + ".n + ghosts_" + S + ".size()") << "\n";
}

void CpuPrinter::addGhosts(const std::string& indent) {
  for (const auto& S : sourceArrays_) {
    int s = plan_.arrayIndex(S);
    scene_ << indent << "sphc::add_ghosts(box, " << hostData(s) << ", cutoff, ghosts_" << S
           << ", " << propIndexList(s, arr(s).ghostProps) << ");  //";
    for (const auto& p : arr(s).ghostProps) scene_ << " " << p;
    scene_ << "\n";
  }
}

std::string CpuPrinter::removeGhosts() const {
  std::string r;
  if (verlet()) {  // the ghosts are kept for the next evaluation (updateNeighboursKeptGhosts)
    for (const auto& S : sourceArrays_)
      r += "    sphc::hide_ghosts(" + hostData(plan_.arrayIndex(S)) + ");\n";
    return r;
  }
  for (const auto& S : sourceArrays_)
    r += std::string(mpi_ ? "    sphc::mpi::remove_halo(" : "    sphc::remove_ghosts(") + hostData(plan_.arrayIndex(S)) + ", ghosts_" + S + ");\n";
  return r;
}

// update_neighbours of a scene with a periodic or mirror domain and kept lists
// (docs/performance-log.md, "Neighbour lists with periodic and mirror sides"). The ghosts are found
// (within the lists' radius and the wrap margin of a side) only when the lists must be built
// again: when ghost_skin finds that some particle moved too far since (the kept lists' own
// test, over every array of a pair loop), and at a permutation, before which the particles are
// wrapped into the box. Otherwise the same ghosts, in the same order, are made again from
// their originals, so the kept lists' indices still name the same particles and images.
// Between two finds a real particle is at most WRAP_MARGIN supports outside a periodic box
// (update_domain) and has moved less than the skin allows: every image within the support of
// a particle now was within the lists' radius plus the margin of a side at the find.
void CpuPrinter::updateNeighboursKeptGhosts() {
  searchDomain();
  if (sourceArrays_.empty()) return;
  scene_ << "    const bool reorder = builds++ % REORDER_EVERY == 0;\n";
  // The arrays of the pair loops: `all` (searchDomain), or in single precision their float
  // copies, whose positions the scene computes on.
  std::string all = "all";
  if (cpuSingle_) {
    all.clear();
    for (const auto& a : plan_.arrays)
      if (loopArrays_.count(a.name)) all += (all.empty() ? "{&f32_" : ", &f32_") + a.name;
    all += "}";
  }
  scene_ << "    const bool new_ghosts = reorder || ghost_skin.must_rebuild(" << all << ", "
            "Kernel::radius_scale);\n";
  scene_ << "    if (reorder) {\n";
  scene_ << "      // Every REORDER_EVERY builds the real particles are wrapped into the box and sorted\n"
            "      // in the cell order of the support's grid (as without lists).\n";
  scene_ << "      wrap_into_box();\n";
  scene_ << "      " << orderDomain() << "\n";
  for (const auto& S : sourceArrays_)
    if (reorders(S))
      scene_ << "      " << cellListBuild(S, S + ".n", "order_domain") << "\n      "
             << permuteInCellOrder(S) << "\n";
  scene_ << "    }\n";
  scene_ << "    // Ghosts within the lists' radius plus WRAP_MARGIN supports of a periodic or mirror side.\n";
  scene_ << "    const double cutoff = domain.cell_size * (1.0 + VERLET_SKIN + WRAP_MARGIN) / "
            "(1.0 + VERLET_SKIN);\n";
  scene_ << "    sphc::check_ghost_span(box, cutoff, \"the neighbour lists kept across steps "
            "need (1 + VERLET_SKIN + WRAP_MARGIN) supports along a periodic or mirrored axis; "
            "a solver built with sphc --verlet-skin=off needs one support\");\n";
  scene_ << "    if (new_ghosts) {\n";
  addGhosts("      ");
  scene_ << "      ghost_skin.mark(" << all << ");\n";
  forEachVerletLists([&](const std::string& lists, const Phase&, const DestinationWork&,
                         const NeighbourPass&) {
    scene_ << "      " << lists << ".end = -1;  // not built: the ghosts were renumbered\n";
  });
  scene_ << "    } else {  // the same ghosts, from their originals now\n";
  for (const auto& S : sourceArrays_) {
    int s = plan_.arrayIndex(S);
    scene_ << "      sphc::restore_ghosts(box, " << hostData(s) << ", ghosts_" << S << ", "
           << propIndexList(s, arr(s).ghostProps) << ");\n";
  }
  scene_ << "    }\n";
  scene_ << "    sphc::extend_for_ghosts(domain, box, cutoff);\n";
  for (const auto& S : sourceArrays_)
    scene_ << "    " << cellListBuild(S, S + ".n + ghosts_" + S + ".size()") << "\n";
}

// The tiled pass over S's own particles kept in slot order (stop 40), if any: its lists'
// name, "" if none.
std::string CpuPrinter::slotOrderLists(const std::string& S) const {
  std::string found;
  forEachVerletLists([&](const std::string& lists, const Phase&, const DestinationWork& w,
                         const NeighbourPass& pass) {
    if (found.empty() && arr(w.array).name == S && clusterTilesRefusal(w, pass).empty() &&
        clusterSlotOrder(w, pass))
      found = lists;
  });
  return found;
}

void CpuPrinter::emitSlotOrder(const std::string& S) {
  const std::string state = slotOrderLists(S);
  std::vector<std::string> forget;
  const DestinationWork* tiled = nullptr;
  forEachVerletLists([&](const std::string& lists, const Phase&, const DestinationWork& w,
                         const NeighbourPass& pass) {
    if (arr(w.array).name == S || arr(pass.source).name == S) forget.push_back(lists);
    if (lists == state) tiled = &w;
  });
  emitClusterSlotOrder(*tiled, state, forget, "    ");
}

bool CpuPrinter::isStatic(const std::string& S) const {
  if (hasDomain() || mpi_ || hasZones()) return false;  // ghosts, halos, inlets and outlets
  auto written = [&](int a, const char* p) {
    const PlanProperty* q = arr(a).find(p);
    return q && q->written;
  };
  const int s = plan_.arrayIndex(S);
  for (const char* p : {"x", "y", "z"})
    if (written(s, p)) return false;
  for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a)
    if (loopArrays_.count(arr(a).name) && written(a, "h")) return false;
  return true;
}

// build_static_cells: each static source on a grid of its own box (padded) with the scene's
// cell size, which h fixes: the cell list is built once, after the particles went into cell
// order, and never again. A point outside the box lands in its nearest border cell, whose
// stencil still holds every neighbour (sphc/nnps.h), so the moving arrays may go anywhere.
void CpuPrinter::emitStaticCells() {
  scene_ << "  // Sources nothing moves (no stepper or equation writes their positions or h; no\n"
            "  // periodic images, halo or zones): their cell lists are built once, on a grid of\n"
            "  // their own box with the scene's cell size, and kept. The first update_neighbours\n"
            "  // calls it.\n";
  scene_ << "  void build_static_cells() {\n";
  for (const auto& S : sourceArrays_) {
    if (!isStatic(S)) continue;
    searchDomain(S, "domain_" + S);
    const std::string build = cellListBuild(S, S + ".n", "domain_" + S);
    if (verlet() && reorders(S)) {
      // --verlet-skin: sorted into the cell order of the support's grid, as without lists
      // (the same particle order), then the lists' cells.
      scene_ << "    domain_" << S << ".cell_size = order_domain.cell_size;  // the cell order "
             << "as without lists\n";
      scene_ << "    " << build << "\n    " << permuteInCellOrder(S) << "\n";
      if (tuned())
        scene_ << "    domain_" << S << ".cell_size = order_domain.cell_size * (1.0 + "
               << "sphc::SkinTuner::kMax);  // every candidate of the lists one cell away, "
               << "whatever skin is chosen\n";
      else
        scene_ << "    domain_" << S << ".cell_size = domain.cell_size;  // every candidate of the "
               << "lists one cell away\n";
      scene_ << "    " << build << "\n";
      continue;
    }
    scene_ << "    domain_" << S << ".cell_size = domain.cell_size;  // every neighbour one cell away\n";
    scene_ << "    " << build << "\n";
    if (reorders(S)) scene_ << "    " << permuteInCellOrder(S) << "\n    " << build << "\n";
  }
  scene_ << "    static_cells_built = true;\n  }\n\n";
}

// update_neighbours of a scene without periodic or mirror domain.
void CpuPrinter::updateNeighbours() {
  if (tuned()) return tunedUpdateNeighbours();  // CpuVerletTune.cpp
  bool reordersMoving = false;
  for (const auto& S : sourceArrays_) reordersMoving |= !isStatic(S) && reorders(S);
  if (lazyCells()) {  // `all` for order_domain; the domain: make_domain (CpuLazyCells.inc)
    if (!loopArrays_.empty() && (reordersMoving || anyStatic())) scene_ << loopArraysDecl();
  } else if (!loopArrays_.empty()) {
    searchDomain();
  }
  // --verlet-skin: permutations sort into the cell order of the support's grid (order_domain,
  // made as `domain` is without lists), so that the particles are in the order they have
  // without lists; the cell lists are then built on the lists' grid (`domain`).
  const std::string orderDomain = this->orderDomain();
  if (anyStatic()) {
    if (lazyCells())  // build_static_cells reads the lists' cell size
      scene_ << "    if (!static_cells_built) {  // once: they never move\n      make_domain();\n      "
             << orderDomain << "\n      build_static_cells();\n    }\n";
    else if (verlet())
      scene_ << "    if (!static_cells_built) {  // once: they never move\n      " << orderDomain
             << "\n      build_static_cells();\n    }\n";
    else
      scene_ << "    if (!static_cells_built) build_static_cells();  // once: they never move\n";
  }
  if (reordersMoving) {
    // Every REORDER_EVERY builds the particles are sorted in cell order, so that neighbours
    // are close in memory; all per-particle state moves with them.
    // (--verlet-skin: a permutation moves the particles under the kept lists, which are
    // then rebuilt.)
    scene_ << "    const bool reorder = builds++ % REORDER_EVERY == 0;\n";
    if (verlet()) scene_ << "    if (reorder) " << orderDomain << "\n";
  } else if (anyReorders()) {
    scene_ << "    ++builds;  // counted as with moving arrays (restart state)\n";
  }
  for (const auto& S : sourceArrays_) {
    if (isStatic(S)) continue;  // build_static_cells
    const std::string build = cellListBuild(S, S + ".n");
    if (slotOrdered(S)) {  // in its tiles' slot order, not in cell order (stop 40)
      emitSlotOrder(S);
      if (!lazyCells()) scene_ << "    " << build << "\n";
      continue;
    }
    if (lazyCells()) {
      if (reorders(S))
        scene_ << "    if (reorder) {\n      " << cellListBuild(S, S + ".n", "order_domain")
               << "\n      " << permuteInCellOrder(S) << "\n    }\n";
      continue;
    }
    if (verlet() && reorders(S)) {
      scene_ << "    if (reorder) {\n      " << cellListBuild(S, S + ".n", "order_domain")
             << "\n      " << permuteInCellOrder(S) << "\n    }\n";
      scene_ << "    " << build << "\n";
      continue;
    }
    scene_ << "    " << build << "\n";
    if (!reorders(S)) continue;  // a ranged group names its particles by index
    scene_ << "    if (reorder) {\n      " << permuteInCellOrder(S) << "\n      " << build
           << "\n    }\n";
  }
  if (lazyCells()) lazyCellsDue();
}

// The call of update_neighbours() in compute_accelerations, timed for --timing.
void CpuPrinter::timedNeighbourUpdate() {
  scene_ << "    const double nnps_t0 = sphc::wall_seconds();\n"
            "    update_neighbours();\n"
            "    nnps_seconds += sphc::wall_seconds() - nnps_t0;\n";
}


// A run of stepper statements: its fused function, with each statement's time.
void CpuPrinter::stepperCall(const StepStatement& st,
                             const std::function<std::string(int)>& timeAfter) {
  const StepperRun& run = sched_.stepperRuns[st.run];
  if (run.parts.empty()) return;
  std::string args;
  for (int d : st.stagesDone) args += timeAfter(d) + ", ";
  scene_ << "    " << run.name << "(" << args << "dt);\n";
}

// The adaptive time step's limits over one moving array: minima of a parallel loop. Where
// the array's h is one value for the whole run (analysis/UniformH.cpp; double precision), the
// minima of h / (c + |v|) and sqrt(h / |a|) are those of the largest c + |v| and |a|^2: for
// h > 0 and positive denominators, a correctly rounded division, and sqrt, are monotonic, so
// f(max) is min f bit for bit; the loop then takes one square root per particle, not three
// and two divisions (stop 46). A non-positive c + |v|, or an h that is not positive and
// finite, runs the per-particle loop (sphc --no-uniform-h: always).
void CpuPrinter::adaptiveDtArray(int a) {
  const AdaptiveDt& ad = sched_.adaptiveDt;
  const std::vector<std::string> vel = {"u", "v", "w"}, acc = {"au", "av", "aw"};
  const std::string& N = arr(a).name;
  scene_ << "      const " << real_ << "* h = " << propPtr(a, "h") << ";\n";
  if (ad.cfl) {
    scene_ << "      const " << real_ << "* cs = " << propPtr(a, "cs") << ";\n";
    for (int k = 0; k < plan_.dim; ++k)
      scene_ << "      const " << real_ << "* " << vel[k] << " = " << propPtr(a, vel[k]) << ";\n";
  }
  if (ad.force)
    for (int k = 0; k < plan_.dim; ++k)
      scene_ << "      const " << real_ << "* " << acc[k] << " = " << propPtr(a, acc[k]) << ";\n";
  // |v|^2 or |a|^2 of particle i: "u[i] * u[i] + v[i] * v[i]".
  auto squared = [&](const std::vector<std::string>& c) {
    std::string s;
    for (int k = 0; k < plan_.dim; ++k) s += (k ? " + " : "") + c[k] + "[i] * " + c[k] + "[i]";
    return s;
  };
  const std::string ompN = ompIf("static_cast<long>(" + N + ".n)");
  // The loop over every particle (`in`: its indentation).
  auto perParticle = [&](const std::string& in) {
    scene_ << parallelFor(in, ad.order,
                          withIf("reduction(min : dt_cfl, dt_force, h2min)", ompN));
    scene_ << in << "for (std::size_t i = 0; i < " << N << ".n; ++i) {\n";
    // The minima by a compare, not std::fmin (a call into libm per particle: GCC does not
    // inline it): the running minimum starts at HUGE_VAL and never becomes NaN, and for such a
    // minimum m, `v < m ? v : m` is fmin(m, v) bit for bit (a NaN v leaves m, as fmin does).
    if (ad.cfl) {
      scene_ << in << "  const double vmag = std::sqrt(" << squared(vel) << ");\n";
      scene_ << in << "  const double cfl_i = h[i] / (cs[i] + vmag);\n";
      scene_ << in << "  dt_cfl = cfl_i < dt_cfl ? cfl_i : dt_cfl;\n";
    }
    if (ad.viscous) {
      scene_ << in << "  const double h2_i = h[i] * h[i];\n";
      scene_ << in << "  h2min = h2_i < h2min ? h2_i : h2min;\n";
    }
    if (ad.force) {
      scene_ << in << "  const double amag = std::sqrt(" << squared(acc) << ");\n";
      scene_ << in << "  if (amag > 0) {\n";
      scene_ << in << "    const double force_i = std::sqrt(h[i] / amag);\n";
      scene_ << in << "    dt_force = force_i < dt_force ? force_i : dt_force;\n";
      scene_ << in << "  }\n";
    }
    scene_ << in << "}\n";
  };
  if (!(hUniform_[a] && real_ == "double" && (ad.cfl || ad.force))) {
    perParticle("      ");
    scene_ << "    }\n";
    return;
  }
  scene_ << "      // h the same for every particle of " << N
         << " all the run (analysis/UniformH.cpp): the minima\n"
            "      // from the largest c + |v| and |a|^2 (monotonic: the same bits; stop 46)\n";
  scene_ << "      const double h_all = " << N << ".n > 0 ? h[0] : 0.0;\n";
  if (ad.cfl) scene_ << "      double den_max = -HUGE_VAL;  // the largest c + |v|\n";
  if (ad.force) scene_ << "      double a2max = 0.0;  // the largest |a|^2\n";
  scene_ << "      bool den_low = !(std::isfinite(h_all) && h_all > 0.0);  // then per particle\n";
  scene_ << "      if (!den_low) {\n";
  std::string red = ad.cfl ? "reduction(max : den_max" : "reduction(max : a2max";
  if (ad.cfl && ad.force) red += ", a2max";
  red += ")";
  if (ad.cfl) red += " reduction(|| : den_low)";
  scene_ << parallelFor("        ", ad.order, withIf(red, ompN));
  scene_ << "        for (std::size_t i = 0; i < " << N << ".n; ++i) {\n";
  if (ad.cfl) {
    scene_ << "          const double den = cs[i] + std::sqrt(" << squared(vel) << ");\n";
    scene_ << "          den_max = den > den_max ? den : den_max;  // NaN: skipped, as h / NaN\n";
    scene_ << "          den_low = den_low || den <= 0.0;\n";
  }
  if (ad.force) {
    scene_ << "          const double a2 = " << squared(acc) << ";\n";
    scene_ << "          a2max = a2 > a2max ? a2 : a2max;  // |a| > 0 where |a|^2 > 0\n";
  }
  scene_ << "        }\n";
  scene_ << "      }\n";
  scene_ << "      if (den_low) {\n";
  perParticle("        ");
  scene_ << "      } else {\n";
  if (ad.cfl) {
    scene_ << "        if (den_max > 0.0) {\n";
    scene_ << "          const double cfl_all = h_all / den_max;\n";
    scene_ << "          dt_cfl = cfl_all < dt_cfl ? cfl_all : dt_cfl;\n";
    scene_ << "        }\n";
  }
  if (ad.viscous) {
    scene_ << "        const double h2_all = h_all * h_all;\n";
    scene_ << "        h2min = h2_all < h2min ? h2_all : h2min;\n";
  }
  if (ad.force) {
    scene_ << "        if (a2max > 0.0) {\n";
    scene_ << "          const double force_all = std::sqrt(h_all / std::sqrt(a2max));\n";
    scene_ << "          dt_force = force_all < dt_force ? force_all : dt_force;\n";
    scene_ << "        }\n";
  }
  scene_ << "      }\n";
  scene_ << "    }\n";
}

// --verlet-skin=auto (CpuVerletTune.cpp) with this scene's arrays, lists and statements.
void CpuPrinter::tunedMembers() { verlet_tune::members(out_); }

void CpuPrinter::phasePrologue(const Phase& ph) {
  phaseDisplacements_ = false;
  if (!verlet() || tuned() || hasDomain()) return;
  int checks = 0;  // of kept lists (a cross pass checks A <- B's lists only)
  for (const DestinationWork& w : ph.destinations)
    for (const NeighbourPass& pass : w.passes)
      checks += pass.searches() && !(crossPair(w).first == &w && &pass == &w.passes.back());
  if (checks < 2) return;
  // Nothing of the phase may move a particle or change h between its checks.
  for (int k : ph.equations) {
    const PlanEquation& eq = plan_.equations[k];
    if (!eq.live) continue;
    if (eq.declIndex < 0) return;
    for (const auto& [kind, body] : plan_.equationDecls[eq.declIndex].methods)
      for (const PropAccess& wr : plan_.bodies[body].facts.dWrites)
        if (wr.prop == "x" || wr.prop == "y" || wr.prop == "z" || wr.prop == "h") return;
  }
  phaseDisplacements_ = true;
  scene_ << "    // Each array's displacement since its lists' build measured once in this phase\n"
            "    // (nothing in it moves a particle or changes h; sphc/verlet.h).\n"
            "    sphc::PhaseDisplacements phase_moved;\n";
}

std::vector<int> CpuPrinter::movingArrays(int d, int s) const {
  std::vector<int> moving;
  for (int a : {d, s})
    if (!isStatic(arr(a).name) && (moving.empty() || moving.back() != a)) moving.push_back(a);
  return moving;
}

void CpuPrinter::tunedRebuildCheck(const std::string& lists, const DestinationWork& w, int d,
                                   int s) {
  verlet_tune::KeptLoop loop;
  loop.lists = lists;
  loop.begin = rangeBegin(w);
  loop.end = rangeEnd(w);
  loop.dest = arr(d).name;
  for (int a : movingArrays(d, s)) loop.moving.push_back(positions(a));
  if (d != s && loop.moving.size() == 1)
    loop.staticArray = loop.moving[0] == positions(d) ? arr(s).name : arr(d).name;
  loop.ranged = w.ranged();
  loop.clearUpper = d == s && symmetric_;
  loop.clearCross = crossSourceLists().count(lists) > 0;
  loop.clearOccupied = d != s && skipEmptyLists_;
  verlet_tune::rebuildCheck(scene_, loop);
}

std::vector<std::string> CpuPrinter::listsOf(const std::string& S) const {
  std::vector<std::string> out;
  forEachVerletLists([&](const std::string& lists, const Phase&, const DestinationWork& w,
                         const NeighbourPass& pass) {
    if (arr(w.array).name == S || arr(pass.source).name == S) out.push_back(lists);
  });
  return out;
}

void CpuPrinter::tunedUpdateNeighbours() {
  verlet_tune::Update u;
  u.lazyCells = lazyCells();
  u.loopArrays = !loopArrays_.empty();
  u.anyStatic = anyStatic();
  u.anyReorders = anyReorders();
  u.loopArraysDecl = loopArraysDecl();
  u.orderDomain = orderDomain();
  for (const auto& S : sourceArrays_) {
    verlet_tune::Source src;
    src.name = S;
    src.isStatic = isStatic(S);
    src.reorders = reorders(S);
    src.orderCells = cellListBuild(S, S + ".n", "order_domain");
    src.cells = cellListBuild(S, S + ".n");
    src.permute = permuteInCellOrder(S);
    src.lists = listsOf(S);
    u.sources.push_back(src);
  }
  verlet_tune::updateNeighbours(scene_, u, [&] { searchDomain(); }, [&] { lazyCellsDue(); });
}

// Lazy cell lists (CpuLazyCells.cpp) with this scene's arrays and statements.
std::vector<std::string> CpuPrinter::movingSources() const {
  std::vector<std::string> moving;
  for (const auto& S : sourceArrays_)
    if (!isStatic(S)) moving.push_back(S);
  return moving;
}

std::string CpuPrinter::loopArraysDecl() const {
  if (cpuSingle_) return "";  // the float domains name their arrays (floatDomain)
  std::vector<std::string> names;
  for (const auto& a : plan_.arrays)
    if (loopArrays_.count(a.name)) names.push_back(a.name);
  return lazy_cells::loopArraysDecl(names);
}

void CpuPrinter::lazyCellsMembers() { lazy_cells::members(out_, movingSources()); }

void CpuPrinter::lazyCellsDue() { lazy_cells::markDue(scene_, movingSources()); }

void CpuPrinter::emitLazyCells() {
  lazy_cells::functions(scene_, movingSources(), [&] { searchDomain(); },
                        [&](const std::string& S) { return cellListBuild(S, S + ".n"); });
}

}  // namespace

std::unique_ptr<ScenePrinter> makeCpuPrinter(const Schedule& sched,
                                             const DiagnosticEngine& diags,
                                             const EmitOptions& opts) {
  return std::make_unique<CpuPrinter>(sched, diags, opts);
}

}  // namespace sphc
