// --backend=opencl: the same phases as the CPU loops, as OpenCL C kernels (the same bodies,
// typed `real`) launched from the host: one work item per destination particle (a gather, as
// the OpenMP loops), a kernel per group phase, destination and method, and per neighbour
// pass (destination <- source). Only the buffers and scalars the bodies use are arguments.
// Particle data stays on the device; `converged` tests run on the host.
#include <algorithm>
#include <cstdio>
#include <functional>

#include "analysis/Access.h"
#include "codegen/Printer.h"

namespace sphc {

namespace {

// Whether destination work w has per-particle methods only (no neighbour pass, post_loop,
// reduction, ghost refresh or host reduction): at most its initialize.
bool initializeOnly(const DestinationWork& w) {
  return w.passes.empty() && w.postLoop.empty() && w.reductions.empty() &&
         w.ghostRefresh.empty() && w.hostReduce.empty();
}

class OpenCLPrinter : public ScenePrinter {
 public:
  OpenCLPrinter(const Schedule& sched, const DiagnosticEngine& diags, const EmitOptions& opts)
      : ScenePrinter(sched, diags, opts), batchedTables_(opts.batchedTables),
        keptCells_(opts.keptCellsSkin > 0.0 && opts.batchedTables),
        keptSkin_(opts.keptCellsSkin), fused_(opts.fusedLaunches),
        groupReductions_(opts.fusedLaunches && opts.fusedReductions) {
    // Line 1 of the kernel source is this directive, so lines are the source's own.
    cl_ << "#line 2 \"" << plan_.sceneName << ".cl\"\n";
  }

 private:
  std::string backendComment() const override {
    return std::string("opencl (kernels in SCENE_CL, ") +
           (singlePrecision_ ? "single" : "double") + " precision)";
  }
  void systemIncludes() override { out_ << "\n#include \"sphc/opencl.h\"\n"; }
  // Every body runs on the device but `converged`, which the host evaluates from the host
  // copy of the constants.
  bool bodyOnDevice(bool converged) const override { return !converged; }
  void deviceKernelFunctions() override;
  void devicePowFunction() override;
  void beforeScene() override;
  void searchMembers() override;
  std::string ghostsType() const override { return "sphc::ocl::DeviceGhosts"; }
  // The launches are asynchronous: a host timer would measure nothing.
  bool timesNeighbourSearch() const override { return false; }
  void dataMovement() override;
  void destination(const DestinationWork& w, const std::string& phase) override;
  void ghostRefresh(const DestinationWork& w);
  // The test runs on the host; constants are current there, properties are not.
  void beforeConverged(const PlanEquation& eq) override {
    scene_ << "        dev_" << arr(eq.dest).name << ".download(ocl, " << arr(eq.dest).name
           << ");\n";
  }
  // ... and constants it wrote go back to the device.
  void afterConverged(const PlanEquation& eq, int c) override {
    scene_ << "        dev_" << arr(eq.dest).name << ".upload_constant(ocl, " << arr(eq.dest).name
           << ", " << constSlot(eq.dest, c) << ");\n";
  }
  void steppers() override;
  void stepperCall(const StepStatement& st,
                   const std::function<std::string(int)>& timeAfter) override;
  void wrapPeriodic(int a) override {
    scene_ << "    sphc::ocl::wrap_periodic(ocl, box, dev_" << arr(a).name << ", " << arr(a).name
           << ");\n";
  }
  void updateNeighbours() override;
  void updateNeighboursWithGhosts() override;
  std::string removeGhosts() const override {
    std::string r;
    for (const auto& S : sourceArrays_) r += "    ghosts_" + S + ".remove();\n";
    return r;
  }
  void timedNeighbourUpdate() override { scene_ << "    update_neighbours();\n"; }
  void adaptiveDtArray(int a) override;
  void mainBackendOptions() override {
    out_ << "  scene.selection = sphc::ocl::take_options(argc, argv);\n";
    out_ << "  prog.device_launches = [] { return scene.ocl.launches(); };  // --timing\n";
  }
  std::string afterSetup() const override {
    return "    if (!sphc::counting_particles()) scene.to_device();\n";
  }
  bool hasToHost() const override { return true; }
  std::string restoreData() const override {
    return "    scene.from_host();  // the restored arrays to the device\n";
  }
  // A limit's remove compacted the host array: up again (the buffers keep their capacity;
  // the cell tables, kept ones too, are built again for the new count).
  std::string afterRemoval(int a) const override {
    const std::string& A = arr(a).name;
    return "      scene.dev_" + A + ".upload(scene.ocl, scene." + A + ");  // to the device\n";
  }
  // The manager works on the host arrays: down before it, up after (DeviceArray::upload
  // grows the buffers' capacity by at least a quarter when an array outgrows it).
  void arraysToHost(const std::vector<int>& arrays) override {
    for (int a : arrays)
      scene_ << "    dev_" << arr(a).name << ".download(ocl, " << arr(a).name << ");\n";
  }
  void arraysFromHost(const std::vector<int>& arrays) override {
    for (int a : arrays)
      scene_ << "    dev_" << arr(a).name << ".upload(ocl, " << arr(a).name << ");\n";
  }
  bool checksZonesFirst() const override { return true; }
  void positionsToHost(const std::vector<int>& arrays) override {
    for (int a : arrays)
      scene_ << "    dev_" << arr(a).name << ".download(ocl, " << arr(a).name << ", {"
             << zoneProps(a, {"x", "y", "z"}) << "});  // positions\n";
  }
  void inletVelocitiesFromHost(const std::vector<int>& arrays) override {
    for (int a : arrays)
      scene_ << "      dev_" << arr(a).name << ".upload(ocl, " << arr(a).name << ", {"
             << zoneProps(a, {"u", "v", "w"}) << "});  // velocities\n";
  }
  // The indices of those of `names` the array has, as a list.
  std::string zoneProps(int a, const std::vector<std::string>& names) const {
    std::string s;
    for (const auto& n : names)
      if (int i = propIndex(a, n); i >= 0) s += (s.empty() ? "" : ", ") + propSlot(a, i);
    return s;
  }

  // loop_all on the device: the capacity of a work item's neighbour list (private memory),
  // and the scratch slot of the neighbour counts that the host checks against it.
  static constexpr int kMaxNbrs = 256;
  static constexpr int kNbrsSlot = 64;
  // The scratch slots of a destination's reductions' per-particle values (one each: the
  // post_loop kernel may compute them all).
  static constexpr int kReduceSlot = 8;
  // ... and of their work groups' results, where the kernel reduces within its groups.
  static constexpr int kGroupReduceSlot = 32;

