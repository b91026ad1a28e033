// sphc: the .sph compiler driver. The lowering reads top to bottom, one pass per line:
//   modules = parse; plan = sema; plan = bodies; plan = prune; ... schedule = lower(plan);
//   cpp = print(schedule, backend); exe = build
// `--dump-after=PASS` prints the state after PASS and stops; `--report` prints the plan.
#include "analysis/Passes.h"
#include "analysis/KeptGhostSpan.h"
#include "analysis/PositionReads.h"
#include "analysis/UniformH.h"
#include "body/BodyAnalysis.h"
#include "codegen/CppEmitter.h"
#include "driver/Build.h"
#include "driver/Study.h"
#include "frontend/ASTPrinter.h"
#include "frontend/Diagnostics.h"
#include "sema/Options.h"
#include "sema/Sema.h"

#include "llvm/Support/CommandLine.h"
#include "llvm/Support/FileSystem.h"
#include "llvm/Support/InitLLVM.h"
#include "llvm/Support/Path.h"
#include "llvm/Support/raw_ostream.h"

#include <chrono>
#include <functional>

using namespace sphc;
namespace cl = llvm::cl;

static cl::OptionCategory SphcCat("sphc options");

// An enum option's parser whose error names the values it accepts (LLVM's own says only
// that it found none): "for the --backend option: unknown value 'cuda'; it is one of:
// serial, openmp, opencl".
template <class T>
class NamedValues : public cl::parser<T> {
 public:
  using cl::parser<T>::parser;
  bool parse(cl::Option& o, llvm::StringRef name, llvm::StringRef arg, T& value) {
    std::string names;
    for (unsigned i = 0; i < this->getNumOptions(); ++i) {
      if (this->getOption(i) == (o.hasArgStr() ? arg : name))
        return cl::parser<T>::parse(o, name, arg, value);
      names += (i ? ", " : "") + this->getOption(i).str();
    }
    return o.error("unknown value '" + arg + "'; it is one of: " + names);
  }
};
static cl::opt<std::string> InputFile(cl::Positional, cl::desc("<scene.sph>"), cl::Required,
                                      cl::cat(SphcCat));
static cl::opt<std::string> OutputFile("o", cl::desc("Executable to write (default: the scene "
                                                     "file's name without .sph)"),
                                       cl::value_desc("file"), cl::cat(SphcCat));
static cl::opt<sphc::Backend, false, NamedValues<sphc::Backend>> BackendOpt(
    "backend", cl::desc("The solver's backend:"), cl::init(sphc::Backend::Serial),
    cl::values(clEnumValN(sphc::Backend::Serial, "serial", "one thread (default)"),
               clEnumValN(sphc::Backend::OpenMP, "openmp", "loops over particles in parallel"),
               clEnumValN(sphc::Backend::OpenCL, "opencl", "OpenCL kernels on a device")),
    cl::cat(SphcCat));
static cl::opt<sphc::Precision, false, NamedValues<sphc::Precision>> PrecisionOpt(
    "precision", cl::desc("Floating point the scene computes in:"),
    cl::init(sphc::Precision::Double),
    cl::values(clEnumValN(sphc::Precision::Double, "double",
                          "double (default; on OpenCL it needs fp64)"),
               clEnumValN(sphc::Precision::Single, "single", "float")),
    cl::cat(SphcCat));
enum class OnOff { On, Off };
static cl::opt<OnOff, false, NamedValues<OnOff>> FmaOpt(
    "fma", cl::desc("Products added to values in bodies (a * b + c, x += a * b):"),
    cl::init(OnOff::On),
    cl::values(clEnumValN(OnOff::On, "on",
                          "fused multiply-adds, fma(a, b, c): rounded once, alike on every "
                          "backend (default)"),
               clEnumValN(OnOff::Off, "off", "a multiply and an add, each rounded")),
    cl::cat(SphcCat));
enum class TileMath { Batched, Recip, Exact };
static cl::opt<TileMath, false, NamedValues<TileMath>> TileMathOpt(
    "tile-math",
    cl::desc("The kernel values W and grad W in the cluster-pair tiles (--simd-pairs=cluster "
             "or auto's tiles):"),
    cl::init(TileMath::Batched),
    cl::values(clEnumValN(TileMath::Batched, "batched",
                          "recip's forms, and a lane's 1/r^2 and 1/RHOIJ (RHOIJ1) from one "
                          "division where it needs both (default; each within 3 u of its division, "
                          "1/(h r) within 12 u; 1/h a division of its own, once per pass where h is "
                          "one value; runtime/include/sphc/kernels.h, sphc::tile_reciprocals)"),
               clEnumValN(TileMath::Recip, "recip",
                          "q = r (1/h) and 1/r = r (1/r^2): no division after the square root "
                          "(within 3 ulp of the exact forms' q, 6 u of their 1/(h r); "
                          "runtime/include/sphc/kernels.h; the default of stops 41-44)"),
               clEnumValN(TileMath::Exact, "exact",
                          "r / h and dW/dq / (h r), the forms of the other pair loops (before "
                          "stop 41)")),
    cl::cat(SphcCat));
static cl::opt<OnOff, false, NamedValues<OnOff>> IntPowOpt(
    "int-pow", cl::desc("pow(x, y) in the bodies (double precision, every backend):"),
    cl::init(OnOff::On),
    cl::values(clEnumValN(OnOff::On, "on",
                          "by multiplications where y is an integer with |y| <= 8 (within 8 "
                          "ulp of the C library's pow), pow otherwise (default)"),
               clEnumValN(OnOff::Off, "off", "the C library's pow")),
    cl::cat(SphcCat));
static cl::opt<std::string> VerletSkin(
    "verlet-skin",
    cl::desc("Neighbour lists kept across time steps: each destination particle's candidates "
             "within (1 + F) times the support, rebuilt when particles moved too far. auto "
             "(default): F = 0.1, the particles sorted in cell order every 50 neighbour "
             "updates; tuned: as auto, with F chosen at run time (from 0.1) from how far "
             "particles move between rebuilds and the sort when they left cell order (no "
             "periodic/mirror domain); both where the lists are written for (serial and openmp, "
             "no periodic/mirror domain, inlets, outlets or --mpi), off elsewhere (--report "
             "says which); F in (0, 1]: that skin, an error elsewhere; off or 0: "
             "the cell lists' neighbours at every evaluation. Sums over neighbours round "
             "differently with and without lists"),
    cl::value_desc("auto|F|off"), cl::init("auto"), cl::cat(SphcCat));
