// The printers of the back half (internal to codegen/). ScenePrinter prints what every
// backend shares: the file's header, the equation and stepper bodies, the scene's
// parameters and set-up, the group functions and their iteration, the integrator's step and
// `main`. Where the execution differs — the loops of a phase's destination, the steppers,
// the neighbour search, ghosts, the adaptive time step, data movement — it calls a hook that
// each backend's printer implements: CpuPrinter (serial and OpenMP, which differ by pragmas
// only: CpuPrinter.cpp) and OpenCLPrinter (kernels and their host launches:
// OpenCLPrinter.cpp). All of them read the decisions from the Schedule and decide nothing
// but spellings.
#pragma once

#include "body/TextEdits.h"
#include "codegen/CppEmitter.h"
#include "codegen/CppText.h"
#include "codegen/Schedule.h"

#include <functional>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace sphc {

// The few spellings in which the C++ of the CPU backends and the OpenCL C of the kernels
// differ, so that bodies, pair quantities and their calls are written once.
struct Dialect {
  std::string real;                  // the floating type: double, float (CPU single), real
  std::string intType, uintType;     // std::int32_t, std::uint32_t / int, uint
  std::string global;                // pointer qualifier: "" / "__global "
  std::string functionPrefix;        // "static inline " / "inline "
  std::string kernelW, kernelGradient, sqrt;  // Kernel::w ... / kernel_w ...
  std::string skipCandidate;         // leaves a neighbour candidate: return; (a lambda) / continue;
  std::string scalarSep;             // eq3.rho0 (host struct) / eq3_rho0 (kernel argument)
  bool floatLiterals = false;        // 0.5f (CPU single precision)
  bool floatBodies = false;          // bodies rewritten by singlePrecisionBody
  // `#line N "file.sph"` before each body and `#line M "<lineFile>"` after it, so that
  // compiler messages and debuggers point at the .sph line (lineFile: the generated file,
  // as the build names it: scene.cpp in the build cache, <scene>.cl for the kernels).
  bool lineDirectives = false;
  std::string lineFile;
  // The fused multiply-add that bodies' products added to values are printed as
  // (codegen/FusedMultiplyAdd.h): std::fma / fma; empty: printed as written (--fma=off).
  std::string fma;
  // Loop bodies read their source-only values from per-particle arrays (codegen/Hoist.cpp).
  bool hoist = false;
  std::string lit(const std::string& v) const { return floatLiterals ? v + "f" : v; }
};

// For one pair loop: its accumulated d_ properties, each with its stride and the components
// the bodies update (empty: the sums stay in memory, `refusal` says why; RegisterSums.cpp).
struct RegisterSums {
  std::map<std::string, std::pair<int, std::set<int>>> props;  // name -> stride, components
  std::string refusal;
  bool active() const { return !props.empty(); }
};

// Text helpers of the functions printed beside a body (Hoist.cpp, PairShared.cpp):
// text[begin, end) with the multiply-adds inside it fused as in the whole body; an
// expression on one line (for a comment); the end of a statement after an expression.
std::string fusedRange(const std::string& text, const BodyFacts& f, unsigned begin, unsigned end,
                       const std::string& fma);
std::string oneLine(const std::string& text);
std::string endStatement(const std::string& expr);

struct PairDialect;  // analysis/PairQuantityTable.h
struct PairQuantity;  // analysis/PairQuantityTable.h
// The spellings the pair-quantity statements take in a dialect (codegen/Bodies.cpp).
PairDialect pairDialectOf(const Dialect& dl);
// The vector pair quantities of a body's text as scalars (SimdPairs.cpp): an edit
// `XIJ[k]` -> `XIJ_k` per indexing by a literal k < 3, appended to `edits`; false (and `why`)
// where one is named otherwise (a pointer passed on, a computed index).
bool scalarPairEdits(const std::string& text, std::vector<TextEdit>& edits, std::string& why);
// The calls in a body's text of the math functions GCC does not vectorise without
// -ffast-math (pow, exp, ...; SimdPairs.cpp): each function name's [begin, end).
std::vector<std::pair<unsigned, unsigned>> scalarMathCallSites(const std::string& text);

class ScenePrinter {
 public:
  ScenePrinter(const Schedule& sched, const DiagnosticEngine& diags, const EmitOptions& opts);
  virtual ~ScenePrinter() = default;
  // The whole C++ file of the solver.
  std::string run();
  // The OpenCL C of the kernels alone (--emit=opencl; empty for a CPU printer): the bodies
  // and scene functions printed, without the host program around them.
  std::string kernelSource();
  // --report's notes on the pair loops (SymmetricPairs.cpp): each pair once or per
  // destination, and why, as this printer prints them.
  std::vector<std::string> pairLoopNotes(const EmitOptions& opts) const;

 protected:
  // ---- What each backend prints (hooks) ----
  virtual std::string backendComment() const = 0;   // after "// Backend: "
  virtual void runtimeIncludes() {}                 // sphc headers of the backend
  virtual void systemIncludes() {}                  // <omp.h>, ...
  // Where the body of an equation method or stepper runs: its dialect and stream.
  virtual bool bodyOnDevice(bool converged) const { return false; }
  // The loop bodies some pair loop calls for (d_idx, s_idx) and mirrored for (s_idx, d_idx)
  // in one iteration (each pair once; codegen/PairShared.cpp uses values of those only).
  virtual std::set<const PlanBody*> pairSharedBodies() const { return {}; }
  virtual void deviceKernelFunctions() {}
  virtual void devicePowFunction() {}  // sphc::pow_int in the kernels' language
  virtual void beforeScene() {}                     // before "The scene" (OpenCL: SCENE_CL)
  virtual void searchMembers() = 0;                 // neighbour search state of struct Scene
  virtual std::string ghostsType() const = 0;
  virtual void extraMembers() {}                    // after the ghosts (OpenMP scratch)
  virtual bool timesNeighbourSearch() const = 0;    // nnps_seconds for --timing
  // group_seconds for --timing: the wall time of each top-level group (the CPU backends:
  // their groups run synchronously; OpenCL's kernels do not, so it does not time them).
  virtual bool timesGroups() const { return timesNeighbourSearch(); }
  virtual void dataMovement() {}                    // to_device/to_single, to_host
  // One destination of a phase, after `const int n = ...;` (its ghost refresh included).
  virtual void destination(const DestinationWork& w, const std::string& phase) = 0;
  // After the phase function's opening line, before its destinations.
  virtual void phasePrologue(const Phase& ph) {}
  // Before a `converged` test reads properties on the host.
  virtual void beforeConverged(const PlanEquation& eq) {}
  // After a `converged` test wrote the array constant of index c on the host.
  virtual void afterConverged(const PlanEquation& eq, int c) {}
  virtual void steppers() = 0;
  // One run of stepper statements in step(), with the time of each statement.
  virtual void stepperCall(const StepStatement& st,
                           const std::function<std::string(int)>& timeAfter) = 0;
  virtual void wrapPeriodic(int a) = 0;             // update_domain, per array
  virtual void updateNeighbours() = 0;              // its body, without a domain
  virtual void staticCellLists() {}  // members it calls, before it (CPU: build_static_cells)
  virtual void updateNeighboursWithGhosts() = 0;    // its body, with one
  virtual std::string removeGhosts() const = 0;
  // compute_accelerations, before update_domain: the CPU printer's kept ghosts wrap every
  // particle into the box before an evaluation where a group reading positions runs
  // (analysis/PositionReads.cpp).
  virtual std::string wrapBeforeEvaluation() const { return ""; }
  virtual void timedNeighbourUpdate() = 0;
  virtual void adaptiveDtArray(int a) = 0;          // the limits of one moving array
  virtual void mainPrologue() {}                    // before `static Scene scene;`
  // --omp-min-particles: the `if (COUNT >= OMP_MIN_PARTICLES)` clause of a loop without
  // neighbours ("" where there is none: serial, or the option 0).
  virtual std::string ompMinIf(const std::string& count) const { return ""; }
  virtual void mainBackendOptions() {}              // prog.set_threads, device selection
  virtual std::string afterSetup() const { return ""; }  // "    if (!sphc::counting_particles()) scene.to_device();\n"
  virtual bool hasToHost() const { return false; }
  // --restart: the statements that move the restored host arrays to where the scene computes
  // on them (OpenCL: uploads; --precision=single: the float copies); "" where they are it.
  virtual std::string restoreData() const { return ""; }
  // --restartable: the statements (in main, on `scene.`) run after each output is written
  // (prog.restart_point) that start afresh the state a restart cannot read from the file, as a
  // run restarted from it starts it (the cluster-pair tiles' layout and sort bookkeeping:
  // CpuPrinter); "" where there is none.
  virtual std::string restartPoint() const { return ""; }
  // A limit's `remove` took particles out of the host array a (the run loop, sphc/sanity.h):
  // the statements (in main, on `scene.`) that move it back where the scene computes and
  // forget what depended on its particles; "" where nothing does (kept lists are rebuilt when
  // a count changes).
  virtual std::string afterRemoval(int a) const { return ""; }
  // The inlet/outlet step runs on the host: the arrays it resizes come to the host before
  // it and go back to where the scene computes after it (their new sizes included).
  virtual void arraysToHost(const std::vector<int>& arrays) {}
  virtual void arraysFromHost(const std::vector<int>& arrays) {}
  // A backend whose data is elsewhere may first bring the positions only (positionsToHost)
  // and, when no particle is due to move (sphc::inlet_outlet_due), send back the inlets'
  // new velocities only (inletVelocitiesFromHost): the whole arrays travel only on steps
  // where particles change arrays.
  virtual bool checksZonesFirst() const { return false; }
  virtual void positionsToHost(const std::vector<int>& arrays) {}
  virtual void inletVelocitiesFromHost(const std::vector<int>& inletArrays) {}