  // Kernel arguments: declarations in the kernel, expressions on the host.
  struct KernelArgs {
    std::vector<std::string> decls, host;
    std::map<std::string, size_t> at;
    // A buffer that one body reads (const) and another writes becomes non-const.
    void add(const std::string& decl, const std::string& hostExpr, const std::string& key) {
      auto it = at.find(key);
      if (it != at.end()) {
        if (decl.find("const ") == std::string::npos) decls[it->second] = decl;
        return;
      }
      at[key] = decls.size();
      decls.push_back(decl);
      host.push_back(hostExpr);
    }
  };
  // start_idx / stop_idx: kernels launched over [0, d_end) return below d_begin.
  void rangeArg(const DestinationWork& w, KernelArgs& ka) const {
    if (w.ranged()) ka.add("const int d_begin", "d_begin", "d_begin");
  }
  void rangeGuard(const DestinationWork& w) {
    if (w.ranged()) cl_ << "  if (d_idx < d_begin) return;  // group option start_idx\n";
  }
  std::string devBuffer(int a, const std::string& p) const;
  void addBodyArgs(KernelArgs& ka, const PlanBody& b, int dest, int src,
                   const std::string& eqValues) const;
  void beginKernel(const std::string& name, const KernelArgs& ka, bool guard = true);
  std::string launch(const std::string& name, const std::string& n, const KernelArgs& ka,
                     const std::string& time = "t") const;
  // The statement that builds the cell table of source S over its first `count` particles.
  std::string cellListBuild(const std::string& S, const std::string& count) const;
  // The statements that build the cell tables of the sources (name, particle count): one
  // build_tables call (batchedTables_), else a cellListBuild each; `indent` before each line.
  std::string cellTablesBuild(const std::vector<std::pair<std::string, std::string>>& sources,
                              const std::string& indent) const;
  bool batchedTables_ = true;
  bool keptCells_ = false;  // EmitOptions::keptCellsSkin > 0 (with batchedTables_)
  double keptSkin_ = 0.0;
  bool fused_ = true;  // EmitOptions::fusedLaunches
  bool groupReductions_ = false;  // EmitOptions::fusedReductions (with fused_)
  // update_neighbours with the cell tables kept across updates (keptCells_).
  void updateNeighboursKept();
  // The arrays of deviceExtents: whether each is a source ("{true, false}").
  std::string extentSources() const;
  // The extents of the arrays in neighbour loops, for ocl.search_domain / ocl.make_grid.
  std::string deviceExtents(const std::string& indent) const;
  // Whether stepper run `r`'s kernels compute the search domain's extents for the neighbour
  // update that follows it (foldsExtents), and whether any run does.
  bool foldsExtents(int r) const;
  bool endsInUpdate(int r) const;
  bool anyFoldsExtents() const;
  // The scratch slot of those extents' partial results (Context::scratch).
  static constexpr int kExtentSlot = -4;
  // The initialize kernels pulled into a stepper run's kernels (pulledOf): the first
  // per-particle work on each array of the evaluation (sequence 0) or of the post_step groups
  // (1), when the run before it ends in the neighbour update (runSequence: 1 + the sequence,
  // or 0). The update reads positions and h only and permutes every property (which commutes
  // with per-particle work), so the initialize, which writes neither, may run before it.
  struct Pulled {
    const DestinationWork* work = nullptr;
    std::string phase;
    int flag = 0;  // index into the scene's pulled_init[]
  };
  // The walk computePulled and computeDtWork share: the destination work of group g's phases
  // in call order (its subgroups' within them) to `visit`, but work that the schedule moved
  // whole into a later kernel on its array; it stops (stop = true) at a subgroup that tests,
  // repeats, skips or rebuilds the neighbours, and after work with host reductions. The
  // subgroups `skip` names are passed over.
  void walkStraight(const ScheduleGroup& g, bool& stop,
                    const std::function<bool(const ScheduleGroup&)>& skip,
                    const std::function<void(const DestinationWork&, const Phase&)>& visit) const;
  mutable std::map<int, Pulled> pulled_[2];  // by array
  mutable int pulledCount_ = -1;             // -1: not computed yet
  void computePulled() const;
  int runSequence(int r) const;
  const Pulled* pulledOf(const DestinationWork& w) const;
  // The adaptive time step's limits computed by the last kernel of the step on an array
  // (dtWorkOf: an initialize-only phase of the post_step groups after which nothing in the
  // step touches the array), within its work groups: adaptive_dt reads them, no kernel.
  mutable std::map<int, const DestinationWork*> dtWork_;
  mutable bool dtComputed_ = false;
  void computeDtWork() const;
  bool dtWorkOf(const DestinationWork& w) const;
  static constexpr int kDtSlot = -5;
  mutable std::string dtAmag_;  // dtLimits' |a| of particle i, where the force limit is used
  // The limits over array a (name, per-particle value of particle i), the properties they
  // read, each named by `name`.
  std::vector<std::pair<std::string, std::string>> dtLimits(
      int a, std::vector<std::string>& props,
      const std::function<std::string(const std::string&)>& name) const;
  // The pulled initialize's arguments and calls (at time `time`) in a kernel on its array.
  void initializeArgs(const DestinationWork& w, KernelArgs& ka) const;
  std::string initializeCalls(const DestinationWork& w, const std::string& time,
                              const std::string& indent) const;
};

void OpenCLPrinter::deviceKernelFunctions() {
  cl_ << "inline real KERNEL_W(real r, real h) { return kernel_w(r, h); }\n"
         "inline real KERNEL_DWDR(real r, real h) {\n"
         "  real x[3] = {r, 0.0, 0.0};\n"
         "  real g[3];\n"
         "  kernel_gradient(x, r, h, g);\n"
         "  return r > 0.0 ? g[0] : 0.0;\n"
         "}\n";
  resetLineDirective(cl_, device_);
}

// sphc/pow.h's pow_int in OpenCL C (the same products in the same order, the same special
// values to the built-in pow), so that the device computes the bodies' integer powers as the
// CPU backends do. The built-in pow cannot be overloaded: the bodies' calls reach it through
// a macro defined after it.
void OpenCLPrinter::devicePowFunction() {
  if (!bodyOnDevice(false)) return;
  cl_ << "// pow(x, y) of the bodies: x^y by multiplications where y is an integer with |y| <= 8,\n"
         "// the built-in pow otherwise (sphc/pow.h's pow_int; sphc --int-pow=off: pow).\n"
         "inline real sphc_pow_uint_small(real x, int n) {\n"
         "  switch (n) {\n"
         "    case 0: return 1.0;\n"
         "    case 1: return x;\n"
         "    case 2: return x * x;\n"
         "    case 3: return x * x * x;\n"
         "    case 4: { const real x2 = x * x; return x2 * x2; }\n"
         "    case 5: { const real x2 = x * x; return x2 * x2 * x; }\n"
         "    case 6: { const real x2 = x * x; return x2 * x2 * x2; }\n"
         "    case 7: { const real x2 = x * x; return x2 * x2 * x2 * x; }\n"
         "    default: { const real x2 = x * x; const real x4 = x2 * x2; return x4 * x4; }\n"
         "  }\n"
         "}\n"
         "inline real sphc_pow_int(real x, real y) {\n"
         "  if (fabs(y) <= 8.0) {  // false for NaN\n"
         "    const int n = (int)y;\n"
         "    if ((real)n == y) {\n"
         "      const real r = sphc_pow_uint_small(x, n < 0 ? -n : n);\n"
         "      const real a = fabs(r);\n"
         "      if (a >= DBL_MIN && a <= DBL_MAX) return n < 0 ? 1.0 / r : r;\n"
         "    }\n"
         "  }\n"
         "  return pow(x, y);\n"
         "}\n"
         "#define pow(x, y) sphc_pow_int(x, y)\n";
  resetLineDirective(cl_, device_);
}

void OpenCLPrinter::beforeScene() {
  out_ << "// ---- OpenCL C of the kernels, built at start-up with the runtime's ----\n\n";
  out_ << "constexpr bool DOUBLE_PRECISION = " << (singlePrecision_ ? "false" : "true") << ";\n";
  out_ << "const char* const SCENE_CL = R\"SPHC_CL(" << cl_.str() << ")SPHC_CL\";\n\n";
}

void OpenCLPrinter::searchMembers() {
  out_ << "  sphc::ocl::Selection selection;  // --platform, --device\n";
  out_ << "  sphc::ocl::Context ocl;\n";
  for (const auto& a : plan_.arrays) out_ << "  sphc::ocl::DeviceArray dev_" << a.name << ";\n";
  out_ << "  sphc::ocl::Grid grid;\n";
  if (anyFoldsExtents())
    out_ << "  // > 0: the rows of extents that the last stepper run's kernels computed, for the\n"
            "  // next neighbour update (0: it computes them itself).\n"
            "  std::size_t extent_rows = 0;\n";
  computePulled();
  computeDtWork();
  for (const auto& [a, w] : dtWork_)
    out_ << "  // > 0: the rows of the adaptive step's limits over " << arr(a).name
         << " that the step's last kernel on it computed\n  std::size_t dt_rows_" << arr(a).name
         << " = 0;\n";
  if (pulledCount_ > 0)
    out_ << "  // true: the initialize kernel k was done in the stepper run's kernels before the\n"
            "  // neighbour update (its own launch is skipped once).\n"
            "  bool pulled_init[" << pulledCount_ << "] = {};\n";
  for (const auto& S : sourceArrays_) out_ << "  sphc::ocl::CellTable cells_" << S << ";\n";
  if (keptCells_ && !sourceArrays_.empty() && !hasDomain()) {
    char skin[64];
    std::snprintf(skin, sizeof skin, "%.17g", keptSkin_);
    out_ << "  sphc::ocl::KeptTables kept{" << skin
         << "};  // the cell tables kept across updates (--kept-cells)\n";
  }
}

void OpenCLPrinter::dataMovement() {
  // Data movement: everything up after set-up; properties back for output and checks.
  scene_ << "  void to_device() {\n";
  scene_ << "    ocl.init(selection, DOUBLE_PRECISION, sphc::ocl::kernel_function_source(\""
         << plan_.kernel << "\", DIM) + SCENE_CL, \"" << plan_.sceneName << "\");\n";
  for (const auto& a : plan_.arrays)
    scene_ << "    dev_" << a.name << ".upload(ocl, " << a.name << ");\n";
  scene_ << "  }\n\n";
  scene_ << "  void to_host() {\n";
  for (const auto& a : plan_.arrays)
    scene_ << "    dev_" << a.name << ".download(ocl, " << a.name << ");\n";
  scene_ << "  }\n\n";
  scene_ << "  // --restart: the host arrays (read from a file) up again, after to_device.\n";
  scene_ << "  void from_host() {\n";
  for (const auto& a : plan_.arrays)
    scene_ << "    dev_" << a.name << ".upload(ocl, " << a.name << ");\n";
  scene_ << "  }\n\n";
}

std::string OpenCLPrinter::cellListBuild(const std::string& S, const std::string& count) const {
  return cellListBuildCall(S, count, "ocl, grid",
                           [&](int a, const std::string& axis) { return devBuffer(a, axis); });
}

std::string OpenCLPrinter::cellTablesBuild(
    const std::vector<std::pair<std::string, std::string>>& sources,
    const std::string& indent) const {
  std::string r;
  if (!batchedTables_ || sources.empty()) {
    for (const auto& [S, count] : sources) r += indent + cellListBuild(S, count) + "\n";
    return r;
  }
  r = indent + "sphc::ocl::build_tables(ocl, grid, {";
  const char* axes[3] = {"x", "y", "z"};
  for (std::size_t k = 0; k < sources.size(); ++k) {
    const auto& [S, count] = sources[k];
    const int s = plan_.arrayIndex(S);
    r += (k ? ",\n" + indent + "                                    " : std::string()) +
         "{&cells_" + S;
    for (int a = 0; a < 3; ++a)
      r += ", " + (a >= plan_.dim ? std::string("nullptr") : devBuffer(s, axes[a]));
    r += ", " + count + "}";
  }
  return r + "});  // every source's cell table in one set of launches\n";
}

// update_neighbours of a scene without periodic or mirror domain, on the device: the search
// domain from min/max reductions, then a cell table per source (cell keys, bitonic sort, cell
// start/end). Positions never leave the device.
void OpenCLPrinter::updateNeighbours() {
  if (keptCells_ && !sourceArrays_.empty()) return updateNeighboursKept();
  if (!loopArrays_.empty() && anyFoldsExtents()) {
    scene_ << "    if (extent_rows > 0) {  // from the stepper run's kernels\n"
           << "      grid = ocl.grid_of_extents(ocl.scratch(7 * extent_rows, " << kExtentSlot
           << "), extent_rows, DIM, Kernel::radius_scale);\n"
           << "      extent_rows = 0;\n"
           << "    } else {\n"
           << "      grid = ocl.make_grid(" << deviceExtents("                            ")
           << ", DIM, Kernel::radius_scale);\n"
           << "    }\n";
  } else if (!loopArrays_.empty()) {
    scene_ << "    grid = ocl.make_grid(" << deviceExtents("                          ")
           << ", DIM, Kernel::radius_scale);\n";
  }
  // Every REORDER_EVERY builds the particles are sorted in cell order on the device, as
  // on the CPU (same grid, same order), so outputs list particles in the same order.
  if (anyReorders())
    scene_ << "    const bool reorder = builds++ % REORDER_EVERY == 0;\n";
  if (batchedTables_ && !sourceArrays_.empty()) {
    std::vector<std::pair<std::string, std::string>> all, reordered;
    for (const auto& S : sourceArrays_) {
      all.push_back({S, S + ".n"});
      if (reorders(S)) reordered.push_back({S, S + ".n"});  // not a ranged group's source
    }
    scene_ << cellTablesBuild(all, "    ");
    if (reordered.empty()) return;
    scene_ << "    if (reorder) {\n";
    for (const auto& [S, count] : reordered)
      scene_ << "      dev_" << S << ".permute(ocl, cells_" << S << ", " << S << ");\n";
    scene_ << cellTablesBuild(reordered, "      ") << "    }\n";
    return;
  }
  for (const auto& S : sourceArrays_) {
    const std::string build = cellListBuild(S, S + ".n");
    scene_ << "    " << build << "\n";
    if (!reorders(S)) continue;  // a ranged group names its particles by index
    scene_ << "    if (reorder) {\n      dev_" << S << ".permute(ocl, cells_" << S << ", " << S
           << ");\n      " << build << "\n    }\n";
  }
}

std::string OpenCLPrinter::extentSources() const {
  std::string r = "{";
  bool first = true;
  for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a) {
    if (!loopArrays_.count(arr(a).name)) continue;
    const bool source = std::find(sourceArrays_.begin(), sourceArrays_.end(), arr(a).name) !=
                        sourceArrays_.end();
    r += std::string(first ? "" : ", ") + (source ? "true" : "false");
    first = false;
  }
  return r + "}";
}

// update_neighbours with the cell tables kept (sphc::ocl::KeptTables): one kernel and one read
// per update test how far the sources moved since the tables were built; the tables are built
// again, on cells of (1 + skin) times the support, only when one moved too far, and at the
// re-sort every REORDER_EVERY updates (in the cell order of cells of the support, as without
// kept tables, so the particles' order is the same).
void OpenCLPrinter::updateNeighboursKept() {
  scene_ << "    // The cell tables are kept while no source particle moved past the cells' skin.\n";
  scene_ << "    const bool rebuild = kept.update(ocl, " << deviceExtents(std::string(41, ' '))
         << ",\n" << std::string(37, ' ') << extentSources() << ", DIM, Kernel::radius_scale);\n";
  if (anyReorders())
    scene_ << "    const bool reorder = builds++ % REORDER_EVERY == 0;\n"
           << "    if (!rebuild && !reorder) return;\n";
  else
    scene_ << "    if (!rebuild) return;\n";
  std::vector<std::pair<std::string, std::string>> all, reordered;
  for (const auto& S : sourceArrays_) {
    all.push_back({S, S + ".n"});
    if (reorders(S)) reordered.push_back({S, S + ".n"});  // not a ranged group's source
  }
  if (!reordered.empty()) {
    scene_ << "    if (reorder) {  // in the cell order of cells of the support\n";
    scene_ << "      grid = kept.grid(ocl, 0.0);\n";
    scene_ << cellTablesBuild(reordered, "      ");
    for (const auto& [S, count] : reordered)
      scene_ << "      dev_" << S << ".permute(ocl, cells_" << S << ", " << S << ");\n";
    scene_ << "    }\n";
  }
  scene_ << "    grid = kept.grid(ocl, kept.skin);\n";
  scene_ << cellTablesBuild(all, "    ");
  scene_ << "    kept.built(ocl, " << deviceExtents(std::string(20, ' ')) << ",\n"
         << std::string(20, ' ') << extentSources() << ");\n";
}

// A stepper run ends in the neighbour update (endsInUpdate) when every statement that calls
// it is followed by a neighbour update with nothing between that could move particles: the next statement (past
// update_domain, which does nothing without a periodic or mirror domain) is
// compute_accelerations, or it is the step's last and post_step runs its update at every step
// (no `every` group). Only without a domain (the ghosts' update has its own extents), without
// inlet/outlet (arrays change size), without --kept-cells (its kernel tests displacements),
// and when the run has a kernel for every array in a neighbour loop. Every other run sets
// extent_rows to 0, so an update never uses extents older than the last positions. It folds
// the extents (foldsExtents) with --fused-reductions.
bool OpenCLPrinter::foldsExtents(int r) const { return groupReductions_ && endsInUpdate(r); }

bool OpenCLPrinter::endsInUpdate(int r) const {
  if (!fused_ || hasDomain() || keptCells_ || loopArrays_.empty()) return false;
  const StepperRun& run = sched_.stepperRuns[r];
  for (const std::string& A : loopArrays_) {
    bool has = false;
    for (const StepperRun::Part& part : run.parts) has |= arr(part.array).name == A;
    if (!has) return false;
  }
  const std::vector<StepStatement>& st = sched_.step;
  bool called = false;
  for (size_t i = 0; i < st.size(); ++i) {
    if (st[i].kind == StepStatement::InletOutlet) return false;
    if (st[i].kind != StepStatement::Stepper || st[i].run != r) continue;
    called = true;
    size_t j = i + 1;
    while (j < st.size() && st[j].kind == StepStatement::UpdateDomain) ++j;
    if (j < st.size()) {
      if (st[j].kind != StepStatement::ComputeAccelerations) return false;
      continue;
    }
    // The step's last statement: post_step's update follows, when it runs at every step.
    if (sched_.postStep.empty() || !sched_.postStepNeighbours) return false;
    for (const auto& ps : sched_.postStep)
      if (ps.group->every) return false;
  }
  return called;
}

bool OpenCLPrinter::anyFoldsExtents() const {
  for (size_t r = 0; r < sched_.stepperRuns.size(); ++r)
    if (!sched_.stepperRuns[r].parts.empty() && foldsExtents(static_cast<int>(r))) return true;
  return false;
}

// 1 + the sequence that follows every call of run r (0: the evaluation, 1: post_step), 0 when
// the run does not end in a neighbour update (endsInUpdate) or is followed by both.
int OpenCLPrinter::runSequence(int r) const {
  if (!endsInUpdate(r)) return 0;
  const std::vector<StepStatement>& st = sched_.step;
  int seq = 0;
  for (size_t i = 0; i < st.size(); ++i) {
    if (st[i].kind != StepStatement::Stepper || st[i].run != r) continue;
    size_t j = i + 1;
    while (j < st.size() && st[j].kind == StepStatement::UpdateDomain) ++j;
    const int s = j < st.size() ? 1 : 2;
    if (seq && seq != s) return 0;
    seq = s;
  }
  return seq;
}

void OpenCLPrinter::walkStraight(
    const ScheduleGroup& g, bool& stop, const std::function<bool(const ScheduleGroup&)>& skip,
    const std::function<void(const DestinationWork&, const Phase&)>& visit) const {
  for (const auto& m : g.members) {
    if (stop) return;
    if (!m.isPhase) {
      const ScheduleGroup& sub = *g.subgroups[m.index];
      if (skip && skip(sub)) continue;
      const PlanGroup& pg = *sub.group;
      if (pg.iterate || pg.every || pg.condition || sub.rebuildNeighbours) {
        stop = true;
        return;
      }
      walkStraight(sub, stop, skip, visit);
      continue;
    }
    const Phase& ph = g.phases[m.index];
    for (const DestinationWork& w : ph.destinations) {
      if (w.initializeMoved && initializeOnly(w)) continue;  // moved whole into a later kernel
      visit(w, ph);
      if (!w.hostReduce.empty()) stop = true;
    }
  }
}

// The first per-particle work on each array in a sequence of calls with no test between
// them, as the schedule's fusion walks it (ScheduleFusion.cpp): an initialize kernel is
// pulled when nothing before it in the sequence reads or writes its array (no pass with the
// array as destination or source, no earlier work on it), it is the array's own kernel (not
// moved into a later phase's, not ranged, not on ghosts, parallel), and it writes no position
// and not h. The walk stops at a group that tests, repeats or skips, and at host reductions.
void OpenCLPrinter::computePulled() const {
  if (pulledCount_ >= 0) return;
  pulledCount_ = 0;
  bool runs[2] = {false, false};
  for (size_t r = 0; r < sched_.stepperRuns.size(); ++r)
    if (!sched_.stepperRuns[r].parts.empty())
      if (int q = runSequence(static_cast<int>(r))) runs[q - 1] = true;
  const std::vector<std::string> moving = [&] {
    std::vector<std::string> m = positionProps(plan_.dim);
    m.push_back("h");
    return m;
  }();
  for (int q = 0; q < 2; ++q) {
    if (!runs[q]) continue;
    std::set<int> touched;
    bool stop = false;
    // Post_step's groups are not part of the evaluation.
    auto skip = [q](const ScheduleGroup& sub) { return q == 0 && sub.group->postStep; };
    auto visit = [&](const DestinationWork& w, const Phase& ph) {
      const int a = w.array;
      bool ok = !touched.count(a) && !w.initialize.empty() && !w.initializeMoved &&
                !w.ranged() && !w.onGhosts && w.perParticle == LoopOrder::Parallel;
      if (ok) {
        std::vector<std::pair<const PlanEquation*, ast::Method::Kind>> work;
        for (const MovedWork& mw : w.initializeFirst) work.push_back({mw.equation, mw.method});
        for (const auto* eq : w.initialize) work.push_back({eq, ast::Method::Initialize});
        for (const auto& [eq, kind] : work)
          for (const Access& x : equationAccesses(plan_, *eq))
            if (x.method == kind && x.write && x.array == a &&
                std::find(moving.begin(), moving.end(), x.prop) != moving.end())
              ok = false;
      }
      if (ok) pulled_[q][a] = {&w, ph.name, pulledCount_++};
      touched.insert(a);
      for (const NeighbourPass& pass : w.passes) touched.insert(pass.source);
    };
    if (q == 0) {
      walkStraight(sched_.equations, stop, skip, visit);
    } else {
      for (const auto& sub : sched_.equations.subgroups)
        if (sub->group->postStep && !stop) {
          const PlanGroup& pg = *sub->group;
          if (pg.iterate || pg.every || pg.condition || sub->rebuildNeighbours) break;
          walkStraight(*sub, stop, skip, visit);
        }
    }
  }
}

const OpenCLPrinter::Pulled* OpenCLPrinter::pulledOf(const DestinationWork& w) const {
  computePulled();
  for (const auto& seq : pulled_)
    if (auto it = seq.find(w.array); it != seq.end() && it->second.work == &w) return &it->second;
  return nullptr;
}

void OpenCLPrinter::initializeArgs(const DestinationWork& w, KernelArgs& ka) const {
  for (const MovedWork& mw : w.initializeFirst)
    addBodyArgs(ka, methodBody(*mw.equation, mw.method), w.array, -1, eqStruct(*mw.equation));
  for (const auto* eq : w.initialize)
    addBodyArgs(ka, methodBody(*eq, ast::Method::Initialize), w.array, -1, eqStruct(*eq));
}

std::string OpenCLPrinter::initializeCalls(const DestinationWork& w, const std::string& time,
                                           const std::string& indent) const {
  std::string r;
  auto call = [&](const PlanEquation& eq, ast::Method::Kind kind) {
    r += indent + callBody(bodyFunctionName(eq.name, ast::methodKeyword(kind)), methodBody(eq, kind),
                           w.array, eqStruct(eq), time, "_") +
         ";  // " + eq.name + ", from " + loc(eq.loc) + "\n";
  };
  for (const MovedWork& mw : w.initializeFirst) call(*mw.equation, mw.method);
  for (const auto* eq : w.initialize) call(*eq, ast::Method::Initialize);
  return r;
}

std::vector<std::pair<std::string, std::string>> OpenCLPrinter::dtLimits(
    int a, std::vector<std::string>& props,
    const std::function<std::string(const std::string&)>& name) const {
  (void)a;
  const AdaptiveDt& ad = sched_.adaptiveDt;
  const bool useCfl = ad.cfl;
  const std::vector<std::string> vel = {"u", "v", "w"}, acc = {"au", "av", "aw"};
  props = {"h"};
  if (useCfl) props.push_back("cs");
  for (int k = 0; k < plan_.dim; ++k) {
    if (useCfl) props.push_back(vel[k]);
    if (ad.force) props.push_back(acc[k]);
  }
  auto at = [&](const std::string& p) { return name(p) + "[i]"; };
  auto mag = [&](const std::vector<std::string>& c) {
    std::string m = "sqrt(";
    for (int k = 0; k < plan_.dim; ++k) m += (k ? " + " : "") + at(c[k]) + " * " + at(c[k]);
    return m + ")";
  };
  dtAmag_ = ad.force ? mag(acc) : std::string();
  std::vector<std::pair<std::string, std::string>> limits;
  if (useCfl) limits.push_back({"dt_cfl", at("h") + " / (" + at("cs") + " + " + mag(vel) + ")"});
  if (ad.force) limits.push_back({"dt_force", "amag > 0 ? sqrt(" + at("h") + " / amag) : INFINITY"});
  if (ad.viscous) limits.push_back({"h2min", at("h") + " * " + at("h")});
  return limits;
}

// The last work of the step on each array with adaptive-dt limits, where it is a kernel of
// its own: the post_step groups run at every step (no `every`; none tests, repeats or
// rebuilds), and, walking them in call order, the array's last destination work is an
// initialize only (no pass, post_loop, reduction, ghost refresh or host reduce; not moved,
// not pulled into a stepper, not ranged, not on ghosts, parallel), after which no pass reads
// the array as its source. Nothing else runs on the device before adaptive_dt (the run loop
// only reads the arrays back for outputs and checks), so the limits computed at the end of
// that kernel are those of the adaptive_dt kernel, and their minima the same values.
void OpenCLPrinter::computeDtWork() const {
  if (dtComputed_) return;
  dtComputed_ = true;
  const AdaptiveDt& ad = sched_.adaptiveDt;
  if (!fused_ || !groupReductions_ || !ad.enabled || hasDomain() || sched_.postStep.empty()) return;
  for (const StepStatement& st : sched_.step)
    if (st.kind == StepStatement::InletOutlet) return;
  for (const auto& ps : sched_.postStep) {
    const PlanGroup& pg = *ps.group;
    if (pg.every || pg.iterate || pg.condition) return;
  }
  std::map<int, const DestinationWork*> last;
  bool stop = false;
  auto visit = [&](const DestinationWork& w, const Phase&) {
    const int a = w.array;
    const bool own = !w.initialize.empty() && !w.initializeMoved && initializeOnly(w) &&
                     !w.ranged() && !w.onGhosts && w.perParticle == LoopOrder::Parallel &&
                     !pulledOf(w);
    if (own)
      last[a] = &w;
    else
      last.erase(a);
    for (const NeighbourPass& pass : w.passes) last.erase(pass.source);
  };
  for (const auto& sub : sched_.equations.subgroups)
    if (sub->group->postStep) {
      if (sub->rebuildNeighbours) return;
      walkStraight(*sub, stop, nullptr, visit);
    }
  if (stop) return;
  for (int a : ad.arrays)
    if (last.count(a)) dtWork_[a] = last[a];
}

bool OpenCLPrinter::dtWorkOf(const DestinationWork& w) const {
  computeDtWork();
  auto it = dtWork_.find(w.array);
  return it != dtWork_.end() && it->second == &w;
}

// A run of stepper statements: its function, with each statement's time.
void OpenCLPrinter::stepperCall(const StepStatement& st,
                                const std::function<std::string(int)>& timeAfter) {
  const StepperRun& run = sched_.stepperRuns[st.run];
  if (run.parts.empty()) return;
  computePulled();
  std::string args;
  for (int d : st.stagesDone) args += timeAfter(d) + ", ";
  // The time of the evaluation (or post_step) that the run's pulled initialize kernels are for.
  const int seq = runSequence(st.run);
  bool pulls = false;
  for (const StepperRun::Part& part : run.parts) pulls |= seq > 0 && pulled_[seq - 1].count(part.array);
  if (pulls) {
    const std::vector<StepStatement>& all = sched_.step;
    size_t i = static_cast<size_t>(&st - all.data()) + 1;
    while (i < all.size() && all[i].kind == StepStatement::UpdateDomain) ++i;
    args += i < all.size() ? timeAfter(all[i].stagesDone[0]) + ", " : std::string("t + dt, ");
  }
  scene_ << "    " << run.name << "(" << args << "dt);\n";
}

std::string OpenCLPrinter::devBuffer(int a, const std::string& p) const {
  int c = constIndex(a, p);
  if (c >= 0) return "dev_" + arr(a).name + ".constant(" + constSlot(a, c) + ")";
  int i = propIndex(a, p);
  if (i < 0) SPHC_INTERNAL("property '" + p + "' of '" + arr(a).name + "' was not allocated");
  return "dev_" + arr(a).name + ".prop(" + propSlot(a, i) + ")";
}

void OpenCLPrinter::addBodyArgs(KernelArgs& ka, const PlanBody& b, int dest, int src,
                          const std::string& eqValues) const {
  for (const auto& p : bodyParams(b, dest, device_)) {
    switch (p.kind) {
      case BodyParam::Scalar:
        ka.add("const real " + eqValues + "_" + p.name, eqValues + "." + p.name,
               eqValues + "." + p.name);
        break;
      case BodyParam::DProp: ka.add(p.decl, devBuffer(dest, p.name), "d_" + p.name); break;
      case BodyParam::SProp:
        ka.add("__global const " + propType(src, p.name, device_) + "* s_" + p.name,
               devBuffer(src, p.name), "s_" + p.name);
        break;
      default: break;
    }
  }
}

void OpenCLPrinter::beginKernel(const std::string& name, const KernelArgs& ka, bool guard) {
  cl_ << "__kernel void " << name << "(const int n, const real t, const real dt";
  for (const auto& d : ka.decls) cl_ << ",\n    " << d;
  cl_ << ") {\n";
  if (guard) cl_ << "  const int d_idx = get_global_id(0);\n  if (d_idx >= n) return;\n";
}

std::string OpenCLPrinter::launch(const std::string& name, const std::string& n,
                                  const KernelArgs& ka, const std::string& time) const {
  std::string s = "ocl.run(\"" + name + "\", " + n + ", " + n + ", " + time + ", dt";
  for (const auto& h : ka.host) s += ", " + h;
  return s + ");";
}

// One destination of a phase: a kernel per method (initialize, post_loop), per neighbour pass
// and per reduction, and their launches; the ghosts refreshed after.
void OpenCLPrinter::destination(const DestinationWork& w, const std::string& name) {
  const int d = w.array;
  const bool onGhosts = w.onGhosts;
  const std::string& D = arr(d).name;
  // The reductions' per-particle values: in the post_loop kernel where the schedule says so
  // (DestinationWork::reduceInPostLoop), else a kernel each.
  auto reduceSlot = [&](size_t i) { return std::to_string(kReduceSlot + i); };
  // A per-particle method's kernel (initialize with the work fused into it, post_loop with
  // the reductions' values): its arguments and its calls, in its own kernel or in a pass's.
  // Min and max reductions whose values the post_loop kernel computes are reduced within its
  // work groups (sphc_group_reduce, groups of Context::kGroup items), the host combines the
  // groups' results: no reduction kernel. Minima and maxima are exact: the same values.
  bool groupReduce = fused_ && groupReductions_ && w.reduceInPostLoop && !w.ranged() && !w.reductions.empty();
  for (const Reduction& r : w.reductions) {
    const std::string& op = plan_.equationDecls[r.equation->declIndex].reduceOp;
    if (op != "max" && op != "min") groupReduce = false;
  }
  auto reduceIsMax = [&](size_t i) {
    return plan_.equationDecls[w.reductions[i].equation->declIndex].reduceOp == "max";
  };
  auto groupSlot = [&](size_t i) { return std::to_string(kGroupReduceSlot + i); };
  auto groupPartial = [&](size_t i) {
    return "ocl.scratch(sphc::ocl::Context::groups(n), " + groupSlot(i) + ")";
  };
  // The kernel that computes them: in groups, every work item past its particle's work.
  auto groupBegin = [&]() {
    cl_ << "  __local real reduce_local[SPHC_GROUP];\n";
    for (size_t i = 0; i < w.reductions.size(); ++i)
      cl_ << "  real reduce_value_" << i << " = " << (reduceIsMax(i) ? "-INFINITY" : "INFINITY")
          << ";\n";
    cl_ << "  const int d_idx = get_global_id(0);\n  if (d_idx < n) {\n";
  };
  auto groupEnd = [&]() {
    cl_ << "  }\n";
    for (size_t i = 0; i < w.reductions.size(); ++i)
      cl_ << "  sphc_group_reduce(reduce_local, reduce_value_" << i << ", "
          << (reduceIsMax(i) ? 1 : 0) << ", reduce_partial_" << i << ");\n";
  };
  auto groupLaunch = [&](std::string l) {
    if (groupReduce) l.replace(0, std::string("ocl.run(").size(), "ocl.run_grouped(");
    return l;
  };
  auto particleWork = [&](ast::Method::Kind kind) -> const std::vector<const PlanEquation*>& {
    static const std::vector<const PlanEquation*> none;
    const bool init = kind == ast::Method::Initialize;
    // Moved by the schedule into a later phase's initialize kernel on the same array.
    if (init ? w.initializeMoved : w.postLoopMoved) return none;
    return init ? w.initialize : w.postLoop;
  };
  auto particleArgs = [&](ast::Method::Kind kind, KernelArgs& ka) {
    const bool init = kind == ast::Method::Initialize;
    if (init)
      for (const MovedWork& mw : w.initializeFirst)
        addBodyArgs(ka, methodBody(*mw.equation, mw.method), d, -1, eqStruct(*mw.equation));
    for (const auto* eq : particleWork(kind)) addBodyArgs(ka, methodBody(*eq, kind), d, -1, eqStruct(*eq));
    if (!init && w.reduceInPostLoop)
      for (size_t i = 0; i < w.reductions.size(); ++i) {
        const PlanEquation* eq = w.reductions[i].equation;
        addBodyArgs(ka, methodBody(*eq, ast::Method::Reduce), d, -1, eqStruct(*eq));
        if (groupReduce)
          ka.add("__global real* reduce_partial_" + std::to_string(i), groupPartial(i),
                 "reduce_partial_" + std::to_string(i));
        else
          ka.add("__global real* reduce_values_" + std::to_string(i), "ocl.scratch(n, " + reduceSlot(i) + ")",
                 "reduce_values_" + std::to_string(i));
      }
  };
  auto particleComments = [&](ast::Method::Kind kind) {
    if (kind == ast::Method::Initialize) {
      // Provenance of the fused work: the phases it comes from.
      for (const MovedWork& mw : w.initializeFirst)
        cl_ << "// fused: " << mw.equation->name << "." << (mw.method == ast::Method::Initialize ? "initialize" : "post_loop")
            << " of " << mw.phase << " (nothing between reads or writes " << D << ")\n";
    } else if (w.reduceInPostLoop) {
      cl_ << "// fused: the reductions' values of this phase\n";
    }
  };
  auto particleCalls = [&](ast::Method::Kind kind) {
    if (kind == ast::Method::Initialize)
      for (const MovedWork& mw : w.initializeFirst) cl_ << "  " << equationCall(*mw.equation, mw.method, d, "_");
    for (const auto* eq : particleWork(kind)) cl_ << "  " << equationCall(*eq, kind, d, "_");
    if (kind != ast::Method::Initialize && w.reduceInPostLoop)
      for (size_t i = 0; i < w.reductions.size(); ++i)
        cl_ << (groupReduce ? "  reduce_value_" + std::to_string(i) + " = "
                            : "  reduce_values_" + std::to_string(i) + "[d_idx] = ")
            << equationCall(*w.reductions[i].equation, ast::Method::Reduce, d, "_");
  };
  // The initialize kernel joins the first neighbour pass, and the post_loop kernel the last,
  // when that pass's source is another array: its kernel then reads and writes the
  // destination at d_idx only (the source's data are not written), so the per-particle work
  // of a work item before (after) its own neighbour loop is the separate kernel's, bit for
  // bit; both run over the same particles (rangeEnd, the same start_idx guard).
  auto ownKernelPass = [&](const NeighbourPass* p) {
    return fused_ && p && p->searches() && p->source != d;
  };
  const NeighbourPass* prologuePass =
      !w.passes.empty() && w.passes.front().initializePair.empty() && !particleWork(ast::Method::Initialize).empty()
          ? &w.passes.front() : nullptr;
  if (!ownKernelPass(prologuePass) || pulledOf(w)) prologuePass = nullptr;
  const NeighbourPass* epiloguePass =
      !w.passes.empty() && !particleWork(ast::Method::PostLoop).empty() ? &w.passes.back() : nullptr;
  if (!ownKernelPass(epiloguePass)) epiloguePass = nullptr;
  auto perParticle = [&](ast::Method::Kind kind, const char* what) {
    const bool init = kind == ast::Method::Initialize;
    const std::vector<const PlanEquation*>& with = init ? w.initialize : w.postLoop;
    if (with.empty()) return;
    if (init ? w.initializeMoved : w.postLoopMoved) {
      scene_ << "      // " << what << ": fused into the next initialize kernel on " << D << "\n";
      return;
    }
    if (init ? prologuePass != nullptr : epiloguePass != nullptr) {
      scene_ << "      // " << what << ": in the kernel of the neighbour pass " << D << " <- "
             << arr((init ? prologuePass : epiloguePass)->source).name << "\n";
      return;
    }
    const bool reduce = !init && w.reduceInPostLoop;
    const bool fusedFirst = init && !w.initializeFirst.empty();
    KernelArgs ka;
    particleArgs(kind, ka);
    std::string k = name + "_" + D + "_" + what;
    rangeArg(w, ka);
    particleComments(kind);
    const bool grouped = reduce && groupReduce;
    const bool dtLims = init && dtWorkOf(w);
    std::vector<std::pair<std::string, std::string>> lims;
    if (dtLims) {
      std::vector<std::string> props;
      KernelArgs probe = ka;  // the kernel's own buffers, by key
      auto own = [&](const std::string& p) {
        auto it = probe.at.find("d_" + p);
        if (it == probe.at.end()) return "dtl_" + p;
        const std::string& decl = probe.decls[it->second];
        const std::string o = " d_" + p;
        return decl.size() >= o.size() && decl.compare(decl.size() - o.size(), o.size(), o) == 0
                   ? "d_" + p : "dtl_" + p;
      };
      lims = dtLimits(d, props, own);
      for (const auto& p : props)
        if (own(p) != "d_" + p) ka.add("__global const real* dtl_" + p, devBuffer(d, p), "d_" + p);
      ka.add("__global real* dt_partial",
             "ocl.scratch(" + std::to_string(lims.size()) + " * sphc::ocl::Context::groups(n), " +
                 std::to_string(kDtSlot) + ")",
             "dt_partial");
      cl_ << "// fused: the adaptive time step's limits over " << D
          << " (nothing after this kernel in the step touches " << D << ")\n";
    }
    if (grouped || dtLims) cl_ << "__attribute__((reqd_work_group_size(SPHC_GROUP, 1, 1)))\n";
    beginKernel(k, ka, /*guard=*/!(grouped || dtLims));
    if (grouped) groupBegin();
    if (dtLims) {
      cl_ << "  __local real dt_local[SPHC_GROUP];\n";
      for (const auto& [lname, v] : lims) cl_ << "  real " << lname << " = INFINITY;\n";
      cl_ << "  const int d_idx = get_global_id(0);\n  if (d_idx < n) {\n";
    }
    rangeGuard(w);
    particleCalls(kind);
    if (grouped) groupEnd();
    if (dtLims) {
      cl_ << "  {  // the limits of adaptive_dt, after this kernel's work\n    const int i = d_idx;\n";
      if (sched_.adaptiveDt.force) cl_ << "    const real amag = " << dtAmag_ << ";\n";
      for (const auto& [lname, v] : lims) cl_ << "    " << lname << " = fmin(" << lname << ", " << v << ");\n";
      cl_ << "  }\n  }\n";
      for (size_t m = 0; m < lims.size(); ++m)
        cl_ << "  sphc_group_reduce(dt_local, " << lims[m].first << ", 0, dt_partial + " << m
            << " * get_num_groups(0));\n";
    }
    cl_ << "}\n\n";
    std::string l = launch(k, rangeEnd(w), ka);
    if (dtLims) l.replace(0, std::string("ocl.run(").size(), "ocl.run_grouped(");
    if (const Pulled* pl = init ? pulledOf(w) : nullptr) {
      const std::string f = "pulled_init[" + std::to_string(pl->flag) + "]";
      scene_ << "      if (" << f << ")  // done by the stepper run's kernel\n        " << f
             << " = false;\n      else\n  ";
    }
    scene_ << "      " << (grouped ? groupLaunch(l) : l) << "  // " << what
           << (fusedFirst ? " (with fused work of earlier phases)" : "")
           << (reduce ? " (with the reductions' values)" : "") << "\n";
    if (dtLims)
      scene_ << "      dt_rows_" << D << " = sphc::ocl::Context::groups(n);  // for adaptive_dt\n";
  };
  perParticle(ast::Method::Initialize, "initialize");
  for (const NeighbourPass& pass : w.passes) {
    const int s = pass.source;
    const std::string& S = arr(s).name;
    const std::set<std::string>& q = pass.pairQuantities;
    // PySPH's initialize_pair: a kernel per destination particle, before the neighbours.
    if (!pass.initializePair.empty()) {
      KernelArgs ia;
      for (const auto* eq : pass.initializePair)
        addBodyArgs(ia, methodBody(*eq, ast::Method::InitializePair), d, s, eqStruct(*eq));
      std::string k = name + "_" + D + "_from_" + S + "_initialize_pair";
      rangeArg(w, ia);
      beginKernel(k, ia);
      rangeGuard(w);
      for (const auto* eq : pass.initializePair)
        cl_ << "  " << equationCall(*eq, ast::Method::InitializePair, d, "_");
      cl_ << "}\n\n";
      scene_ << "      " << launch(k, rangeEnd(w), ia) << "  // initialize_pair: " << D
             << " <- " << S << "\n";
    }
    if (!pass.searches()) continue;
    KernelArgs ka;
    for (const auto* eq : pass.loopAll)
      addBodyArgs(ka, methodBody(*eq, ast::Method::LoopAll), d, s, eqStruct(*eq));
    for (const auto* eq : pass.equations)
      addBodyArgs(ka, plan_.bodies[plan_.equationDecls[eq->declIndex].methods.at(
                          ast::Method::Loop)],
                  d, s, eqStruct(*eq));
    // loop_all: each work item's neighbour list is private, of at most SPHC_MAX_NBRS entries;
    // the count goes to a scratch buffer, which the host checks after the launch.
    const bool all = !pass.loopAll.empty();
    if (all)
      ka.add("__global real* nbrs_count", "ocl.scratch(" + rangeEnd(w) + ", " + std::to_string(kNbrsSlot) + ")",
             "nbrs_count");
    for (const auto& p : pass.shared) {
      ka.add("__global const real* di_" + p, devBuffer(d, p), "di_" + p);
      ka.add("__global const real* sj_" + p, devBuffer(s, p), "sj_" + p);
    }
    const bool prologue = &pass == prologuePass, epilogue = &pass == epiloguePass;
    if (prologue) particleArgs(ast::Method::Initialize, ka);
    if (epilogue) particleArgs(ast::Method::PostLoop, ka);
    ka.add("SPHC_CELLS_ARGS(cells)", "cells_" + S, "cells");
    ka.add("SPHC_GRID_ARGS", "grid", "grid");
    std::string k = name + "_" + D + "_from_" + S;
    cl_ << "// neighbours: " << D << " <- " << S << "\n";
    if (prologue) {
      particleComments(ast::Method::Initialize);
      cl_ << "// fused: the initialize kernel of " << D << " (the pass reads " << D
          << " at d_idx only)\n";
    }
    if (epilogue) {
      particleComments(ast::Method::PostLoop);
      cl_ << "// fused: the post_loop kernel of " << D << " (the pass reads " << D
          << " at d_idx only)\n";
    }
    rangeArg(w, ka);
    if (all)
      cl_ << "#define SPHC_MAX_NBRS " << kMaxNbrs << "  // loop_all's neighbour list\n";
    const bool grouped = epilogue && groupReduce;
    if (grouped) cl_ << "__attribute__((reqd_work_group_size(SPHC_GROUP, 1, 1)))\n";
    beginKernel(k, ka, /*guard=*/!grouped);
    if (grouped) groupBegin();
    if (all && w.ranged())
      cl_ << "  if (d_idx < d_begin) { nbrs_count[d_idx] = 0; return; }  // start_idx\n";
    else
      rangeGuard(w);
    if (prologue) particleCalls(ast::Method::Initialize);
    emitDestLocals(cl_, "  ", q, device_);
    // The 3^dim cells around the particle's cell, by z, y, x (the CPU candidate order).
    const char* axes[3] = {"x", "y", "z"};
    for (int a = 0; a < 3; ++a)
      cl_ << "  const int c" << axes[a] << " = "
          << (a < plan_.dim ? std::string("sphc_axis_cell((") + axes[a] + "i - grid_lo" +
                                  axes[a] + ") * grid_inv, grid_n" + axes[a] + ")"
                            : std::string("0"))
          << ";\n";
    const std::string cellLoops =
        "  for (int kz = max(cz - 1, 0); kz <= min(cz + 1, grid_nz - 1); ++kz)\n"
        "  for (int ky = max(cy - 1, 0); ky <= min(cy + 1, grid_ny - 1); ++ky)\n"
        "  for (int kx = max(cx - 1, 0); kx <= min(cx + 1, grid_nx - 1); ++kx) {\n"
        "    const int cell = (kz * grid_ny + ky) * grid_nx + kx;\n"
        "    for (uint k = cells_start[cell]; k < cells_end[cell]; ++k) {\n"
        "            const int s_idx = (int)cells_order[k];\n";
    if (all) {
      // The neighbour list in candidate order (the CPU's), every loop_all with it.
      cl_ << "  uint NBRS[SPHC_MAX_NBRS];\n  int found = 0;\n" << cellLoops;
      emitNeighbourTest(cl_, device_, "continue;", "            ");
      cl_ << "            if (found < SPHC_MAX_NBRS) NBRS[found] = (uint)s_idx;\n"
          << "            ++found;\n    }\n  }\n";
      cl_ << "  nbrs_count[d_idx] = (real)found;  // checked on the host\n";
      cl_ << "  const int N_NBRS = min(found, SPHC_MAX_NBRS);\n";
      for (const auto* eq : pass.loopAll)
        cl_ << "  " << equationCall(*eq, ast::Method::LoopAll, d, "_");
    }
    if (!pass.equations.empty()) {
      cl_ << cellLoops;
      emitCandidate(cl_, q, pass.equations, d, device_);
      cl_ << "    }\n  }\n";
    }
    if (epilogue) particleCalls(ast::Method::PostLoop);
    if (grouped) groupEnd();
    cl_ << "}\n";
    if (all) cl_ << "#undef SPHC_MAX_NBRS\n";
    cl_ << "\n";
    const std::string l = launch(k, rangeEnd(w), ka);
    scene_ << "      " << (grouped ? groupLaunch(l) : l) << "  // neighbours: " << D << " <- " << S
           << (prologue ? ", after initialize" : "") << (epilogue ? ", then post_loop" : "")
           << "\n";
    if (all)
      scene_ << "      sphc::ocl::check_neighbour_lists(ocl, ocl.scratch(" << rangeEnd(w)
             << ", " << kNbrsSlot << "), " << rangeEnd(w) << ", " << kMaxNbrs << ", \"" << D << " <- " << S
             << "\");  // loop_all\n";
  }
  perParticle(ast::Method::PostLoop, "post_loop");
  // Reductions: per-particle values on the device, partial results there, the last step
  // on the host, into the host copy of the constant (uploaded again).
  for (size_t ri = 0; ri < w.reductions.size(); ++ri) {
    const Reduction& r = w.reductions[ri];
    const PlanEquation* eq = r.equation;
    const auto& pd = plan_.equationDecls[eq->declIndex];
    const PlanBody& b = plan_.bodies[pd.methods.at(ast::Method::Reduce)];
    // Reductions see the real particles only (never the ghosts of a non-real group).
    const std::string nReal = onGhosts ? "static_cast<int>(" + D + ".n)" : std::string("n");
    const std::string values = "ocl.scratch(" + nReal + ", " + reduceSlot(ri) + ")";
    int c = constIndex(d, pd.reduceTarget);
    std::string op = pd.reduceOp == "sum" || pd.reduceOp == "mean" ? "Sum"
                     : pd.reduceOp == "max"                         ? "Max"
                                                                    : "Min";
    scene_ << "      {  // reduce " << pd.reduceOp << " into " << D << "." << pd.reduceTarget
           << ": " << eq->name << ", from " << loc(eq->loc) << "\n";
    if (!w.reduceInPostLoop) {
      KernelArgs ka;
      addBodyArgs(ka, b, d, -1, eqStruct(*eq));
      ka.add("__global real* reduce_values", values, "reduce_values");
      std::string k = name + "_" + D + "_reduce_" + std::to_string(eq->id);
      beginKernel(k, ka);
      cl_ << "  reduce_values[d_idx] = " << equationCall(*eq, ast::Method::Reduce, d, "_")
          << "}\n\n";
      scene_ << "        " << launch(k, nReal, ka) << (onGhosts ? "  // real particles only" : "")
             << "\n";
    } else if (groupReduce) {
      scene_ << "        // the work groups' results: from the post_loop's kernel\n";
      scene_ << "        " << D << ".constant(" << constSlot(d, c) << ")[0] = ocl.reduce_groups("
             << groupPartial(ri) << ", sphc::ocl::Context::groups(n), sphc::ocl::Op::" << op
             << ");\n";
      scene_ << "        dev_" << D << ".upload_constant(ocl, " << D << ", " << constSlot(d, c) << ");\n";
      scene_ << "      }\n";
      continue;
    } else {
      scene_ << "        // the values: from the post_loop kernel\n";
    }
    scene_ << "        " << D << ".constant(" << constSlot(d, c) << ")[0] = ocl.reduce(" << values
           << ", " << nReal << ", sphc::ocl::Op::" << op << ")"
           << (pd.reduceOp == "mean" ? " / (" + nReal + " > 0 ? " + nReal + " : 1)" : "")
           << ";\n";
    scene_ << "        dev_" << D << ".upload_constant(ocl, " << D << ", " << constSlot(d, c) << ");\n";
    scene_ << "      }\n";
  }
  emitHostReduces(w);
  ghostRefresh(w);
}

// A run of stepper statements (the schedule's StepperRun): per array one kernel doing the
// run's methods in turn on each particle, each at its statement's time t_<k> (steppers read
// and write their own particle only, so this equals a kernel per method, bit for bit).
// Where the run is followed by a neighbour update (foldsExtents), each array's kernel also
// computes the search domain's extents of its particles after its stepper bodies
// (sphc_extent_group, in work groups of Context::kGroup items), which saves the update's
// extents kernel: the update reads the rows of partial results (Context::grid_of_extents).
void OpenCLPrinter::steppers() {
  computePulled();
  for (size_t ri = 0; ri < sched_.stepperRuns.size(); ++ri) {
    const StepperRun& run = sched_.stepperRuns[ri];
    if (run.parts.empty()) continue;
    const bool fold = foldsExtents(static_cast<int>(ri));
    const int seq = runSequence(static_cast<int>(ri));
    bool pulls = false;
    for (const StepperRun::Part& part : run.parts) pulls |= seq > 0 && pulled_[seq - 1].count(part.array);
    scene_ << "  void " << run.name << "(";
    for (size_t k = 0; k < run.methods.size(); ++k) scene_ << "double t_" << k << ", ";
    if (pulls) scene_ << "double t_eval, ";
    scene_ << "double dt) {\n";
    std::string rows;  // the rows of every array's groups, as an expression
    if (fold) {
      scene_ << "    // The search domain's extents, computed by these kernels for the neighbour update\n"
             << "    // that follows (a row of partial results per work group).\n";
      for (const StepperRun::Part& part : run.parts) {
        if (!loopArrays_.count(arr(part.array).name)) continue;
        const std::string& A = arr(part.array).name;
        scene_ << "    const std::size_t rows_" << A << " = sphc::ocl::Context::groups(" << A
               << ".n);\n";
      }
      for (const StepperRun::Part& part : run.parts)
        if (loopArrays_.count(arr(part.array).name))
          rows += (rows.empty() ? "" : " + ") + std::string("rows_") + arr(part.array).name;
      scene_ << "    cl_mem extents = ocl.scratch(7 * (" << rows << "), " << kExtentSlot << ");\n";
    } else if (anyFoldsExtents()) {
      scene_ << "    extent_rows = 0;  // positions may change: the update computes its extents\n";
    }
    std::string rowBefore = "0";  // the rows of the arrays before this one
    // A statement's time is unused when no array's stepper has its method.
    for (size_t k = 1; k < run.methods.size(); ++k) {
      bool used = false;
      for (const auto& part : run.parts)
        for (const auto& [j, b] : part.bodies) used |= j == k;
      if (!used) scene_ << "    (void)t_" << k << ";\n";
    }
    for (const StepperRun::Part& part : run.parts) {
      const PlanArray& A = arr(part.array);
      const std::string& stepper = part.stepper->decl->name.name;
      std::string methods;
      for (size_t i = 0; i < part.bodies.size(); ++i)
        methods += (i ? ", " : ".") + run.methods[part.bodies[i].first];
      scene_ << "    {  // " << A.name << ": " << stepper << methods << "\n";
      scene_ << "      const int n = static_cast<int>(" << A.name << ".n);\n";
      KernelArgs ka;
      for (const auto& [k, b] : part.bodies) {
        const std::string tk = "t_" + std::to_string(k);
        if (k > 0) ka.add("const real " + tk, tk, tk);  // t_0 is the kernel's t
        addBodyArgs(ka, *b, part.array, -1, "");
      }
      const Pulled* pl = seq > 0 && pulled_[seq - 1].count(part.array) ? &pulled_[seq - 1].at(part.array) : nullptr;
      if (pl) {
        ka.add("const real t_eval", "t_eval", "t_eval");
        initializeArgs(*pl->work, ka);
      }
      const bool extents = fold && loopArrays_.count(A.name);
      const char* axes[3] = {"x", "y", "z"};
      if (extents) {
        for (int a = 0; a < plan_.dim; ++a)
          ka.add(std::string("__global const real* ext_") + axes[a], devBuffer(part.array, axes[a]),
                 std::string("d_") + axes[a]);
        ka.add("__global const real* ext_h", devBuffer(part.array, "h"), "d_h");
        ka.add("__global real* extent_partial", "extents", "extent_partial");
        ka.add("const uint extent_row", "static_cast<unsigned>(" + rowBefore + ")", "extent_row");
      }
      std::string kn = run.name + "_" + A.name;
      cl_ << "// " << A.name << ": " << stepper << methods << " (a run of the step)"
          << (extents ? ", then the extents of its particles" : "") << "\n";
      if (pl)
        cl_ << "// fused: the initialize kernel of " << pl->phase << " on " << A.name
            << " (after the neighbour update, which it does not read)\n";
      if (extents) {
        cl_ << "__attribute__((reqd_work_group_size(SPHC_GROUP, 1, 1)))\n";
        beginKernel(kn, ka, /*guard=*/false);
        cl_ << "  __local real extent_local[7 * SPHC_GROUP];\n"
               "  const int d_idx = get_global_id(0);\n"
               "  if (d_idx < n) {\n";
      } else {
        beginKernel(kn, ka);
      }
      const std::string in = extents ? "    " : "  ";
      for (const auto& [k, b] : part.bodies)
        cl_ << in
            << callBody(bodyFunctionName(stepper, run.methods[k]), *b, part.array, "",
                        k == 0 ? std::string("t") : "t_" + std::to_string(k), "_")
            << ";\n";
      if (pl) cl_ << initializeCalls(*pl->work, "t_eval", in);
      if (extents) {
        // The kernel's own buffer of an axis, else the argument added above.
        auto buf = [&](const std::string& p) {
          const std::string& decl = ka.decls[ka.at.at("d_" + p)];
          const std::string own = " d_" + p;
          return decl.size() >= own.size() && decl.compare(decl.size() - own.size(), own.size(), own) == 0
                     ? "d_" + p : "ext_" + p;
        };
        cl_ << "  }\n  sphc_extent_group(d_idx < n, " << plan_.dim << ", d_idx, " << buf("x") << ", "
            << (plan_.dim > 1 ? buf("y") : buf("x")) << ", " << (plan_.dim > 2 ? buf("z") : buf("x"))
            << ", " << buf("h") << ", extent_local, extent_partial + 7 * extent_row);\n";
      }
      cl_ << "}\n\n";
      // The kernel's t is the run's first statement's time.
      if (extents) {
        std::string l = launch(kn, "n", ka, "t_0");
        l.replace(0, std::string("ocl.run(").size(), "ocl.run_grouped(");
        scene_ << "      " << l << "\n";
        rowBefore = rowBefore == "0" ? "rows_" + A.name : rowBefore + " + rows_" + A.name;
      } else {
        scene_ << "      " << launch(kn, "n", ka, "t_0") << "\n";
      }
      if (pl)
        scene_ << "      pulled_init[" << pl->flag << "] = true;  // " << pl->phase
               << "'s initialize on " << A.name << "\n";
      scene_ << "    }\n";
    }
    if (fold) scene_ << "    extent_rows = " << rows << ";\n";
    scene_ << "  }\n\n";
  }
}

std::string OpenCLPrinter::deviceExtents(const std::string& indent) const {
  const char* axes[3] = {"x", "y", "z"};
  auto buf = [&](int a, int k) {
    return k < plan_.dim ? devBuffer(a, axes[k]) : std::string("nullptr");
  };
  std::string r = "{";
  bool first = true;
  for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a) {
    if (!loopArrays_.count(arr(a).name)) continue;
    r += (first ? "" : ",\n" + indent) + "{" + buf(a, 0) + ", " + buf(a, 1) + ", " + buf(a, 2) +
         ", " + devBuffer(a, "h") + ", " + arr(a).name + ".n}";
    first = false;
  }
  return r + "}";
}