static cl::opt<bool> NoGroupFusion(
    "no-group-fusion",
    cl::desc("Run every group on its own (default: consecutive plain groups of which none "
             "reads or writes what an earlier one writes, nor writes what it reads, run as one "
             "phase, sharing their neighbour passes; the results are the same bit for bit)"),
    cl::init(false), cl::cat(SphcCat));
static cl::opt<bool> NoHoist(
    "no-hoist",
    cl::desc("Compute every subexpression of a pair-loop body per pair, as written (default: "
             "those that depend on the source particle only and divide or call sqrt, pow, ... "
             "are computed once per particle before the neighbour pass; serial and openmp, "
             "double and single precision; the results are the same bit for bit)"),
    cl::init(false), cl::cat(SphcCat));
static cl::opt<bool> NoUniformH(
    "no-uniform-h",
    cl::desc("In the CPU pair loops, read every particle's h and compute hmax, the cut-off and "
             "HIJ per pair (default: where an array's h is one value for the whole run, i.e. "
             "nothing writes it, its initial value is an expression of params, no file or inlet "
             "or outlet gives it particles, they read it once per pass and compute those once; "
             "serial and openmp, not --mpi; --report says which arrays; the results are the "
             "same bit for bit)"),
    cl::init(false), cl::cat(SphcCat));
static cl::opt<bool> NoFoldZeroTerms(
    "no-fold-zero-terms",
    cl::desc("In a 1D or 2D scene, keep the terms of the bodies' multiply-adds whose product has "
             "a factor the dimension leaves out (default: dropped, e.g. the z row and column of "
             "a 3x3 tensor, the z term of a dot product: a * DWIJ[2] + c is c; the results are "
             "the same bit for bit but where a factor is infinite or NaN or in the sign of a "
             "zero sum, docs/performance-log.md)"),
    cl::init(false), cl::cat(SphcCat));
// --omp-min-particles (default): measured in docs/performance-log.md, "OpenMP on small scenes".
static constexpr unsigned kDefaultOmpMinParticles = 10000;
static cl::opt<unsigned> OmpMinParticles(
    "omp-min-particles",
    cl::desc("--backend=openmp: loops without neighbours (initialize, post_loop, steppers, "
             "reductions, hoisted values, the adaptive step's limits) over fewer particles "
             "than this run on one thread (an `if` clause; a parallel region costs more than "
             "their work); pair loops stay parallel. 0: all parallel, as before this option. "
             "The results are the same bit for bit"),
    cl::value_desc("N"), cl::init(kDefaultOmpMinParticles), cl::cat(SphcCat));
static cl::opt<bool> NoBatchedTables(
    "no-batched-tables",
    cl::desc("--backend=opencl: build each source's cell table in its own five launches "
             "(default: the tables of all sources of an update in four launches per two "
             "sources; the same tables, the results are the same bit for bit)"),
    cl::init(false), cl::cat(SphcCat));
static cl::opt<bool> NoFusedLaunches(
    "no-fused-launches",
    cl::desc("--backend=opencl: a kernel per initialize and post_loop, per stepper run and "
             "array, for the search domain's extents and per min/max reduction (default: "
             "the initialize and post_loop of a destination in its neighbour pass's kernel "
             "where the pass's source is another array, the first initialize of each array "
             "after a neighbour update in the stepper run's kernel before it, and with "
             "--fused-reductions more; the results are the same bit for bit)"),
    cl::init(false), cl::cat(SphcCat));
static cl::opt<bool> FusedReductions(
    "fused-reductions",
    cl::desc("--backend=opencl: also compute the search domain's extents (in the stepper "
             "runs before a neighbour update), min/max reductions (in the post_loop's kernel) "
             "and the adaptive step's limits (in the step's last kernel on the array) within "
             "those kernels' work groups, saving their kernels (the dam break: 16 launches "
             "per step instead of 20). Off by default: no gain measured on PoCL's CPU device, "
             "where the kernels with work-group barriers profile slower than the kernels they "
             "replace (docs/performance.md); meant for GPUs. The results are the same bit for bit"),
    cl::init(false), cl::cat(SphcCat));
static cl::opt<std::string> KeptCells(
    "kept-cells",
    cl::desc("--backend=opencl without periodic or mirror sides: keep the device's cell tables "
             "across neighbour updates, on cells of (1 + F) times the support, until a source "
             "particle moved farther than F times the support (a check kernel per update: 20 "
             "launches per dam-break step, not 26); off (default): built at every update. Sums "
             "over neighbours round differently with and without (not measured to pay on PoCL: "
             "docs/performance-log.md)"),
    cl::value_desc("off|F"), cl::init("off"), cl::cat(SphcCat));
static cl::opt<bool> NoSymmetricPairs(
    "no-symmetric-pairs",
    cl::desc("Evaluate every pair of a pair loop for each of its two particles (default: where "
             "the destination array is the source and the bodies allow it, each pair once for "
             "both particles, on the CPU backends with kept neighbour lists; --report says "
             "which loops; the results are the same bit for bit)"),
    cl::init(false), cl::cat(SphcCat));
static cl::opt<std::string> PairSharedValues(
    "pair-shared-values",
    cl::desc("Where a pair loop evaluates each pair once for both particles, compute the "
             "values of its bodies that are the same (or negated) for the mirrored pair once "
             "per pair and pass them to both calls (serial and openmp, double and single "
             "precision). on "
             "(default, or --pair-shared-values alone); off: each of the two calls computes "
             "its own values. The results are the same bit for bit (docs/performance-log.md)"),
    cl::value_desc("on|off"), cl::ValueOptional, cl::init("on"), cl::cat(SphcCat));
static cl::opt<bool> NoRegisterSums(
    "no-register-sums",
    cl::desc("In the CPU pair loops, update the destination's sums in memory at every pair "
             "(default: the d_ properties the loop bodies accumulate at d_idx are locals "
             "across the neighbours, loaded before them and stored after them, where the "
             "bodies allow it; serial and openmp, double and single precision (float locals "
             "in single); the results are the same bit for bit)"),
    cl::init(false), cl::cat(SphcCat));
static cl::opt<std::string> KernelLanesOpt(
    "kernel-lanes",
    cl::desc("The serial CPU loops that evaluate each pair once with scalar code: a "
             "destination's candidates first in SIMD lanes (the cut-off, W and the gradient's "
             "factor of each), then the bodies over the neighbours among them; double "
             "precision, kernels without exp. auto (default): in a scene of one array in a "
             "periodic or mirror domain (measured to pay there); on: wherever the loop allows "
             "it; off: the kernel in the pair loop. The results are the same bit for bit"),
    cl::value_desc("auto|on|off"), cl::init("auto"), cl::cat(SphcCat));