  // ---- Bodies, their parameters and calls (Bodies.cpp) ----
  // Parameters of a body function, in order, as (C++ declaration, argument kind) pairs.
  struct BodyParam {
    std::string decl;  // e.g. "const double* s_m"
    enum Kind { Idx, SIdx, T, Dt, Pair, Scalar, DProp, SProp, Nbrs, NNbrs, N, Hoisted,
                DHoisted, PairShared } kind;
    std::string name;  // property, pair quantity or scalar name; Hoisted: the site's number
  };
  // The body-parameter types: what each property, pair quantity and scalar is declared as.
  std::vector<BodyParam> bodyParams(const PlanBody& b, int destArray, const Dialect& d) const;
  void emitBodyFunction(const PlanBody& b, const std::string& name, const std::string& ret,
                        int destArray, const Dialect& d, std::ostringstream& os);
  std::string bodyText(const PlanBody& b, const Dialect& d) const;
  void emitKernelFunctions();
  // pow(x, y) of the bodies as sphc::pow_int (--int-pow, CPU double precision): whether it is
  // emitted (some body calls pow), and its definition, with the kernel functions.
  bool intPowUsed() const;
  void emitPowFunction();
  void emitHelperFunction(const PlanBody& f, const Dialect& d, std::ostringstream& os);
  // eqValues + sep + scalar: "eq3.rho0" on the host, "eq3_rho0" (a kernel argument) on the
  // device.
  // argument(p), where given and not empty, replaces a parameter's usual argument (the
  // mirrored calls of SymmetricPairs.cpp swap the indices and mirror the pair quantities).
  std::string callBody(const std::string& fn, const PlanBody& b, int dest,
                       const std::string& eqValues, const std::string& time,
                       const std::string& sep = ".",
                       const std::function<std::string(const BodyParam&)>& argument = {}) const;
  // callBody's argument for a parameter without `argument`'s.
  std::string callBodyDefault(const BodyParam& p, const std::string& eqValues,
                              const std::string& time, const std::string& sep) const;
  // The destination particle's position, h (and velocity) as locals xi, yi, zi, hi (ui...).
  void emitDestLocals(std::ostream& os, const std::string& indent,
                      const std::set<std::string>& q, const Dialect& d) const;
  // The body of the neighbour loop for one candidate s_idx: the pair quantities and the
  // neighbour criterion (emitPairQuantities), then every loop body. Shared by the C++ loop
  // and the OpenCL kernel. test = false: for a neighbour already tested (the CPU loops over a
  // gathered neighbour list), the quantities without the cut-off test.
  void emitCandidate(std::ostream& os, const std::set<std::string>& q,
                     const std::vector<const PlanEquation*>& loopers, int d, const Dialect& dl,
                     bool test = true, const RegisterSums* sums = nullptr,
                     const std::string& skip = "");
  // loop_all: the neighbour test of one candidate s_idx (hj, XIJ, R2IJ and the cut-off,
  // leaving with `skip`), before it joins the neighbour list. `radius2`: the squared radius
  // in units of hmax (RADIUS2, the support; VERLET_RADIUS2 for the lists of --verlet-skin).
  void emitNeighbourTest(std::ostream& os, const Dialect& dl, const std::string& skip,
                         const std::string& indent, const std::string& radius2 = "RADIUS2");
  // What the test reads of candidate s_idx: hj and the quantities before it (XIJ, R2IJ).
  void emitTestOperands(std::ostream& os, const Dialect& dl, const std::string& indent) const;
  // The pair quantities of one candidate (XIJ, R2IJ, the cut-off test, HIJ, RIJ, ...); the
  // test leaves with `skip` (empty: the dialect's skipCandidate).
  void emitPairQuantities(std::ostream& os, const std::set<std::string>& q, const Dialect& dl,
                          bool test = true, const std::string& skip = "");
  void emitLineDirective(std::ostringstream& os, llvm::SMLoc l) const;
  void resetLineDirective(std::ostringstream& os, const Dialect& d) const;
  // A property's type in a dialect (constants and floating properties: its real).
  std::string propType(int array, const std::string& prop, const Dialect& d) const;