// The same on the device (--backend=opencl): the search domain of the real particles from
// device reductions, the cell-order permutation of the real particles on the device, then the
// ghost list of every source found on the host from its downloaded positions (the CPU's
// find_ghosts, so the same ghosts in the same order), the ghost slots filled on the device,
// and the cell tables over real particles and ghosts on the widened grid.
void OpenCLPrinter::updateNeighboursWithGhosts() {
  scene_ << "    sphc::SearchDomain domain = ocl.search_domain(" << deviceExtents("        ")
         << ", DIM, Kernel::radius_scale);\n";
  scene_ << "    grid = ocl.grid_of(domain);\n";
  if (sourceArrays_.empty()) return;
  scene_ << "    // Every REORDER_EVERY builds the real particles are sorted in cell order.\n";
  scene_ << "    if (builds++ % REORDER_EVERY == 0) {\n";
  for (const auto& S : sourceArrays_)
    if (reorders(S))
      scene_ << "      " << cellListBuild(S, S + ".n") << "\n      dev_" << S
             << ".permute(ocl, cells_" << S << ", " << S << ");\n";
  scene_ << "    }\n";
  scene_ << "    // Ghosts within the largest interaction radius of a periodic or mirror side.\n";
  scene_ << "    const double cutoff = domain.cell_size;\n";
  for (const auto& S : sourceArrays_) {
    int s = plan_.arrayIndex(S);
    scene_ << "    ghosts_" << S << ".add(ocl, box, " << S << ", dev_" << S << ", cutoff, "
           << propIndexList(s, arr(s).ghostProps) << ");  //";
    for (const auto& p : arr(s).ghostProps) scene_ << " " << p;
    scene_ << "\n";
  }
  scene_ << "    sphc::extend_for_ghosts(domain, box, cutoff);\n";
  scene_ << "    grid = ocl.grid_of(domain);\n";
  std::vector<std::pair<std::string, std::string>> withGhosts;
  for (const auto& S : sourceArrays_) withGhosts.push_back({S, S + ".n + ghosts_" + S + ".size()"});
  scene_ << cellTablesBuild(withGhosts, "    ");
}