static cl::opt<bool> NoSlotOrder(
    "no-slot-order",
    cl::desc("The cluster-pair tiles (--simd-pairs=cluster or auto's) over slot-order copies of "
             "the particles, gathered per evaluation and their sums added back (stops 37-39), "
             "not over the particles themselves kept in the tiles' slot order (stop 40; a "
             "measurement knob)"),
    cl::init(false), cl::Hidden, cl::cat(SphcCat));
static cl::opt<bool> Cluster2d8x8(
    "cluster-2d-8x8",
    cl::desc("The 2D cluster-pair tiles (--simd-pairs=cluster) as 8 x 8 tiles of one i x 8 j's "
             "per register (stops 37-38), not GROMACS' 2xMM form of 4 x 4 cluster pairs in "
             "registers of 2 i's x 4 j's (stop 39; a measurement knob)"),
    cl::init(false), cl::Hidden, cl::cat(SphcCat));
static cl::opt<bool> Cluster3d2xmm(
    "cluster-3d-2xmm",
    cl::desc("The 3D cluster-pair tiles of --simd-pairs=cluster in GROMACS' 2xMM form, "
             "4-clusters (columns of 2 spacings: 2 x 2 x 1 lattice cells) in registers of 2 i's x "
             "4 j's, as the 2D tiles (stop 42; with --simd-pairs=auto too), not 8 x 8 tiles: "
             "measured no faster than the 8 x 8 tiles on the cube, slower on the DualSPHysics "
             "scene and dambreak3d (a measurement knob)"),
    cl::init(false), cl::Hidden, cl::cat(SphcCat));
static cl::opt<bool> ClusterQueue(
    "cluster-queue",
    cl::desc("The 8 x 8 cluster-pair tiles' pairs within the support compacted, 8 to a register "
             "(a tile's rows' masks, their pairs' indices packed by vpcompressb, the values by "
             "permutes of the clusters' registers, the sums back per row; under AVX-512 with "
             "VBMI2, else the rows as before; not for the 2xMM form, bodies with a rare math "
             "call, or a pass that keeps the self pair). Sums reassociated; serial = OpenMP "
             "bitwise (stop 43, docs/performance-log.md \"The tiles' pairs compacted (stop 43)\"). "
             "Measured slower than the rows since the SIMD builds prefer 512-bit vectors: 0.91x "
             "their pairs per second on the cube and the DualSPHysics scene (stop 44, \"The "
             "interaction loop against the measured peak (stop 44)\"); a measurement knob"),
    cl::init(false), cl::cat(SphcCat));
static cl::opt<bool> Cluster2dDoubled(
    "cluster-2d-doubled",
    cl::desc("The 2D cluster-pair tiles (2xMM) in slot order read their j side from copies "
             "doubled per cluster at every evaluation (stops 39-40), not from the particles' "
             "arrays through a tile-local doubled register (stop 41; a measurement knob)"),
    cl::init(false), cl::Hidden, cl::cat(SphcCat));
static cl::opt<bool> NoSelfPairSkip(
    "no-self-pair-skip",
    cl::desc("Evaluate the self pair (a particle with itself, r = 0) in the each-pair-once "
             "loops too (default: where every body of such a loop only adds zeros at r = 0, "
             "e.g. the momentum, continuity and XSPH equations, a particle's pairs start after "
             "it; the results are the same bit for bit but for the sign of a sum that is -0 "
             "there)"),
    cl::init(false), cl::cat(SphcCat));
static cl::opt<bool> FilteredLists(
    "filtered-lists",
    cl::desc("In the CPU per-destination pair loops with kept lists, filter each list to the "
             "support first, then loop over the filtered list (default: walk the kept list "
             "once with the support's test inline, where no loop_all, SIMD lanes or --mpi "
             "need the filtered list; the results are the same bit for bit)"),
    cl::init(false), cl::cat(SphcCat));
static cl::opt<bool> NoSkipEmptyLists(
    "no-skip-empty-lists",
    cl::desc("In the CPU pair loops of two arrays with kept lists (fluid <- wall), visit every "
             "destination particle at every evaluation (default: after a build of the lists "
             "only those whose kept list is not empty; the others add nothing to their sums: "
             "the results are the same bit for bit)"),
    cl::init(false), cl::cat(SphcCat));
static cl::opt<bool> NoInitInAddBack(
    "no-init-in-add-back",
    cl::desc("Run a destination's initialize in a loop of its own before its first pair loop "
             "also where that loop is in cluster-pair tiles whose add-back could run it "
             "(default: per particle in the tiles' add-back, where the tiles write only slot "
             "sums that the initialize alone writes; the results are the same bit for bit)"),
    cl::init(false), cl::cat(SphcCat));
static cl::opt<bool> NoOmpRegions(
    "no-omp-regions",
    cl::desc("OpenMP: print each loop without neighbours before a destination's first pair "
             "loop (its initialize, the hoisted values) as a parallel region of its own "
             "(default: those loops in one region, each `omp for nowait`: the same "
             "iterations on the same threads; the results are the same bit for bit)"),
    cl::init(false), cl::cat(SphcCat));
static cl::opt<bool> NoConstantValues(
    "no-constant-values",
    cl::desc("Set every parameter and const of the equation instances at set-up (default: "
             "those whose value is a literal, e.g. dim = 2 or a default such as R = 0.2, are "
             "constants of the generated C++, which the C++ compiler folds into the loops; "
             "the results are the same bit for bit)"),
    cl::init(false), cl::cat(SphcCat));