  // ---- Values a pair shares, computed once for both particles (PairShared.cpp) ----
  // The sites of a loop body (BodyFacts::pairShared) the printer uses: none unless
  // pairShared_ and d.hoist; of properties no pair loop writes.
  std::vector<SourceOnlySite> pairSharedSites(const PlanBody& b, const Dialect& d) const;
  // Stage two of hoistedBodyText: each site replaced by `pair_sharedK` (an `if` site by
  // `NAME = pair_sharedK;`), `text` and `facts` already moved by the other edits.
  void replacePairShared(const PlanBody& b, const Dialect& d, std::string& text,
                         BodyFacts& facts) const;
  // After a loop body's function `name`: NAME_pairsharedK(...) per site, the body's
  // parameters but the written properties, returning the site's value for (d_idx, s_idx).
  void emitPairSharedFunctions(const PlanBody& b, const std::string& name, int destArray,
                               const Dialect& d, std::ostringstream& os) const;
  // The parameters of those functions (bodyParams without pair_sharedK and written d_).
  std::vector<BodyParam> pairSharedParams(const PlanBody& b, int destArray, const Dialect& d) const;
  // In a pair loop that calls `direct` for (d_idx, s_idx) and `mirrored` for (s_idx, d_idx):
  // the locals `pshared_eqN_K` of the values both share, computed once, and the scope that
  // makes callBody pass them (pairSharedScope_); endPairShared clears it.
  // `simd`: in SIMD lanes, by the functions' _simd forms (scalar pair components, dval_).
  void emitPairSharedLocals(std::ostream& os, const std::string& indent, int dest,
                            const std::vector<const PlanEquation*>& direct,
                            const std::vector<const PlanEquation*>& mirrored,
                            bool simd = false) const;
  // The _simd forms of b's NAME_pairsharedK (NAME_pairsharedK_simd), for SIMD lanes.
  void emitPairSharedSimdFunctions(const PlanBody& b, const std::string& name, int destArray,
                                   std::ostringstream& os) const;
  void printPairShared(const PlanBody& b, const std::string& name, int destArray,
                       const Dialect& d, bool simd, std::ostringstream& os) const;
  void endPairShared() const { pairSharedScope_.clear(); }
  // A value computed once for the pair: its local, and 1 or -1 (the mirrored calls pass "-"
  // before the local of an antisymmetric one).
  struct PairSharedLocal {
    std::string local;
    int sign = 1;
  };
  mutable std::map<std::string, PairSharedLocal> pairSharedScope_;  // eqValues + "/" + K
  bool pairShared_ = false;  // EmitOptions::pairShared (CPU double, not mpi, not --simd-pairs)
  bool skipSelfPairs_ = false;  // EmitOptions::skipSelfPairs (SymmetricPairs.cpp)
  bool filteredLists_ = false;  // EmitOptions::filteredLists (CpuPrinter.cpp)
  bool skipEmptyLists_ = true;  // EmitOptions::skipEmptyLists (occupiedRefusal)
  bool initInAddBack_on_ = true;  // EmitOptions::initInAddBack (initInAddBackRefusal)
  bool constantValues_ = true;  // EmitOptions::constantValues (HostProgram.cpp)
  mutable std::unique_ptr<std::set<const PlanBody*>> pairSharedBodies_;  // (once)

  // ---- Per-particle loops in one OpenMP region (OmpRegions.cpp; stop 46) ----
  // Under OpenMP every `#pragma omp parallel` wakes the team: ~127 us a region on a VM
  // under OMP_WAIT_POLICY=passive. Where the CPU printer opens a queue (ompQueueOpen), the
  // per-particle loops that ompLoop is given (a destination's initialize, the source-only
  // and destination-only values of its first pass) are kept and printed at ompQueueFlush
  // as one `#pragma omp parallel` of `#pragma omp for schedule(static) nowait` loops: a
  // thread runs the same iterations of loops over the same particles (the same count and
  // static schedule in one region), so a loop that reads what an earlier one wrote for the
  // same particle needs no barrier; loops over another array's particles touch nothing of
  // the first's. A loop over the same array with another count gets a barrier before it.
  // One loop alone is printed as given. EmitOptions::ompRegions (--no-omp-regions: each
  // loop its own region).
  struct OmpQueuedLoop {
    std::string pragma;  // `#pragma omp parallel for schedule(static) [if (...)]`, as given
    std::string loop;    // the loop's text, from `for`
    std::string space;   // "ARRAY|count": the particles it runs over
  };
  bool ompRegions_on_ = true;  // EmitOptions::ompRegions
  mutable bool ompQueueing_ = false;
  mutable std::vector<OmpQueuedLoop> ompQueue_;
  mutable std::string ompQueueIndent_;
  // Where the first kept loop would have been printed (its stream and offset): one loop
  // alone goes there, as without the queue.
  mutable std::ostringstream* ompQueueOs_ = nullptr;  // scene_, else null
  mutable std::streampos ompQueueAt_ = 0;
  // Starts keeping loops (OpenMP and the switch on; else nothing is kept).
  void ompQueueOpen(bool openmp, const std::string& indent) const;
  // Prints `pragma` and `loop` to os, or keeps them (a queue open and the pragma not empty).
  void ompLoop(std::ostream& os, const std::string& pragma, const std::string& loop,
               const std::string& space) const;
  // Prints what is kept (one region, or the one loop as given) and closes the queue.
  void ompQueueFlush(std::ostream& os) const;
  // The space of a loop over w's particles from 0 to n (ghosts too where w runs on them).
  std::string ompSpace(const DestinationWork& w) const {
    return arr(w.array).name + (w.onGhosts ? "|all+ghosts" : "|all");
  }