// Ghosts copy the values a phase computed on the real particles, where they carry them.
void OpenCLPrinter::ghostRefresh(const DestinationWork& w) {
  if (!ghostsFollow(w)) return;
  const int d = w.array;
  const std::string& D = arr(d).name;
  const std::vector<std::string>& refresh = w.ghostRefresh;
  scene_ << "\n      ghosts_" << D << ".refresh(ocl, box, " << D << ", dev_" << D << ", "
         << propIndexList(d, refresh) << ");\n";
}

// The adaptive time step's limits over one moving array in one launch: each of
// Context::kPartials work items takes the minima of the limits over its particles (i = g,
// g + G, ...), the host the minima of those (fmin, as sphc_reduce: the same values).
void OpenCLPrinter::adaptiveDtArray(int a) {
  const AdaptiveDt& ad = sched_.adaptiveDt;
  const std::string& A = arr(a).name;
  KernelArgs ka;
  std::vector<std::string> props;
  // The limits the scene uses, in order: (name, per-particle value).
  const std::vector<std::pair<std::string, std::string>> limits =
      dtLimits(a, props, [](const std::string& p) { return p; });
  const std::string amag = dtAmag_;
  for (const auto& p : props) ka.add("__global const real* " + p, devBuffer(a, p), p);
  if (limits.empty()) {
    scene_ << "    }\n";
    return;
  }
  const std::string partial =
      "ocl.scratch(" + std::to_string(limits.size()) + " * sphc::ocl::Context::kPartials, 1)";
  ka.add("__global real* partial", partial, "partial");
  std::string k = "adaptive_dt_" + A;
  cl_ << "// adaptive dt over " << A << ": partial minima per work item\n";
  beginKernel(k, ka, /*guard=*/false);
  cl_ << "  const int g = get_global_id(0), G = get_global_size(0);\n";
  for (const auto& [name, v] : limits) cl_ << "  real " << name << " = INFINITY;\n";
  cl_ << "  for (int i = g; i < n; i += G) {\n";
  if (ad.force) cl_ << "    const real amag = " << amag << ";\n";
  for (const auto& [name, v] : limits) cl_ << "    " << name << " = fmin(" << name << ", " << v << ");\n";
  cl_ << "  }\n";
  for (size_t m = 0; m < limits.size(); ++m)
    cl_ << "  partial[" << limits.size() << " * g + " << m << "] = " << limits[m].first << ";\n";
  cl_ << "}\n\n";
  scene_ << "      const int n = static_cast<int>(" << A << ".n);\n";
  std::string in = "      ";
  computeDtWork();
  const bool fused = dtWork_.count(a) > 0;
  if (fused) {
    const std::string L = std::to_string(limits.size());
    scene_ << "      std::vector<double> mins;\n";
    scene_ << "      if (dt_rows_" << A << " > 0) {  // from the step's last kernel on " << A << "\n";
    scene_ << "        mins = ocl.minima_rows(ocl.scratch(" << L << " * dt_rows_" << A << ", "
           << kDtSlot << "), dt_rows_" << A << ", " << L << ");\n";
    scene_ << "        dt_rows_" << A << " = 0;\n      } else {\n";
    in = "        ";
  }
  scene_ << in << "const double t = 0.0, dt = 0.0;  // (kernel arguments, unused)\n";
  std::string l = "ocl.run(\"" + k + "\", sphc::ocl::Context::kPartials, n, t, dt";
  for (const auto& h : ka.host) l += ", " + h;
  scene_ << in << l << ");\n";
  if (fused)
    scene_ << in << "mins = ocl.minima(" << partial << ", " << limits.size() << ");\n      }\n";
  else
    scene_ << "      const std::vector<double> mins = ocl.minima(" << partial << ", "
           << limits.size() << ");\n";
  for (size_t m = 0; m < limits.size(); ++m)
    scene_ << "      " << limits[m].first << " = std::fmin(" << limits[m].first << ", mins[" << m
           << "]);\n";
  scene_ << "    }\n";
}

}  // namespace

std::unique_ptr<ScenePrinter> makeOpenCLPrinter(const Schedule& sched,
                                                const DiagnosticEngine& diags,
                                                const EmitOptions& opts) {
  return std::make_unique<OpenCLPrinter>(sched, diags, opts);
}

}  // namespace sphc