static cl::opt<std::string> SimdPairs(
    "simd-pairs",
    cl::desc("The CPU pair loops (serial and openmp, double and single precision) whose bodies allow it "
             "may process the neighbours of a destination in SIMD lanes: `#pragma omp simd` "
             "with the destination's sums as reductions, built with -fopenmp-simd; such a loop "
             "is per destination even where each pair could be evaluated once. auto "
             "(default): where it pays, on a CPU where the lanes pay (--simd-cpu), the loops "
             "where 30 or more neighbours are expected in "
             "the support (from the dimension, the kernel's support and h/dx with the scene's "
             "defaults; where they are not known before the run, 3D yes, 2D no: with h = 1.3 "
             "dx and a support of 2 h, 74 and 21 neighbours; below 30, each pair once pays "
             "more), and a loop over its own array that is per destination anyway (a periodic "
             "or mirror domain, zones) at any count; on (or --simd-pairs alone): every loop that allows it; off: the "
             "scalar loops. Under auto a loop in lanes over its own array (kept lists, double "
             "precision) evaluates each pair once in them, the values the pair shares once, "
             "the source side gathered and scattered; on Intel Sapphire Rapids-class cores "
             "and later (AVX512-FP16 or AMX; --simd-cpu) a 3D such loop in cluster-pair tiles "
             "of 8 x 8 particles instead (stop 38), a 2D one over its own array in 2xMM tiles "
             "(stop 43) (once: the "
             "lanes; perdest: auto's loops "
             "per destination, the default before stop 35; docs/performance.md). --report says "
             "per loop which and why. The sums are reassociated "
             "in the lanes, so results differ from the scalar loop's in the last bits "
             "(serial and openmp stay bitwise equal)"),
    cl::value_desc("auto|on|off|once|perdest"), cl::ValueOptional, cl::init("auto"), cl::cat(SphcCat));
static cl::opt<std::string> SimdCpuOpt(
    "simd-cpu",
    cl::desc("The CPU --simd-pairs=auto chooses for (codegen/SimdCpu.cpp): host (default: "
             "this machine's cpuid, the CPU that -march=native builds for) or "
             "VENDOR:FAMILY:MODEL[:FEATURES] as cpuid gives them (GenuineIntel:6:207, "
             "AuthenticAMD:26:2, GenuineIntel:6:167:+avx512fp16,+amx), FEATURES a comma list "
             "of +F or -F with F one of avx512f, avx512fp16, amx, avx512vbmi2 (without it: "
             "AVX-512F and none of the others; :noavx512 is -avx512f). The lanes where they "
             "were measured to pay, with AVX-512F: AMD family 26 (Zen 5) and later; Intel with "
             "AVX512-FP16 or AMX (Sapphire Rapids-class cores and later, whatever the model a "
             "VM reports) and Intel family 6 models 207 and 143 (Emerald and Sapphire Rapids) "
             "without them; there the 3D and 2D loops in cluster-pair tiles. The scalar loops "
             "on other Intel CPUs (AVX-512 without FP16 or AMX: not measured), without "
             "AVX-512F (GCC does not vectorise them) and on CPUs not measured. sphc -v and "
             "--report say which, and which features decided"),
    cl::value_desc("host|VENDOR:FAMILY:MODEL[:FEATURES]"), cl::init("host"), cl::cat(SphcCat));
static cl::opt<double> SimdNeighbours(
    "simd-neighbours",
    cl::desc("--simd-pairs=auto (and once, perdest): the expected neighbour count from which a "
             "pair loop goes in SIMD lanes (default 30; codegen/SimdPairs.cpp). A measurement "
             "knob: 0 with --simd-pairs=once puts the 2D scenes' loops in the lanes too"),
    cl::value_desc("N"), cl::init(-1), cl::Hidden, cl::cat(SphcCat));
static cl::opt<double> SimdOnceNeighbours(
    "simd-once-neighbours",
    cl::desc("--simd-pairs=auto: the expected neighbour count from which a pair loop that the "
             "lanes print each pair once goes in them (default: --simd-neighbours'; a "
             "measurement knob)"),
    cl::value_desc("N"), cl::init(-1), cl::Hidden, cl::cat(SphcCat));
static cl::opt<double> SimdPerDestNeighbours(
    "simd-perdest-neighbours",
    cl::desc("--simd-pairs=auto: the expected neighbour count from which a pair loop that is "
             "per destination anyway (a periodic domain, no kept lists) goes in SIMD lanes "
             "(a measurement knob)"),
    cl::value_desc("N"), cl::init(-1), cl::Hidden, cl::cat(SphcCat));
static cl::opt<bool> NoLazyCells(
    "no-lazy-cells",
    cl::desc("With kept neighbour lists, build the search domain and cell lists at every "
             "neighbour update (default: only at the updates where a pair loop rebuilds its "
             "kept lists, the only ones that read them; the results are the same bit for bit)"),
    cl::init(false), cl::cat(SphcCat));
static cl::opt<bool> SingleUnit(
    "single-unit",
    cl::desc("Generate the solver as one translation unit (default, serial and openmp without "
             "--mpi: the phases, the pair loops, are defined after struct Scene and built as "
             "a unit of their own, in parallel with the rest, which shortens a cold build; "
             "the results are the same bit for bit). --emit=cpp prints the one-unit form; "
             "the split file a build compiled is scene.cpp in its cache directory (sphc -v)"),
    cl::init(false), cl::cat(SphcCat));
// --verlet-skin=auto (the default): the starting skin (the solver then chooses it,
// sphc/verlet_tune.h, where SkinTuner::kStart is the same 0.1), as a fraction of the support radius. Measured (callgrind
// and CPU time, docs/performance-log.md, "Neighbour lists kept across steps"): 0.1 pays more
// than 0.2 on the cube and the dam break (0.2 keeps ~1.33x (3D) the candidates of 0.1 in
// every list for fewer rebuilds).
static constexpr double kAutoVerletSkin = 0.1;

// Whether a group with `real = false` has a live equation with sources among its own
// equations: a neighbour loop whose destinations include the ghosts. The kept lists are not
// written for those (their ghosts' sums would see the kept ghost layer, wider than the one
// found at every evaluation).
static bool ghostPairLoops(const sphc::Plan& plan) {
  std::function<bool(const sphc::PlanGroup&)> walk = [&](const sphc::PlanGroup& g) {
    if (!g.real)
      for (int e : g.equations)
        if (plan.equations[e].live && !plan.equations[e].sources.empty()) return true;
    for (const auto& sub : g.subgroups)
      if (walk(*sub)) return true;
    return false;
  };
  return walk(plan.root);
}
enum class EmitKind { Exe, Cpp, OpenCL, Plan, Ast };
static cl::opt<std::string> KernelOpt(
    "kernel", cl::desc("Replace the scene's smoothing kernel (CubicSpline, QuinticSpline, "
                       "WendlandQuintic, ...; sphc study --vary kernel=...)"),
    cl::value_desc("name"), cl::cat(SphcCat));