  // ---- Source-only values hoisted out of the pair loops (Hoist.cpp) ----
  // The sites of a loop body computed once per source particle (none unless d.hoist), and
  // those computed once per destination particle (of properties no pair loop writes).
  std::vector<SourceOnlySite> hoistedSites(const PlanBody& b, const Dialect& d) const;
  std::vector<SourceOnlySite> hoistedDestinationSites(const PlanBody& b, const Dialect& d) const;
  // The properties the neighbour passes of the phases that call loop body b write (an
  // accumulator such as au changes during the neighbour loop): neither hoisted per
  // destination nor shared by a pair in b. A body no pass calls: those of every pair loop.
  const std::set<std::string>& pairLoopWrites(const PlanBody& b) const;
  mutable std::unique_ptr<std::set<std::string>> pairLoopWrites_;  // (once)
  mutable std::unique_ptr<std::map<const PlanBody*, std::set<std::string>>> pairLoopWritesByBody_;
  // The body's text with each hoisted site replaced by `s_hoistedK[s_idx]` (and its facts
  // moved with it), its multiply-adds fused.
  // `extra`: further edits of the text (RegisterSums.cpp), none overlapping a hoisted site.
  std::string hoistedBodyText(const PlanBody& b, const Dialect& d,
                              const std::vector<TextEdit>& extra = {}) const;
  // Its first stage: the text with the hoisted sites and `extra` replaced, not fused, and
  // the facts moved with it.
  void hoistedText(const PlanBody& b, const Dialect& d, const std::vector<TextEdit>& extra,
                   std::string& text, BodyFacts& facts) const;
  // After a loop body's function `name`: one function per hoisted site, NAME_hoistedK(s_idx,
  // ...), returning the site's value for a source particle.
  void emitHoistFunctions(const PlanBody& b, const std::string& name, const Dialect& d,
                          std::ostringstream& os) const;
  // Before a neighbour pass over source s (with `count` particles): the hoisted values of
  // its loop equations, one array each, filled in a loop over the source particles (with
  // `pragma` before it; `space`: the particles it runs over, for ompLoop).
  void emitHoistedValues(std::ostream& os, const NeighbourPass& pass, const std::string& count,
                         const std::string& pragma, const std::string& space = "") const;
  // In the destination loop of a pass, before the neighbours: the destination-only values,
  // locals `dhoisted_eqN_K`.
  void emitDestinationHoisted(std::ostream& os, const NeighbourPass& pass,
                              const std::string& indent) const;
  // The members of struct Scene that hold them.
  void emitHoistMembers(std::ostream& os) const;
  // The C++ type of the value of b's hoisted site k (source: once per source particle, else
  // per destination): double; in single precision (d.floatBodies) the type the expression
  // has in the body's float text (float, or double where it calls KERNEL_W, ...), named
  // NAME_hoistedK_t / NAME_dhoistedK_t after its function (emitHoistFunctions).
  std::string hoistedValueType(const PlanBody& b, const Dialect& d, bool source, size_t k) const;
  // The same for b's pair-shared value k (NAME_pairsharedK_t; PairShared.cpp).
  std::string pairSharedValueType(const PlanBody& b, const Dialect& d, size_t k) const;
  // The name of the function of loop body b (NAME_loop).
  std::string loopFunctionName(const PlanBody& b) const;
  // `using NAME_t = decltype(NAME(...))` for a function whose parameters have the types
  // `types`, printed after it in single precision: the type of its value.
  static std::string valueTypeAlias(const std::string& fn, const std::vector<std::string>& types);
  // What identifies a source-hoisted value across the equations of a pass (Hoist.cpp): its
  // type, t/dt, the properties it reads, its locals and its expression as printed; "" where
  // it reads an equation's scalars (not shared).
  // source = false: of a destination-only value (the destination's properties it reads).
  std::string hoistedSiteKey(const PlanBody& b, const SourceOnlySite& s,
                             const std::string& type, bool source = true) const;
  // The destination-only values of a pass's loops (an equation's site k,
  // hoistedDestinationSites) that an earlier equation of the pass hoists too (the same
  // hoistedSiteKey, not a value of the parameters alone), each mapped to that equation's
  // struct name and site index, whose local and per-particle array it reads; the first of
  // each value is not in the map (Hoist.cpp, stop 38). One scan of the pass.
  using SameHoisted =
      std::map<std::pair<const PlanEquation*, size_t>, std::pair<std::string, std::string>>;
  SameHoisted sameDestinationHoisted(const NeighbourPass& pass) const;
  // The source-hoisted values of a pass's loops that an earlier equation of the pass hoists
  // too (the same hoistedSiteKey: e.g. the shifting's two bodies' s_m / s_rho): each one's
  // pointer (hoisted_eqN_K) mapped to that earlier equation's, which holds the same doubles
  // (emitHoistedValues computes them once; the tiles load them once, stop 46).
  std::map<std::string, std::string> sameSourceHoisted(const NeighbourPass& pass) const;
  // Where eq's loop's destination-only site k is a value of the parameters alone (no
  // property, local or d_idx: the shifting's 1 / KERNEL_W(1 / hdx, 1)): the local that holds
  // it once per pass (pass_dhoisted_eqN_K, emitHoistedValues), else "". The passes of each
  // pair once and the tiles read that value, not a per-particle array (stop 46).
  std::string passDestinationHoisted(const PlanEquation& eq, size_t k) const;
  // The call of eq's loop's hoisted site k's function (source: per source particle, else
  // per destination) for `index`, each property it reads as the array `rename` names for it
  // (stop 39: the tiles' slot-order copies); "" where one is not in `rename`, or a
  // destination value of the parameters alone.
  std::string hoistedCall(const PlanEquation& eq, size_t k, bool source, const std::string& index,
                          const std::map<std::string, std::string>& rename) const;
  std::string hoistArgument(const std::string& eqValues, const std::string& k) const {
    return "hoisted_" + eqValues + "_" + k;
  }
  std::string hoistDestinationArgument(const std::string& eqValues, const std::string& k) const {
    return "dhoisted_" + eqValues + "_" + k;
  }

  // ---- Each pair once for both particles (SymmetricPairs.cpp) ----
  // A same-array pair loop that symmetricPairsRefusal() allows, on the CPU with kept lists
  // (member `lists`): the lists built for all particles when due, the destination-only values
  // of every particle, then each pair once (OpenMP: per block of particles).
  void emitSymmetricPass(const DestinationWork& w, const NeighbourPass& pass,
                         const std::string& lists, bool openmp,
                         const std::string& listRadius2);
  // The call of eq's loop for destination s_idx and source d_idx, with the mirrored pair
  // quantities (XIJ_ji, ...); with `pointers`, its property arguments are pointers + d_NAME
  // and pointers + s_NAME (emitCrossPass: mirror_d_, mirror_s_).
  // callBodyMirrored's arguments (the swapped indices, mirrored pair quantities, s_idx's
  // destination-only values, the pair-shared locals): for callBody or pairCall's `first`.
  std::function<std::string(const BodyParam&)> mirroredArgument(
      const PlanEquation& eq, const std::string& pointers = "") const;
  std::string callBodyMirrored(const PlanEquation& eq, int dest,
                               const std::string& pointers = "") const;
  // Pair loops A <- B (A's last) and B <- A (B's first) of one phase that crossPairsRefusal()
  // allows (kept lists): in B's destination after its initialize, one pass over A's
  // kept lists of B, the bodies of both per pair; `listsCheck` writes the rebuild check
  // (verlet_build) of those lists. With `hoistPragma` (OpenMP: the pragma of the source-only
  // values' loops), A's particles in blocks per thread (emitCrossBlocksHead), then the B
  // particles whose candidates span blocks (emitCrossSpanning; sphc/cross_pairs.h).
  void emitCrossPass(const DestinationWork& A, const NeighbourPass& ab, const DestinationWork& B,
                     const NeighbourPass& ba, const std::string& lists,
                     const std::string& listRadius2, const std::function<void()>& listsCheck,
                     const std::string& hoistPragma = "");
  void emitCrossBlocksHead(const std::string& lists, const std::string& nameA,
                           const std::string& nameB);
  // Pair loops of two arrays with kept lists (fluid <- wall; the per-destination loops with
  // the support's test inline, CpuPrinter.cpp, and emitCrossPass): "" where, after a build
  // of the lists, they visit only the destinations whose kept list is not empty
  // (sphc/verlet.h, find_occupied), else why not. A destination without candidates only
  // loads and stores its sums: skipped, the results are the same bits.
  std::string occupiedRefusal(const DestinationWork& w, const NeighbourPass& pass) const;
  // The per-destination loop's head in that form over [begin, end): every destination while
  // the lists' `occupied` is not found (a build: it is found after the loop), else those.
  void emitOccupiedHead(const std::string& lists, const std::string& begin,
                        const std::string& end, const std::string& pragma);
  void emitCrossSpanning(const NeighbourPass& ba, int b, const std::set<std::string>& q,
                         const std::string& lists, const std::string& nameA,
                         const std::string& nameB);
  // Its list of the spanning particles and the pointers into the lists from nameB's side.
  void emitSpanningHead(const std::string& lists);
  // Pieces of both: the kept lists of every destination particle when due (verlet_build);
  // the destination-only values of every particle (dhoisted_all_*); the pair quantities of
  // a neighbour s_idx, with `both` the mirrored ones too (XIJ_ji, DWIJ_ji, ...).
  void emitKeptListsBuild(const std::string& lists, bool openmp, const std::string& listRadius2);
  void emitDestinationHoistedAll(const NeighbourPass& pass, const std::string& pragma,
                                 const std::string& space = "");
  // lanes: WIJ and DWIJ from the kernel lanes' arrays (kl_w, kl_s at kl_k).
  void emitPairQuantitiesOnce(const std::set<std::string>& q, bool both, const std::string& body,
                              bool lanes = false);
  // Whether an each-pair-once pass leaves out the self pair: every body adds zeros there
  // (BodyFacts::vanishesOnSelfPair, body/SelfPair.cpp) and EmitOptions::skipSelfPairs.
  bool skipsSelfPair(const NeighbourPass& pass) const;
  // The members holding the destination-only values of every particle (dhoist_eqN_K).
  void emitSymmetricMembers(std::ostream& os) const;
  std::string symmetricDestinationHoisted(const std::string& eqValues, const std::string& k) const {
    return "dhoisted_all_" + eqValues + "_" + k;
  }

  // ---- The destination's sums in locals across its neighbours (RegisterSums.cpp) ----
  // The sums of pass (destination w) in locals, or why not; `mirrored`: the pass of the
  // other array whose calls go with it (a cross pass, SymmetricPairs.cpp).
  RegisterSums registerSums(const DestinationWork& w, const NeighbourPass& pass,
                            const NeighbourPass* mirrored = nullptr) const;
  // Before the neighbour loop: the locals acc_NAME loaded (or, refused, a comment why);
  // after it: stored.
  void emitSumsLoad(std::ostream& os, const std::string& indent, const RegisterSums& rs) const;
  // A sum's local (acc_NAME, accK_NAME) and its index in d_NAME for particle `idx`.
  static std::string sumsLocalName(const std::string& prop, int stride, int comp);
  static std::string sumsIndexText(int stride, int comp, const std::string& idx);
  void emitSumsStore(std::ostream& os, const std::string& indent, const RegisterSums& rs) const;
  // The call of eq's loop for destination d: with rs active, of its function on the locals
  // (named sumsPrefix + acc_NAME); `first`, where it returns an argument, overrides the others
  // (SimdPairs.cpp: the mirrored call of each pair once in SIMD lanes).
  std::string pairCall(const PlanEquation& eq, int d, const RegisterSums& rs,
                       bool scalarPairs = false, const std::string& sumsPrefix = "",
                       const std::function<std::string(const BodyParam&)>& first = nullptr) const;
  // After eq's loop function: its form on the locals (NAME_loop_sums), where a loop uses it.
  void emitSumsFunction(const PlanEquation& eq, std::ostringstream& os);
  bool registerSums_ = false;                // EmitOptions::registerSums (CPU, not mpi)
  std::string kernelLanes_ = "off";          // EmitOptions::kernelLanes (CPU, not mpi)
  // Why the serial each-pair-once loop of the pass does not compute its candidates' kernel
  // values in SIMD lanes first ("" where it does; SymmetricPairs.cpp).
  std::string kernelLanesRefusal(const std::set<std::string>& q,
                                 bool openmp) const;
  std::unique_ptr<std::set<int>> sumsDecls_;  // equation declarations whose _sums form is used
  // eq's loop on the locals, named NAME_loop_sums; `scalarPairs`: NAME_loop_simd, its vector
  // pair quantities three scalars each (XIJ_0, XIJ_1, XIJ_2; SimdPairs.cpp).
  // `mirror`: NAME_loop_simd_mirror, also its source properties values (sval_NAME).
  // `rare`: the tiles' rare form (NAME_loop_simd_rare, _simd_mirror_rare; stop 40): each
  // scalar math call a mark of the lane, `double& sphc_rare` (sphc_rare_call).
  void printSumsFunction(const PlanEquation& eq, bool scalarPairs, std::ostringstream& os,
                         bool mirror = false, bool rare = false) const;
  // The edits of b's text for its _simd form but the sums: XIJ[k] -> XIJ_k, the destination
  // values dval_NAME (the pair-shared values' _simd functions, PairShared.cpp).
  std::vector<TextEdit> simdValueEdits(const PlanBody& b, int d) const;
  // The destination properties a loop body reads and writes not, indexed `S * d_idx + k`
  // only (floating): name -> stride, components; in its _simd form values (dval_NAME,
  // dvalK_NAME) loaded before the loop.
  std::map<std::string, std::pair<int, std::set<int>>> destinationValues(const PlanBody& b,
                                                                         int d) const;
  std::vector<SourceOnlySite> allHoistedSites(const PlanBody& b) const;  // source and destination
  static std::string destinationValueName(const std::string& prop, int stride, int comp);
  // The source properties a loop body reads, indexed `S * s_idx + k` only (sval_NAME).
  std::map<std::string, std::pair<int, std::set<int>>> sourceValues(const PlanBody& b) const;
  static std::string sourceValueName(const std::string& prop, int stride, int comp);
  std::string destinationValueLoad(const std::string& prop, int stride, int comp) const;

  // ---- SIMD pair loops (SimdPairs.cpp; sphc --simd-pairs) ----
  // Why pass (destination w) is not printed in SIMD lanes, "" if it is (the switch off:
  // "off"): what the lanes cannot do (simdPairsBlocker), then under --simd-pairs=auto the
  // choice (simdPairsAutoChoice).
  std::string simdPairsRefusal(const DestinationWork& w, const NeighbourPass& pass) const;
  // What in pass (its bodies, its sums) the SIMD form cannot print, "" if nothing.
  std::string simdPairsBlocker(const DestinationWork& w, const NeighbourPass& pass) const;
  // The neighbour loop of a per-destination pass in SIMD lanes (true), or a comment why not
  // (false: the caller prints the scalar loop); nothing with the switch off.
  bool emitSimdNeighbours(std::ostream& os, const DestinationWork& w, const NeighbourPass& pass,
                          const RegisterSums& sums);
  // After eq's loop function: its NAME_loop_simd form, where a SIMD loop calls it (and its
  // NAME_loop_simd_mirror form and pair-shared values' _simd functions for each pair once).
  void emitSimdFunction(const PlanEquation& eq, std::ostringstream& os);
  // --simd-pairs=once: whether pass (destination w) is printed each pair once in SIMD lanes
  // (emitSymmetricSimdLoops): a pass over w's own array that may be each pair once and that
  // simdPairsRefusal() puts in lanes.
  bool onceLanes(const DestinationWork& w, const NeighbourPass& pass) const;
  // Whether pass would be each pair once if in lanes (onceLanes but for simdPairsRefusal):
  // over w's own array, may be each pair once, the sums only added to.
  bool onceForm(const DestinationWork& w, const NeighbourPass& pass) const;
  // Each pair once in SIMD lanes (the rest of emitSymmetricPass): serial, or OpenMP blocks,
  // bitwise equal; q the pair quantities with their mirrors.
  void emitSymmetricSimdLoops(const DestinationWork& w, const NeighbourPass& pass,
                              const std::string& lists, bool openmp,
                              const std::set<std::string>& q, const RegisterSums& sums);
  // Pieces of it: the pair quantities as scalars (with `both` the mirrored ones, XIJ_ji_0,
  // ...) and, with `mask`, the cut-off as a mask (in_support); the destination's other
  // values (dval_NAME); the mirrored call of eq in its _simd form on the locals
  // sumsPrefix + acc_NAME.
  // `negatedMirrors`: the mirrored differences as negations (-XIJ_0: the same doubles but
  // for the sign of a zero difference; the cluster-pair tiles).
  // `tileRecip`: the kernel values in the tiles' reciprocal forms (Kernel::w_tile,
  // gradient_factor_tile: no division after the square root; --tile-math=recip, stop 41);
  // with tileMathBatched_ (--tile-math=batched, stop 45) a lane's 1/r^2 and RHOIJ1 from one
  // division where it needs both (sphc::tile_reciprocals; 1/h a division of its own).
  void emitLanePairQuantities(std::ostream& os, const std::set<std::string>& q, bool both,
                              const std::string& body, bool mask,
                              bool negatedMirrors = false, bool tileRecip = false) const;
  void emitDestinationValueLoads(std::ostream& os, const DestinationWork& w,
                                 const NeighbourPass& pass, const std::string& in) const;
  std::string simdMirroredCall(const PlanEquation& eq, int d, const RegisterSums& sums,
                               const std::string& sumsPrefix) const;
  bool simdOnce_ = false;  // EmitOptions::simdPairsOnce (double, kept lists)