static cl::opt<EmitKind, false, NamedValues<EmitKind>> Emit(
    "emit", cl::desc("What to produce:"), cl::init(EmitKind::Exe),
    cl::values(clEnumValN(EmitKind::Exe, "exe", "the solver executable (default)"),
               clEnumValN(EmitKind::Cpp, "cpp", "the generated C++ on stdout"),
               clEnumValN(EmitKind::OpenCL, "opencl", "the OpenCL C kernels of --backend=opencl"),
               clEnumValN(EmitKind::Plan, "plan", "the execution plan (as --report)"),
               clEnumValN(EmitKind::Ast, "ast", "the parsed main module")),
    cl::cat(SphcCat));
// The passes in the order the driver runs them: --dump-after=PASS prints the state after it.
enum class Pass { None, Parse, Options, Sema, Bodies, Prune, Properties, Hazards, Pairs, Ghosts,
                  Schedule };
static cl::opt<Pass, false, NamedValues<Pass>> DumpAfter(
    "dump-after", cl::desc("Print the state after a pass and stop:"), cl::init(Pass::None),
    cl::value_desc("pass"),
    cl::values(clEnumValN(Pass::Parse, "parse", "the AST of the main module"),
               clEnumValN(Pass::Options, "options", "the AST with compile-time options chosen"),
               clEnumValN(Pass::Sema, "sema", "the plan: arrays, equation instances, groups"),
               clEnumValN(Pass::Bodies, "bodies", "with what Clang found in the bodies"),
               clEnumValN(Pass::Prune, "prune", "with equations that reach nothing pruned"),
               clEnumValN(Pass::Properties, "properties", "with every array's property set"),
               clEnumValN(Pass::Hazards, "hazards", "after the group hazard check"),
               clEnumValN(Pass::Pairs, "pairs", "with the pair quantities of every loop"),
               clEnumValN(Pass::Ghosts, "ghosts", "with what periodic/mirror ghosts carry"),
               clEnumValN(Pass::Schedule, "schedule",
                          "how set-up and one time step run (phases, neighbour passes, steppers)")),
    cl::cat(SphcCat));
static cl::opt<bool> Report("report", cl::desc("Print the execution plan the compiler derived "
                                               "(arrays, properties, groups, pruned equations)"),
                            cl::cat(SphcCat));
static cl::list<std::string> Defines("D",
                                     cl::desc("Choose a compile-time option of the scene, as in "
                                              "-D scheme=edac (see `option` in the scene)"),
                                     cl::value_desc("name=choice"), cl::Prefix,
                                     cl::cat(SphcCat));
static cl::list<std::string> IncludeDirs("I", cl::desc("Add a directory to the import path"),
                                         cl::value_desc("dir"), cl::Prefix, cl::cat(SphcCat));
static cl::opt<std::string> Cxx("cxx", cl::desc("C++ compiler for the generated code"),
                                cl::cat(SphcCat));
static cl::opt<std::string> CxxFlags("cxxflags", cl::desc("Flags for the generated code "
                                                          "(replace the defaults)"),
                                     cl::cat(SphcCat));
static cl::opt<bool> NoCache("no-cache", cl::desc("Always rebuild, ignoring the cache"),
                             cl::cat(SphcCat));
static cl::opt<bool> WarningsAsErrors("Werror", cl::desc("Treat warnings as errors"),
                                      cl::cat(SphcCat));
static cl::opt<bool> Mpi("mpi", cl::desc("Build a distributed solver (MPI; run it with mpirun -np N): "
                                         "domain decomposition, migration, halo exchange"),
                         cl::cat(SphcCat));
static cl::opt<bool> GlobalIds("global-ids",
                               cl::desc("Give every particle a global id `gid` (unique over the arrays, in set-up order), "
                                        "written with the output (implied by --mpi)"),
                               cl::cat(SphcCat));
static cl::opt<bool> Verbose("v", cl::desc("Print the build command and timings"),
                             cl::cat(SphcCat));

static int fail() { return 1; }