  // ---- Each pair once in cluster-pair tiles (ClusterPairs.cpp; sphc --simd-pairs=cluster) ----
  // Why the pass (destination w) that onceLanes() prints each pair once in lanes is not
  // printed as cluster-pair tiles, "" if it is ("off" without the switch). The CPU printer
  // adds its own conditions (kept lists shared with another pass, the tuned skin).
  std::string clusterTilesRefusal(const DestinationWork& w, const NeighbourPass& pass) const;
  // The destination's initialize in the tiles' add-back (stop 45; --no-init-in-add-back):
  // "" where the tiles pass `pass` (w's first, in tiles: the caller asks) may run w's
  // initialize per particle in its add-back loop, just before that particle's slot sums are
  // added, instead of in a loop of its own before the pass; else why not. The tiles then
  // write only the slot sums (every sum has components: in the slot order, an add-back in
  // the particles' order), and the initialize writes only those sums, which nothing before
  // the add-back reads: the same operations on the same values, one sweep less.
  std::string initInAddBackRefusal(const DestinationWork& w, const NeighbourPass& pass) const;
  // Set by the printer of w's pass while it prints the tiles with w's initialize in their
  // add-back (initInAddBackRefusal ""), else null.
  const DestinationWork* initInAddBack_ = nullptr;
  // The same without the switch and the lanes (the bodies, the properties; the CPU printer's
  // conditions): for --simd-pairs=cluster's choice of the 2D loops (simdPairsAutoChoice),
  // which puts a loop in the lanes only where the tiles take it.
  virtual std::string clusterTilesFormRefusal(const DestinationWork& w,
                                              const NeighbourPass& pass) const;
  // The pass as cluster-pair tiles (in emitSymmetricPass's place, after the kept lists'
  // rebuild check: verlet_build): the cluster layout and list at a rebuild, the slot-order
  // copies, the pruned list, the tiles, the sums added back. `state`: the prefix of its
  // members (clusterTilesMembers). `openmp`: blocks of i-clusters in parallel, bitwise the
  // serial tiles' sums (the tiles across two blocks computed in both, each side in one).
  void emitClusterTiles(const DestinationWork& w, const NeighbourPass& pass,
                        const std::string& state, const std::string& listRadius2,
                        const std::set<std::string>& q, const RegisterSums& sums,
                        bool openmp = false);
  // Stop 40: update_neighbours' statements that permute w's array into the tiles' slot
  // order where the lists `state` are expected to be rebuilt, then forget the lists `forget`.
  void emitClusterSlotOrder(const DestinationWork& w, const std::string& state,
                            const std::vector<std::string>& forget, const std::string& ind);
  // The 2xMM layout's column side (both of the above build the same layout): prints
  // `double cl_side` from the spacing (mean m / rho of array d's first `count` particles,
  // where `guard` holds) and returns "cl_side", or prints nothing and returns "0.0" (the
  // layout's rule from the bounding box) where the form is 8 x 8 or m, rho are not plain doubles.
  std::string emitClusterColumnSide(int d, bool mm, const std::string& guard,
                                    const std::string& count, const std::string& in);
  // The tiles' rare path (stop 40): why a body's scalar math calls (scalarMathCallSites) cannot
  // be printed as the rare path, "" where it has none or each is in a branch (an `if`, an
  // `else`, a `?:`'s operand) outside the hoisted and pair-shared values.
  std::string rareCallsRefusal(const PlanBody& b) const;
  // Whether the pass's bodies have scalar math calls: its tiles have the rare path (the lanes
  // call NAME_loop_simd_rare, each call a mark of the lane; the marked lanes redone by a
  // scalar fix-up with the bodies' NAME_loop_simd forms).
  bool rareCalls(const NeighbourPass& pass) const;
  // Whether the tiles take the pass with its scalar math calls (simdPairsBlocker lets them
  // through then).
  bool rareCallsInTiles(const DestinationWork& w, const NeighbourPass& pass) const;
  bool rareHelperPrinted_ = false;  // sphc_rare_call, before the first _simd_rare form
  // The members of struct Scene a pass in tiles keeps (state: its kept lists' member name).
  // `users`: the passes in tiles that share these kept lists (and the layout, the outer and
  // the pruned lists), each with a slot buffer of its own (_slots, _slots1, ...; stop 40).
  static void clusterTilesMembers(std::ostream& os, const std::string& state,
                                  const std::string& what, int users = 1);
  // The tiles' sort bookkeeping members of `state` as a run starts them (stop 40: the slot
  // order due, not yet sorted, no reference pair count): the statements (on `prefix`, each
  // line after `ind`) that set them so. clusterTilesMembers declares them with these values;
  // a --restartable run sets them again after each output (CpuPrinter::restartPoint).
  static std::string clusterSortFresh(const std::string& prefix, const std::string& ind);
  // Which of the passes in tiles sharing its kept lists this one is, and how many there are
  // ({0, 1}: the lists its own; the CPU printer's kept lists, stop 40).
  virtual std::pair<int, int> clusterListsShare(const DestinationWork&, const NeighbourPass&) const {
    return {0, 1};
  }
  bool simdCluster_ = false;  // EmitOptions::simdPairsCluster (with simdOnce_)
  bool simdClusterAuto_ = false;  // EmitOptions::simdPairsClusterAuto: 3D loops (2D: the next)
  bool simdClusterAuto2d_ = false;  // EmitOptions::simdPairsClusterAuto2d: auto's 2D loops too (stop 41)
  // Whether --simd-pairs=auto leaves this scene's loops out of the tiles (its dimension not
  // measured to pay on this CPU: 1D; 2D without SimdCpuVerdict::tiles2d).
  bool clusterAutoSkipsDim() const {
    return simdClusterAuto_ && plan_.dim != 3 && !(plan_.dim == 2 && simdClusterAuto2d_);
  }
  bool cluster2d8x8_ = false;     // EmitOptions::cluster2d8x8: 2D tiles 8 x 8, not 2xMM
  bool cluster2dDoubled_ = false; // EmitOptions::cluster2dDoubled: 2xMM j side from doubled copies
  bool cluster3d2xmm_ = false;    // EmitOptions::cluster3d2xmm: 3D tiles in the 2xMM form
  bool clusterQueue_ = false;     // EmitOptions::clusterQueue: 8 x 8 tiles' pairs compacted
  // Whether the tiles are GROMACS' 2xMM form (2D by default, 3D with --cluster-3d-2xmm).
  bool clusterTiles2xMM() const {
    return plan_.dim == 2 ? !cluster2d8x8_ : cluster3d2xmm_;
  }
  bool clusterSlotOrder_ = true;  // EmitOptions::clusterSlotOrder (--no-slot-order: false)
  bool tileMathRecip_ = true;     // EmitOptions::tileMathRecip (--tile-math=exact: false)
  bool tileMathBatched_ = true;   // EmitOptions::tileMathBatched (--tile-math=batched)
  // ---- h as one value per array (EmitOptions::uniformH; analysis/UniformH.h, stop 45) ----
  std::vector<bool> hUniform_;    // per array: its h the same for every particle, all the run
  // The pass being printed: its destination's (uhI_) and source's (uhJ_) h is uniform, read
  // once into uh_hi and uh_hj; with both, uh_hmax, uh_cut2 (RADIUS2 * hmax * hmax) and uh_HIJ
  // too (beginUniformH). uhPrefix_: "uh_", or "uhl_" for the tiles' local copies.
  bool uhI_ = false, uhJ_ = false;
  std::string uhPrefix_ = "uh_";
  // Prints the pass's uniform values (after its di_h, sj_h) and sets uhI_, uhJ_; endUniformH:
  // the pass is over.
  void beginUniformH(int d, int s, const std::string& in);
  void endUniformH() { uhI_ = uhJ_ = false; uhPrefix_ = "uh_"; }
  // The tiles' lambda: the values as locals of its own (read through the capture, GCC would
  // load them again after every store to a double).
  void uniformHLocals(const std::string& in);
  // What a pair loop prints for hi, hj, hmax and the cut-off `radius2 * hmax * hmax`.
  std::string hiValue(const std::string& perParticle) const {
    return uhI_ ? uhPrefix_ + "hi" : perParticle;
  }
  std::string hjValue(const std::string& perParticle) const {
    return uhJ_ ? uhPrefix_ + "hj" : perParticle;
  }
  std::string hmaxValue() const { return uhI_ && uhJ_ ? uhPrefix_ + "hmax" : "hi > hj ? hi : hj"; }
  std::string cutoffValue(const std::string& radius2) const {
    return uhI_ && uhJ_ && radius2 == "RADIUS2" ? uhPrefix_ + "cut2" : radius2 + " * hmax * hmax";
  }
  // pairQuantityStatement, with HIJ the pass's uh_HIJ where both sides are uniform (and the
  // kernel's values of it by kernelCall).
  std::string pairStatement(const PairQuantity& pq, const PairDialect& dialect,
                            const std::string& indent) const;
  // The call Kernel::FN(BEFORE H AFTER); where H is the pass's uniform HIJ, FN's form taking
  // h's factors computed once per pass (kernels.h, FN_ih: uh_ihd = 1 / h^dim, and for the
  // tiles' forms uh_ih = 1 / h in h's place), the same values bit for bit.
  std::string kernelCall(const std::string& fn, const std::string& before, const std::string& h,
                         const std::string& after) const;
  // Whether the pass's array is kept in its tiles' slot order (stop 40; ClusterPairs.cpp):
  // permuted into it where its tiles' lists are due (update_neighbours) and read and written
  // by the tiles in place. The CPU printer's answer (its own arrays, sorted, double).
  virtual bool clusterSlotOrder(const DestinationWork&, const NeighbourPass&) const { return false; }
  std::string simdClusterWhy_;    // the report's reason (--simd-pairs=cluster, or auto's)
  // --precision=single: the float local a SIMD loop passes for a body's double argument (t,
  // dt, an equation's scalar: f_t, f_eq2_alpha), converted once before the loop; "" for
  // other parameters.
  static std::string floatScalarName(const std::string& eqValues, const BodyParam& p);
  bool simdPairs_ = false;                    // EmitOptions::simdPairs (CPU, not mpi)
  // --simd-pairs=auto (SimdPairs.cpp): whether pass is put in SIMD lanes, and why (the
  // expected neighbour count, or the loop being per destination anyway).
  struct SimdAutoChoice {
    bool lanes = false;
    std::string why;
  };
  SimdAutoChoice simdPairsAutoChoice(const DestinationWork& w, const NeighbourPass& pass) const;
  // With zones (inlets, outlets): why the per-destination lanes are not taken ("" where they
  // are: every pair-loop body of the scene adds what vanishes at the support; SimdPairs.cpp).
  std::string zonesLanesRefusal() const;
  // Whether the CPU printer would evaluate pass (destination w) once per pair without SIMD.
  bool eachPairOncePossible(const DestinationWork& w, const NeighbourPass& pass) const;
  // --report: per pair loop, whether it is in SIMD lanes and why (nothing with the switch off).
  std::vector<std::string> simdPairsNotes() const;
  bool simdAuto_ = false;           // EmitOptions::simdPairsAuto
  SimdCpuVerdict simdCpu_;          // EmitOptions::simdCpu: the lanes on this CPU (auto)
  double simdNeighbours_ = 30;      // EmitOptions::simdAutoNeighbours (auto's threshold)
  double simdOnceNeighbours_ = -1;  // of a loop each pair once in lanes (< 0: simdNeighbours_)
  double simdPerDestNeighbours_ = 0;  // of a loop over its own array per destination anyway
  bool simdSymmetric_ = false;      // EmitOptions::symmetricPairs, kept lists (for the choice)
  bool simdSymmetricSwitch_ = false;  // EmitOptions::symmetricPairs (--no-symmetric-pairs: false)
  bool simdGhostOnce_ = false;  // scalar each pair once with periodic or mirror ghosts (Bodies.cpp)
  std::unique_ptr<std::set<int>> simdDecls_;  // equation declarations whose _simd form is used

  // ---- The host program (HostProgram.cpp) ----
  void emitBodies();
  void emitSceneFunctions();
  void emitParams();
  // The C++ literal of an equation instance's value known at compile time, "" if none
  // (HostProgram.cpp; EmitOptions::constantValues).
  std::string literalValue(const PlanEquation& eq, const std::string& name,
                           const ast::Expr& v) const;
  void emitSetup();
  void emitArraySetup(const PlanArray& a);
  void emitDomainSetup();
  void emitGroup(const ScheduleGroup& g);
  void emitPhase(const Phase& ph);
  void emitPhaseMember(const Phase& ph);
  void outOfClassMembers(const std::string& members, const std::set<std::string>& names);
  // A group option evaluated at run time (start_idx, stop_idx, condition) as C++: params,
  // array constants `arr.c` (their first value), t and dt.
  std::string groupOptionCpp(const ast::Expr& e) const;
  // update_nnps: rebuild the neighbour search inside an evaluation.
  void emitNeighbourRebuild(const std::string& indent);
  // d_begin, d_end of a destination with start_idx / stop_idx, clamped to [0, n).
  void emitParticleRange(const DestinationWork& w);
  // The first and one-past-last destination particle of a phase's per-particle loops.
  static std::string rangeBegin(const DestinationWork& w) { return w.ranged() ? "d_begin" : "0"; }
  static std::string rangeEnd(const DestinationWork& w) { return w.ranged() ? "d_end" : "n"; }
  // An iterated group's convergence: its loop, the tests, the iteration bounds.
  void emitIteration(const ScheduleGroup& g);
  // --timing: (FILE:LINE, live equations comma-separated) of each call of the top-level
  // group `equations`, in call order.
  std::vector<std::pair<std::string, std::string>> topGroupLabels() const;
  // The same for the groups with post_step = true, in sched_.postStep order.
  std::vector<std::pair<std::string, std::string>> postStepLabels() const;
  // The convergence test of an iterated group's equation (inside the iteration loop).
  void emitConverged(const PlanEquation& eq);
  // `reduce { }` (PySPH's reduce(dst, t, dt)) of a destination's equations, on the host,
  // after its per-particle work (HostProgram.cpp).
  void emitHostReduces(const DestinationWork& w);
  void emitStep();
  void emitAdaptiveDt();
  void emitSceneMembers();
  // The SceneProgram of `main`: name, params, options, set-up, arrays, step, outputs.
  void emitMain();
  void emitLimits();
  // metrics { } (MetricsPrinter.cpp): Scene::metrics(t), and their descriptions in main.
  void emitMetrics();
  void emitMetricsMain();
  void emitProfile(const PlanMetric& m, size_t k);  // a profile metric (MetricsPrinter.cpp)
  // Opens the loop over a metric's particles; the names in its scope (MetricsPrinter.cpp).
  std::function<std::string(const std::string&)> emitMetricParticleLoop(const PlanMetric& m);