int main(int argc, char** argv) {
  // `sphc study ...`: variants of a scene, their cost and accuracy (driver/Study.cpp).
  if (argc > 1 && std::string(argv[1]) == "study") return sphc::runStudy(argc, argv);
  llvm::InitLLVM init(argc, argv);
  cl::HideUnrelatedOptions(SphcCat);
  cl::SetVersionPrinter([](llvm::raw_ostream& os) { os << "sphc 0.1.0\n"; });
  cl::ParseCommandLineOptions(argc, argv,
                              "sphc: compiles a .sph SPH scene into a solver executable\n\n"
                              "  sphc study SCENE.sph --vary NAME=v1,v2 ... -o DIR: runs variants "
                              "and reports what accuracy costs in time (sphc study --help)\n");
  auto t0 = std::chrono::steady_clock::now();
  auto log = [&](const char* what) {
    if (!Verbose) return;
    double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    llvm::errs() << "sphc: " << what << " done at " << llvm::format("%.3f", s) << " s\n";
  };

  const sphc::Backend Backend = BackendOpt;
  Install install = locateInstall(argv[0]);
  // A solver of --backend=opencl needs the OpenCL runtime, built only where CMake found
  // OpenCL; say so before any work (--emit=cpp/opencl do not need it).
  if (Backend == sphc::Backend::OpenCL && Emit == EmitKind::Exe) {
    std::string why;
    if (!openclAvailable(install, why)) {
      llvm::errs() << "sphc: error: --backend=opencl is not available in this build: " << why
                   << "\n";
      return fail();
    }
  }
  // --mpi: the CPU backends in double precision, and a build that found MPI and Zoltan.
  if (Mpi && (Backend == sphc::Backend::OpenCL || PrecisionOpt == sphc::Precision::Single)) {
    llvm::errs() << "sphc: error: --mpi works with --backend=serial or openmp in double "
                    "precision (not with --backend=opencl or --precision=single yet)\n";
    return fail();
  }
  // --verlet-skin: the host pair loops of one process. auto: there,
  // with kAutoVerletSkin; a number: there only (an error elsewhere).
  // tuned: auto's support, with the skin and the sort chosen at run time (sphc/verlet_tune.h;
  // not the default: ~1% fewer instructions on the dam break, not seen in CPU time, and its
  // other sort steps move a particle of the nx = 30 cavity 0.04 dx past the lid at t = 6.5).
  const bool verletTuned = VerletSkin == "tuned";
  const bool verletAuto = VerletSkin == "auto" || verletTuned;
  double verletSkin = 0.0;
  if (verletAuto) {
    verletSkin = kAutoVerletSkin;
  } else if (VerletSkin != "off") {
    if (llvm::StringRef(VerletSkin).getAsDouble(verletSkin) ||
        !(verletSkin >= 0.0 && verletSkin <= 1.0)) {
      llvm::errs() << "sphc: error: --verlet-skin=" << VerletSkin
                   << ": auto, tuned, off, or the skin as a fraction of the support radius, from 0 "
                      "(off) to 1\n";
      return fail();
    }
  }
  // --kept-cells: off, or the skin of the device's kept cell tables.
  double keptCellsSkin = 0.0;
  if (KeptCells != "off" &&
      (llvm::StringRef(KeptCells).getAsDouble(keptCellsSkin) ||
       !(keptCellsSkin > 0.0 && keptCellsSkin <= 1.0))) {
    llvm::errs() << "sphc: error: --kept-cells=" << KeptCells
                 << ": off, or the skin as a fraction of the support radius, in (0, 1]\n";
    return fail();
  }
  // Why the lists cannot be kept in this build or scene ("": they can).
  auto verletUnsupported = [&](const Plan& p) -> std::string {
    if (Mpi) return "--mpi";
    if (Backend == sphc::Backend::OpenCL) return "--backend=opencl";
    if (p.domain.any() && ghostPairLoops(p))
      return "a periodic or mirror domain with a neighbour loop in a `real = false` group";
    // Kept with the lists, the ghosts let a particle sit up to half a support outside a
    // periodic box between sorts: an equation reading d_x then sees another value than the
    // wrapped one (tests/mpi periodic_drift's r = x). Kept by default where the scene reads
    // positions only as copies and increments, or in groups with a condition before which
    // the printer wraps every particle (analysis/PositionReads.cpp); else opt in with a number.
    // Single precision too since stop 37 (Taylor-Green nx = 100, EDAC and WCSPH: 0.96 of the
    // gathered lists' CPU time; docs/performance-log.md, "Loose ends (stop 37)").
    if (p.domain.any()) {
      const sphc::PositionReads reads = sphc::positionReads(p);
      if (!reads.refusal.empty())
        return "a periodic or mirror domain where " + reads.refusal +
               " (positions wrapped lazily with kept lists: --verlet-skin=F opts in)";
      if (verletAuto) {
        const std::string narrow = sphc::keptGhostSpanRefusal(p, verletSkin);
        if (!narrow.empty()) return narrow;
      }
    }
    if (!p.zones.empty()) return "inlets or outlets";
    return "";
  };
  if (!verletAuto && verletSkin > 0.0 && (Mpi || Backend == sphc::Backend::OpenCL)) {
    llvm::errs() << "sphc: error: --verlet-skin works with --backend=serial or openmp "
                    "(not with --backend=opencl or --mpi)\n";
    return fail();
  }
  if (Mpi && Emit == EmitKind::Exe) {
    std::string why;
    if (!mpiAvailable(install, why)) {
      llvm::errs() << "sphc: error: --mpi is not available in this build: " << why << "\n";
      return fail();
    }
  }
  llvm::SourceMgr sm;
  DiagnosticEngine diags(sm);
  diags.setWarningsAsErrors(WarningsAsErrors);

  // --- front end ---------------------------------------------------------------------
  std::vector<std::string> includes(IncludeDirs.begin(), IncludeDirs.end());
  bool parseOnly = Emit == EmitKind::Ast || DumpAfter == Pass::Parse;
  auto modules = loadModules(InputFile, parseOnly ? std::vector<std::string>{} : includes,
                             install.stdlibDir, diags);
  log("parse");
  if (parseOnly) {
    if (!modules.empty() && !diags.hasErrors()) printModule(*modules.front(), llvm::outs(), diags);
    return diags.hasErrors() ? fail() : 0;
  }
  if (modules.empty() || diags.hasErrors()) return fail();

  // --- compile-time options, semantic analysis and the analysis passes --------------------
  std::vector<ChosenOption> options;
  std::vector<std::string> defines(Defines.begin(), Defines.end());
  if (!selectOptions(modules, defines, diags, options)) return fail();
  log("options");
  if (DumpAfter == Pass::Options) {
    printModule(*modules.front(), llvm::outs(), diags);
    return 0;
  }
  auto plan = buildPlan(modules, diags);
  log("sema");
  if (!plan || diags.hasErrors()) return fail();
  plan->options = options;
  if (!KernelOpt.empty()) {
    std::string why;
    if (!overrideKernel(*plan, KernelOpt, why)) {
      llvm::errs() << "sphc: error: --kernel: " << why << "\n";
      return fail();
    }
  }
  plan->distributed = Mpi;
  // A limit's `remove` takes particles out of the host arrays between steps (the run loop,
  // sphc/sanity.h), which then go back where the scene computes (afterRemoval); a distributed
  // solver removes each rank's own and gathers them to rank 0 (sphc/mpi/output.h,
  // set_removal). Periodic or mirror sides refuse it (their ghosts are made from the
  // particles' places, kept with the neighbour lists).
  for (const auto& l : plan->limits) {
    if (!l.hasRemove || !plan->domain.any()) continue;
    diags.error(l.removeLoc, llvm::Twine("'remove' in limit '") + plan->arrays[l.array].name +
                                 "." + l.quantity + "' is not supported with periodic or "
                                 "mirror sides (their ghosts, kept with the neighbour lists): "
                                 "the run loop takes particles out of the host arrays between "
                                 "steps (serial, openmp, opencl, mpi), without periodic or "
                                 "mirror sides");
  }
  if (diags.hasErrors()) return fail();
  // Inlets and outlets are distributed (sphc/mpi/zones.h), metrics too: their sums are
  // combined over the ranks (sphc/mpi/comm.h, all_reduce).
  auto dump = [&](Pass pass) {
    if (DumpAfter != pass) return false;
    printPlan(*plan, llvm::outs(), false);
    return true;
  };
  if (dump(Pass::Sema)) return 0;

  {
    // Helper functions first: the bodies call them.
    std::vector<BodySource> sources;
    for (const auto& f : plan->functions) sources.push_back(f.source);
    for (const auto& b : plan->bodies) sources.push_back(b.source);
    auto facts = BodyAnalyzer(diags).analyze(sources);
    size_t nf = plan->functions.size();
    for (size_t i = 0; i < facts.size(); ++i)
      (i < nf ? plan->functions[i] : plan->bodies[i - nf]).facts = facts[i];
  }
  log("bodies");
  if (diags.hasErrors()) return fail();
  if (dump(Pass::Bodies)) return 0;

  if (!dropAbsentComponents(*plan, diags, !NoFoldZeroTerms)) return fail();
  if (!pruneEquations(*plan, diags)) return fail();
  if (dump(Pass::Prune)) return 0;
  if (!inferProperties(*plan, diags)) return fail();
  if (dump(Pass::Properties)) return 0;
  if (!checkHazards(*plan, diags)) return fail();
  if (dump(Pass::Hazards)) return 0;
  if (!selectPairQuantities(*plan, diags)) return fail();
  if (dump(Pass::Pairs)) return 0;
  if (!selectGhostProperties(*plan, diags)) return fail();
  if (dump(Pass::Ghosts)) return 0;
  if (!boundTimeStep(*plan, diags)) return fail();
  if (!checkInternalFlow(*plan, diags)) return fail();
  log("analysis");
  if (diags.hasErrors()) return fail();

  if (verletAuto) {
    // --verlet-skin=auto: on where the lists are written for, off (and said so) elsewhere.
    const std::string why = verletUnsupported(*plan);
    char skin[32];
    std::snprintf(skin, sizeof skin, "%g", kAutoVerletSkin);
    if (why.empty() && !verletTuned)
      plan->notes.push_back(std::string("neighbour lists kept across steps (--verlet-skin=auto): "
                                        "candidates within (1 + ") +
                            skin + ") times the support, rebuilt when particles moved too far" +
                            (plan->domain.any() ? " (the ghosts of periodic or mirror sides "
                                                  "kept with the lists)" : ""));
    else if (why.empty() && plan->domain.any())
      plan->notes.push_back(std::string("neighbour lists kept across steps (--verlet-skin=auto): "
                                        "candidates within (1 + F) times the support, F = ") +
                            skin + " with periodic or mirror sides (the ghosts kept with the "
                            "lists), rebuilt when particles moved too far");
    else if (why.empty())
      plan->notes.push_back(std::string("neighbour lists kept across steps (--verlet-skin=auto): "
                                        "candidates within (1 + F) times the support, rebuilt "
                                        "when particles moved too far; F chosen at run time "
                                        "from how far they move between rebuilds (from ") +
                            skin + "), the cell-order sort when they left that order");
    else
      plan->notes.push_back("neighbour lists gathered at every evaluation (--verlet-skin=auto): "
                            "lists kept across steps are not written for " + why);
    if (why.empty() && plan->domain.any()) {
      const sphc::PositionReads reads = sphc::positionReads(*plan);
      plan->notes.push_back(
          reads.wrapBefore.empty()
              ? std::string("periodic or mirror domain: positions read only as copies and "
                            "increments, wrapped into the box lazily (--verlet-skin=auto)")
              : "periodic or mirror domain: positions wrapped into the box lazily, and every "
                "particle before an evaluation where a group reading them runs (" +
                    reads.reader + "; its group's condition)");
    }
    if (!why.empty()) verletSkin = 0.0;
  }
  {  // h as one value per array (analysis/UniformH.cpp, stop 45)
    const std::string off = NoUniformH ? "--no-uniform-h"
                            : Mpi      ? "--mpi"
                            : Backend == sphc::Backend::OpenCL ? "--backend=opencl" : "";
    if (std::string note = uniformHNote(*plan, off); !note.empty()) plan->notes.push_back(note);
  }
  if (Report) printPlan(*plan, llvm::outs(), true);
  if (Emit == EmitKind::Plan) {
    if (!Report) printPlan(*plan, llvm::outs(), true);
    return 0;
  }

  // --- the back half: schedule, code generation and build ----------------------------
  auto schedule = buildSchedule(*plan, !NoGroupFusion);
  log("schedule");
  if (DumpAfter == Pass::Schedule) {
    printSchedule(*schedule, diags, llvm::outs());
    return 0;
  }
  if (verletSkin > 0.0 && ((schedule->domain && ghostPairLoops(*plan)) || !plan->zones.empty())) {
    llvm::errs() << "sphc: error: --verlet-skin: " << InputFile << " has "
                 << (plan->zones.empty() ? "a neighbour loop on periodic or mirror ghosts "
                                           "(a `real = false` group)"
                                         : "inlets or outlets")
                 << ", whose ghosts or particle changes renumber the neighbours at every step "
                    "(not supported)\n";
    return fail();
  }
  EmitOptions emitOpts{Backend, PrecisionOpt, GlobalIds || Mpi, FmaOpt == OnOff::On,
                       verletSkin, !NoHoist};
  emitOpts.ompMinParticles = OmpMinParticles;
  emitOpts.verletAuto = verletTuned;  // --verlet-skin=tuned: the skin and re-sort chosen at run time
  emitOpts.batchedTables = !NoBatchedTables;
  emitOpts.fusedLaunches = !NoFusedLaunches;
  emitOpts.fusedReductions = FusedReductions;
  emitOpts.keptCellsSkin = keptCellsSkin;
  emitOpts.splitUnits = !SingleUnit && Emit == EmitKind::Exe;
  emitOpts.symmetricPairs = !NoSymmetricPairs;
  // --pair-shared-values: on (the default, also bare) or off.
  const std::string sharedMode = PairSharedValues.empty() ? std::string("on") : PairSharedValues.getValue();
  if (sharedMode != "on" && sharedMode != "off") {
    llvm::errs() << "sphc: error: --pair-shared-values=" << sharedMode << ": it is on or off\n";
    return fail();
  }
  emitOpts.pairShared = sharedMode == "on";
  emitOpts.intPow = IntPowOpt == OnOff::On;
  emitOpts.lazyCells = !NoLazyCells;
  emitOpts.registerSums = !NoRegisterSums;
  if (KernelLanesOpt != "auto" && KernelLanesOpt != "on" && KernelLanesOpt != "off") {
    llvm::errs() << "sphc: error: --kernel-lanes=" << KernelLanesOpt << ": it is auto, on or off\n";
    return fail();
  }
  emitOpts.kernelLanes = KernelLanesOpt;
  emitOpts.skipSelfPairs = !NoSelfPairSkip;
  emitOpts.filteredLists = FilteredLists;
  emitOpts.skipEmptyLists = !NoSkipEmptyLists;
  emitOpts.initInAddBack = !NoInitInAddBack;
  emitOpts.ompRegions = !NoOmpRegions;
  emitOpts.constantValues = !NoConstantValues;
  // --simd-pairs: auto (the default), on (also bare), off; the lanes only on the CPU backends.
  const std::string simdMode = SimdPairs.empty() ? std::string("on") : SimdPairs.getValue();
  if (simdMode != "auto" && simdMode != "on" && simdMode != "off" && simdMode != "once" &&
      simdMode != "perdest" && simdMode != "cluster") {
    llvm::errs() << "sphc: error: --simd-pairs=" << simdMode
                 << ": it is auto, on, off, once or perdest\n";
    return fail();
  }
  emitOpts.simdPairs = simdMode != "off";
  // auto (= once since stop 35): the loops that pay in lanes, each pair once in them where
  // they may; perdest: the same loops per destination (stops 33-34's auto).
  // cluster (stop 37; not in the option's help): auto's loops, those each pair once in
  // lanes as cluster-pair tiles where they can (codegen/ClusterPairs.cpp), 2D too (there,
  // since stop 38, every loop each pair once the tiles take, at any neighbour count:
  // SimdPairs.cpp) and on any CPU; since stop 38 auto takes the tiles for its 3D loops where the CPU's verdict says
  // (SimdCpuVerdict::tiles), once keeps the lanes.
  emitOpts.simdPairsAuto = simdMode == "auto" || simdMode == "once" || simdMode == "perdest" ||
                           simdMode == "cluster";
  emitOpts.simdPairsOnce = simdMode == "auto" || simdMode == "once" || simdMode == "cluster";
  emitOpts.simdPairsCluster = simdMode == "cluster";
  emitOpts.cluster2d8x8 = Cluster2d8x8;
  emitOpts.cluster2dDoubled = Cluster2dDoubled;
  emitOpts.cluster3d2xmm = Cluster3d2xmm;
  emitOpts.clusterQueue = ClusterQueue;
  emitOpts.clusterSlotOrder = !NoSlotOrder;
  emitOpts.tileMathRecip = TileMathOpt != TileMath::Exact;
  emitOpts.tileMathBatched = TileMathOpt == TileMath::Batched;
  emitOpts.uniformH = !NoUniformH;
  emitOpts.simdAutoNeighbours = SimdNeighbours;
  emitOpts.simdOnceNeighbours = SimdOnceNeighbours;
  emitOpts.simdPerDestNeighbours = SimdPerDestNeighbours;
  // --simd-pairs=auto goes by the CPU the solver is built for: this machine's (the default
  // flags have -march=native), or the one --simd-cpu names (codegen/SimdCpu.cpp).
  {
    SimdCpu cpu;
    if (SimdCpuOpt == "host") {
      cpu = hostSimdCpu();
    } else if (std::string why; !parseSimdCpu(SimdCpuOpt, cpu, why)) {
      llvm::errs() << "sphc: error: --simd-cpu=" << SimdCpuOpt << ": " << why << "\n";
      return fail();
    }
    emitOpts.simdCpu = simdLanesOnCpu(cpu);
    if (simdMode == "once" || simdMode == "perdest" || simdMode == "cluster") {  // named: the lanes, whatever the CPU
      emitOpts.simdCpu.lanes = true;
      emitOpts.simdCpu.why = "--simd-pairs=" + simdMode + " names the lanes";
    }
    if (SimdCpuOpt == "host" && !CxxFlags.empty() &&
        CxxFlags.find("-march=native") == std::string::npos) {
      emitOpts.simdCpu.lanes = false;
      emitOpts.simdCpu.why = "--cxxflags without -march=native build for a CPU sphc does not "
                             "know (--simd-cpu names it): the scalar loops";
    }
    // auto (stop 38): its 3D loops each pair once in lanes as cluster-pair tiles
    // (codegen/ClusterPairs.cpp, where they can) on a CPU where the tiles were measured to pay
    // (codegen/SimdCpu.cpp); --simd-pairs=once keeps the lanes.
    if (simdMode == "auto" && emitOpts.simdCpu.lanes && emitOpts.simdCpu.tiles) {
      emitOpts.simdPairsCluster = true;
      emitOpts.simdPairsClusterAuto = true;
      emitOpts.simdPairsClusterAuto2d = emitOpts.simdCpu.tiles2d;  // (stop 41) the 2D loops too
    }
    if (Verbose && emitOpts.simdPairsAuto && emitOpts.simdPairs &&
        Backend != sphc::Backend::OpenCL && !Mpi)  // the CPU backends' lanes
      llvm::errs() << "sphc: --simd-pairs=auto: " << emitOpts.simdCpu.why
                   << (emitOpts.simdCpu.lanes ? ": pair loops with 30 or more neighbours "
                                                "expected, and those over their own array "
                                                "per destination anyway, in SIMD lanes"
                                              : ": no pair loop in SIMD lanes")
                   << " (--simd-pairs=on|off override it; --report says per loop)\n";
  }
  if (Report && Emit != EmitKind::OpenCL)
    for (const std::string& note : sphc::pairLoopNotes(*schedule, diags, emitOpts))
      llvm::outs() << "note: " << note << "\n";
  if (Emit == EmitKind::OpenCL) {
    llvm::outs() << emitOpenCL(*schedule, diags, emitOpts);
    return 0;
  }
  std::string cpp = emitCpp(*schedule, diags, emitOpts);
  log("emit");
  if (Emit == EmitKind::Cpp) {
    llvm::outs() << cpp;
    return 0;
  }
  if (Report && OutputFile.empty()) return 0;  // `sphc scene.sph --report` only reports

  std::string output = OutputFile;
  if (output.empty()) output = llvm::sys::path::stem(InputFile).str();
  BuildRequest req;
  req.cpp = cpp;
  req.output = output;
  req.cxx = Cxx;
  req.cxxflags = CxxFlags;
  req.backend = backendName(Backend);
  req.mpi = Mpi;
  req.useCache = !NoCache;
  // -fopenmp-simd where a loop is printed in SIMD lanes (codegen/SimdPairs.cpp,
  // ClusterPairs.cpp; the kernel lanes of SymmetricPairs.cpp).
  req.simd = cpp.find("#pragma omp simd") != std::string::npos;
  req.verbose = Verbose;
  BuildResult res = buildExecutable(install, req);
  log("build");
  if (!res.ok) {
    llvm::errs() << "sphc: error: " << res.message << "\n";
    return fail();
  }
  if (Verbose)
    llvm::errs() << "sphc: wrote " << output << (res.cached ? " (cached)" : "") << " in "
                 << llvm::format("%.2f", res.seconds) << " s\n";
  return 0;
}