  // ---- Inlets and outlets (InletOutletPrinter.cpp) ----
  bool hasZones() const { return !plan_.zones.empty(); }
  // In setup(), after the arrays: the zones of the scene and init_inlet_outlet.
  void emitZoneSetup();
  // The Scene member inlet_outlet(t), the schedule's InletOutlet statement.
  void emitInletOutlet();

  // ---- Distributed runs, sphc --mpi (DistributedPrinter.cpp) ----
  // update_neighbours' first statement: migration (and re-balancing when due).
  void emitMigration();
  // The halo exchange of every source array and the search domain over real + halo particles
  // (after the cell-order permutation of the real particles; `all` is in scope).
  void emitHaloExchange();
  // Lines that combine a reduction's `acc` (over nReal local particles) over every rank.
  std::string globalReduction(const std::string& op, const std::string& nReal) const;
  // Members of struct Scene (decomposition, gathered output) and its distribute()/number().
  void distributedMembers();
  void distributedFunctions();
  // In main: after the set-up (distribute or number), the MPI session, SceneProgram fields.
  std::string afterSetupDistributed() const;
  void distributedMain();
  std::string distributedReport() const;  // after run_main: halo volumes (SPHC_MPI_STATS)
  // In main: prog.run_state and prog.restore (--restart, sphc/restart.h; RestartPrinter.cpp).
  void emitRestart();
  // The array list `{&a, &b}` of every array (prefix: "" inside Scene, "scene." in main).
  std::string allArrays(const std::string& prefix) const;

  // ---- Shared helpers ----
  // The data a scene computes on: host arrays, or their float copies (--precision=single).
  std::string propPtr(int array, const std::string& prop) const;
  // `cells_S.build(ON, x, y|nullptr, z|nullptr, COUNT);` with each coordinate as coord(a, axis)
  // gives it (host pointer or device buffer): the one cell-list build statement.
  std::string cellListBuildCall(
      const std::string& S, const std::string& count, const std::string& on,
      const std::function<std::string(int, const std::string&)>& coord) const;
  // The host array's own data (set-up writes it).
  std::string hostPtr(int array, const std::string& prop) const;
  // The C++ type of a property or constant in the scene's host loops.
  std::string hostType(int array, const std::string& prop) const {
    return propType(array, prop, host_);
  }
  bool hasDomain() const { return sched_.domain; }
  // Whether source S is permuted into cell order (not when a ranged group names its
  // particles by index), and whether any source is.
  bool reorders(const std::string& S) const {
    return !sched_.keepOrder.count(plan_.arrayIndex(S));
  }
  bool anyReorders() const {
    for (const auto& S : sourceArrays_)
      if (reorders(S)) return true;
    return false;
  }
  std::string propIndexList(int a, const std::vector<std::string>& props) const;
  // The comment before a ghost refresh, "// ghosts follow: p q ...", in scene_; false (nothing
  // printed) where the destination work refreshes no property.
  bool ghostsFollow(const DestinationWork& w) {
    if (w.ghostRefresh.empty()) return false;
    scene_ << "      // ghosts follow:";
    for (const auto& p : w.ghostRefresh) scene_ << " " << p;
    return true;
  }
  // The name of property slot i / constant slot c of array a in the generated code
  // (`fluid_props::rho`, `fluid_consts::dim`), declared by emitSlots().
  std::string propSlot(int a, int i) const;
  std::string constSlot(int a, int c) const;
  void emitSlots();
  std::string loc(llvm::SMLoc l) const { return diags_.lineInfo(l); }
  std::string paramRef(const std::string& n) const { return "P." + n; }
  std::string eqStruct(const PlanEquation& eq) const { return "eq" + std::to_string(eq.id); }
  const PlanArray& arr(int a) const { return plan_.arrays[a]; }
  int propIndex(int a, const std::string& p) const;
  int constIndex(int a, const std::string& c) const;
  const PlanBody& methodBody(const PlanEquation& eq, ast::Method::Kind kind) const {
    return plan_.bodies[plan_.equationDecls[eq.declIndex].methods.at(kind)];
  }
  // f(eq, body) for every live equation with a pair loop, in order, with its loop's body.
  template <class F>
  void forEachLoopBody(F&& f) const {
    for (const PlanEquation& eq : plan_.equations)
      if (eq.live && plan_.equationDecls[eq.declIndex].methods.count(ast::Method::Loop))
        f(eq, methodBody(eq, ast::Method::Loop));
  }
  // The statement that calls equation eq's method `kind` for destination array d, with its
  // provenance: "CALL;  // NAME, from FILE:LINE\n" (sep: as callBody's).
  std::string equationCall(const PlanEquation& eq, ast::Method::Kind kind, int d,
                           const std::string& sep = ".") const;

  const Schedule& sched_;
  const Plan& plan_;
  const DiagnosticEngine& diags_;
  std::string backendName_;  // serial, openmp, opencl (prog.backend)
  bool singlePrecision_ = false;
  // --precision=single on the CPU backends: the scene computes on float copies of the arrays
  // (sphc::FloatArray f32_<array>), bodies and neighbour search included; the host arrays
  // (double) serve set-up and, after to_host(), output.
  bool cpuSingle_ = false;
  std::string real_ = "double";  // the C++ floating type the scene computes in
  bool mpi_ = false;        // sphc --mpi (the schedule's Distribution)
  bool globalIds_ = false;  // particles carry gid (--global-ids, --mpi)
  Dialect host_, device_;
  std::ostringstream out_;    // the file
  std::ostringstream scene_;  // members of struct Scene
  std::ostringstream cl_;     // OpenCL C of the kernels (--backend=opencl)
  // EmitOptions::splitUnits on a CPU backend without --mpi: the phases' definitions, out of
  // struct Scene (emitPhase), printed after it between the markers of CppEmitter.h.
  bool splitPhases_ = false;
  bool intPow_ = false;  // EmitOptions::intPow, double precision (host and device)
  std::ostringstream phases_;
  std::vector<std::string> sourceArrays_;  // arrays that need a cell list, by name
  std::set<std::string> loopArrays_;       // arrays in a neighbour pass, as dest or source
};

std::unique_ptr<ScenePrinter> makeCpuPrinter(const Schedule& sched,
                                             const DiagnosticEngine& diags,
                                             const EmitOptions& opts);
std::unique_ptr<ScenePrinter> makeOpenCLPrinter(const Schedule& sched,
                                                const DiagnosticEngine& diags,
                                                const EmitOptions& opts);

}  // namespace sphc
