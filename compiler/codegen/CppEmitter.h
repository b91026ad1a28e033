// Code generation: a schedule (codegen/Schedule.h) to one readable C++ file that includes the
// runtime headers and defines `main`, printed by the printer of the chosen backend
// (codegen/Printer.h: CpuPrinter for serial and OpenMP, OpenCLPrinter for OpenCL C kernels
// launched from the host code). Every equation and stepper body becomes an inline function
// holding the body as written (with `// from file.sph:line` provenance and `#line`).
#pragma once

#include "codegen/SimdCpu.h"
#include "codegen/Schedule.h"
#include "frontend/Diagnostics.h"
#include "sema/Plan.h"

#include <string>
#include <vector>

namespace sphc {

// The backends: each is a printer of the schedule (codegen/*Printer.cpp).
enum class Backend { Serial, OpenMP, OpenCL };
// What the scene computes in: double, or single (float).
enum class Precision { Double, Single };
// "serial", "openmp", "opencl": as on the command line, in prog.backend and the build.
const char* backendName(Backend b);

struct EmitOptions {
  Backend backend = Backend::Serial;
  Precision precision = Precision::Double;
  // Every particle gets a global id `gid` (unique over the arrays, in set-up order), written with the output, so runs
  // can be compared particle by particle (--global-ids; always with --mpi).
  bool globalIds = false;
  // Products added to values in bodies are printed as explicit fused multiply-adds (std::fma,
  // OpenCL fma): rounded once and alike on every backend (--fma=off: as written).
  bool fma = true;
  // --verlet-skin=F: the CPU pair loops keep their neighbour candidates within (1 + F) times
  // the support across steps (sphc/verlet.h); 0: gathered from the cell lists every
  // evaluation.
  double verletSkin = 0.0;
  // Source-only subexpressions of pair-loop bodies that divide or call sqrt, pow, ... are
  // computed once per source particle before the neighbour pass (codegen/Hoist.cpp; CPU
  // backends, double precision, not --mpi); false (--no-hoist): computed per pair as written.
  // The values are the same bit for bit.
  bool hoist = true;
  // --omp-min-particles=N (OpenMP backend): a loop without neighbours (initialize, post_loop,
  // initialize_pair, hoisted values, reductions, steppers, the adaptive step's limits) over
  // fewer than N particles runs on the calling thread (an `if` clause): its few ns per
  // particle cost less than waking the team. 0: every such loop parallel, as before.
  long ompMinParticles = 0;
  // --verlet-skin=auto: the skin and the cell-order re-sort chosen at run time
  // (sphc/verlet_tune.h); false: the fixed skin verletSkin, re-sorted every REORDER_EVERY.
  bool verletAuto = false;
  // --backend=opencl: the cell tables of all sources of a neighbour update built in one set
  // of launches (sphc::ocl::build_tables); false (--no-batched-tables): CellTable::build per
  // source. The same tables, the same results bit for bit.
  bool batchedTables = true;
  // --backend=opencl: fewer kernel launches per step (docs/performance-log.md, "OpenCL: fewer
  // launches per step (stop 39)"); false (--no-fused-launches): a kernel each. The same
  // results bit for bit.
  bool fusedLaunches = true;
  // With fusedLaunches, --fused-reductions: the search domain's extents, min/max reductions
  // and the adaptive step's limits within the work groups of kernels that visit the
  // particles anyway (barriers in local memory), which saves their kernels. Off by default:
  // no gain measured on PoCL's CPU device, where those kernels profile slower.
  bool fusedReductions = false;
  // --backend=opencl: the cell tables kept across neighbour updates on cells of (1 + skin)
  // times the support while no source particle moved farther than the skin
  // (sphc::ocl::KeptTables, --kept-cells=F); 0 (the default): built at every update.
  // Needs batchedTables; scenes with periodic or mirror sides rebuild at every update.
  double keptCellsSkin = 0.0;
  // Pair loops whose destination array is their source evaluate each pair once for both
  // particles where the bodies allow it (codegen/SymmetricPairs.cpp; CPU backends with kept
  // neighbour lists); false (--no-symmetric-pairs): each destination gathers from all its
  // neighbours. The values are the same bit for bit.
  bool symmetricPairs = true;
  // Where a pair is evaluated once for both particles, the values of its loop bodies that are
  // the same (or negated) for the mirrored pair (body/PairShared.cpp) are computed once and
  // passed to both calls (codegen/PairShared.cpp; CPU backends, double precision, not --mpi,
  // not --simd-pairs); false (--pair-shared-values=off): each call computes them. The values
  // are the same bit for bit.
  bool pairShared = false;
  // `pow` in the bodies of the CPU backends (double precision) is sphc::pow_int (sphc/pow.h):
  // by multiplications where the exponent is an integer of magnitude <= 8, the C library's
  // pow otherwise; false (--int-pow=off): the C library's pow everywhere.
  bool intPow = true;
  // With kept lists (CPU, no periodic or mirror domain) the search domain and the moving
  // sources' cell lists are built only at the updates where a pair loop rebuilds its lists
  // (codegen/CpuLazyCells.inc); false (--no-lazy-cells): at every update. Bitwise the same.
  bool lazyCells = true;
  // The phases (the pair loops), and compute_accelerations, step and adaptive_dt (the
  // per-step code inlined into them), are defined out of struct Scene, after it, between the
  // marker lines below, and the scene's namespace is named (sphc_scene) so that the build
  // can compile them as a translation unit of their own, in parallel with the rest
  // (driver/Build.cpp); serial and openmp, not --mpi. false (--single-unit): the old single
  // unit, byte for byte. The same object code either way, up to where functions are placed.
  bool splitUnits = true;
  // In the CPU pair loops the destination's sums (the d_ properties the loop bodies
  // accumulate at d_idx, by literal components) are locals across its neighbours, loaded
  // before them and stored after them (codegen/RegisterSums.cpp; serial and openmp, double
  // precision, not --mpi); false (--no-register-sums): updated in memory at every pair, as
  // before. The values are the same bit for bit.
  bool registerSums = true;
  // In the serial each-pair-once loops (codegen/SymmetricPairs.cpp) whose kernel values are
  // WIJ and DWIJ (of HIJ), a destination's candidates first in SIMD lanes: the cut-off, W and
  // the gradient's factor of each, into short arrays; then the bodies over the neighbours
  // among them, in the list's order (kernelLanesRefusal says where). "auto" (--kernel-lanes,
  // the default): where measured to pay, a scene of one array in a periodic or mirror domain
  // (Taylor-Green); "on": wherever the loop allows it; "off": the kernel in the pair loop, as
  // before. The values are the same bit for bit (the same IEEE operations per candidate).
  std::string kernelLanes = "auto";
  // In the each-pair-once loops of one array (codegen/SymmetricPairs.cpp) whose bodies all
  // add only zeros at the self pair (body/SelfPair.cpp: momentum, continuity, XSPH, the
  // shifting's sums, ...), particle i's pairs start after i itself; false
  // (--no-self-pair-skip): the self pair is evaluated as before. The values are the same bit
  // for bit but for the sign of a sum that is -0 when its self pair comes (docs/performance.md).
  bool skipSelfPairs = true;
  // --filtered-lists: the per-destination loops filter the kept list, then loop (CpuPrinter.cpp).
  bool filteredLists = false;
  // The CPU pair loops of two arrays with kept lists (fluid <- wall; CpuPrinter.cpp and
  // SymmetricPairs.cpp's emitCrossPass): after a build of the lists, only the destinations
  // whose kept list is not empty (sphc/verlet.h, find_occupied); false
  // (--no-skip-empty-lists): every destination at every evaluation. The same bits.
  bool skipEmptyLists = true;
  // The cluster-pair tiles' add-back runs the destination's initialize per particle where
  // the tiles are its first pass and write only slot sums that the initialize alone writes
  // (ClusterPairs.cpp, initInAddBackRefusal); false (--no-init-in-add-back): the initialize
  // in its own loop before the pass. The same bits.
  bool initInAddBack = true;
  // OpenMP: a destination's per-particle loops before its first pair loop (initialize, the
  // hoisted values) in one parallel region of `omp for nowait` loops (OmpRegions.cpp);
  // false (--no-omp-regions): each loop its own region. The same bits.
  bool ompRegions = true;
  // The equation instances' values that are literals (`dim = 2`, defaults such as R = 0.2)
  // as constants of the C++ (HostProgram.cpp); false (--no-constant-values): members set at
  // set-up, as the others. The values are the same bit for bit.
  bool constantValues = true;
  // --simd-pairs: the CPU pair loops that allow it (codegen/SimdPairs.cpp) are printed per
  // destination with the neighbour loop under `#pragma omp simd reduction(+: sums)`, the pair
  // quantities scalars (XIJ_0, ...), the bodies' calls of their NAME_loop_simd form; the
  // build adds -fopenmp-simd. false (the default): today's loops, byte for byte. The sums are
  // reassociated across the SIMD lanes: not bitwise the scalar loop's (serial and OpenMP with
  // the switch are bitwise equal).
  bool simdPairs = false;
  // --simd-pairs=auto (the driver's default; with simdPairs true): the SIMD form only for the
  // loops where it pays (codegen/SimdPairs.cpp, simdPairsAutoChoice): those whose expected
  // neighbour count reaches kSimdAutoNeighbours.
  bool simdPairsAuto = false;
  // --simd-pairs=auto: whether the lanes pay on the CPU the solver is built for, and why
  // (codegen/SimdCpu.h; the driver reads the host's cpuid, or --simd-cpu).
  SimdCpuVerdict simdCpu;
  // --simd-pairs=auto or once (with simdPairs and simdPairsAuto: auto's choice of loops; not
  // --simd-pairs=perdest, stop 33-34's auto): a loop in
  // lanes that may evaluate each pair once (same array, kept lists, double precision) is
  // printed each pair once in the lanes, the values the pair shares once per pair, the source
  // side added by a masked scatter (codegen/SimdPairs.cpp, emitSymmetricSimdLoops).
  bool simdPairsOnce = false;
  // --simd-pairs=cluster (opt-in, stop 37; with simdPairsOnce): a loop that simdPairsOnce
  // prints each pair once in lanes is printed as cluster-pair tiles where it can
  // (codegen/ClusterPairs.cpp: serial and OpenMP (stop 38: bitwise the serial tiles), double
  // precision, 2D and 3D; sphc/cluster_pairs.h),
  // else as simdPairsOnce prints it, the generated code saying why.
  bool simdPairsCluster = false;
  // --simd-pairs=auto (stop 38): simdPairsCluster set by auto's rule (the CPU's verdict,
  // SimdCpuVerdict::tiles), for the 3D loops only; a 2D loop stays in the lanes silently.
  bool simdPairsClusterAuto = false;
  // --simd-pairs=auto (stop 41): the 2D loops too, as --simd-pairs=cluster takes them
  // (SimdCpuVerdict::tiles2d).
  bool simdPairsClusterAuto2d = false;
  // --cluster-2d-8x8 (hidden, a measurement knob; stop 39): the 2D tiles in stop 37-38's
  // 8 x 8 form (one i x 8 j's per register) instead of the 2xMM form (codegen/ClusterPairs.cpp).
  bool cluster2d8x8 = false;
  // --cluster-2d-doubled (hidden, a measurement knob; stop 41): the 2xMM tiles in slot order
  // read their j side from per-evaluation copies doubled per cluster (stops 39-40) instead of
  // the particles' arrays (codegen/ClusterPairs.cpp).
  bool cluster2dDoubled = false;
  // The 3D tiles in the 2xMM form (4-clusters, registers of 2 i's x 4 j's) as the 2D tiles,
  // not 8 x 8 (stop 42): --cluster-3d-2xmm (hidden; --simd-pairs=auto keeps 8 x 8 on every
  // CPU: measured no faster).
  bool cluster3d2xmm = false;
  // --cluster-queue (stop 43): the 8 x 8 tiles' pairs within the support compacted into
  // registers of 8 pairs (codegen/ClusterPairs.cpp), under AVX-512 with VBMI2 (measured
  // slower than the rows since the SIMD builds' 512-bit vectors, stop 44).
  bool clusterQueue = false;
  // --no-slot-order (hidden, a measurement knob; stop 40): false keeps the tiles' slot-order
  // copies and add-backs; true (the default) keeps the particles in the tiles' slot order.
  bool clusterSlotOrder = true;
  // --tile-math (stop 41): true (recip, the default) prints the cluster-pair tiles' kernel
  // values in their reciprocal forms (Kernel::w_tile, Kernel::gradient_factor_tile: q = r (1/h),
  // 1/r = r (1/r^2), no division after the square root); false (exact) the forms of the
  // other loops (Kernel::w, Kernel::gradient_factor).
  bool tileMathRecip = true;
  // --tile-math=batched (stop 45, the default): with tileMathRecip, a tile lane's reciprocals
  // 1/r^2 and 1/RHOIJ from one division where it needs both (sphc::tile_reciprocals; 1/h a
  // division of its own); false (recip, exact) a division for each.
  bool tileMathBatched = true;
  // --simd-neighbours=N: auto's threshold on a loop's expected neighbour count
  // (kSimdAutoNeighbours by default; a measurement knob: 0 puts every loop that allows it in
  // lanes under auto's rule, e.g. with --simd-pairs=once the 2D scenes' loops).
  double simdAutoNeighbours = -1;  // < 0: kSimdAutoNeighbours
  // --simd-once-neighbours=N: the threshold of a loop the lanes print each pair once (< 0:
  // simdAutoNeighbours); --simd-perdest-neighbours=N: of a loop over its own array that is per
  // destination anyway (no each pair once: a periodic or mirror domain, zones; < 0:
  // kSimdPerDestNeighbours). Measurement knobs.
  double simdOnceNeighbours = -1;
  double simdPerDestNeighbours = -1;
  // The CPU pair loops (serial and openmp, not --mpi) of a destination or source array whose h
  // is one value for the whole run (analysis/UniformH.h: nothing writes it, its initial value
  // is an expression of params) read it once per pass, and compute hmax, the cut-off's
  // RADIUS2 * hmax * hmax and HIJ once (codegen/Bodies.cpp, beginUniformH; stop 45); false
  // (--no-uniform-h): per particle and per pair, as before. The same results bit for bit.
  bool uniformH = true;
};

// --simd-pairs=auto: a pair loop is put in SIMD lanes where its expected neighbour count
// (the kernel support's ball over dx^dim) reaches this (docs/performance-log.md, "SIMD pair loops
// chosen by the compiler": the measurements between which it lies). Where h or dx is not
// known before the run, by the dimension: 3D yes, 1D and 2D no (with h = 1.3 dx and a support
// of 2 h, 74 and 21 neighbours).
inline constexpr double kSimdAutoNeighbours = 30.0;
// --simd-pairs=auto: a loop over its own array that is per destination anyway (no each pair
// once to lose: a periodic or mirror domain; zones where every pair body vanishes at the
// support, ScenePrinter::zonesLanesRefusal) goes in the lanes at any
// expected count in 2D and 3D (stop 36, Intel with gathers: 0.84-0.97 of the scalar step at
// ~28 neighbours, 0.79-0.81 for a per-destination loop at ~21; stop 33, AMD Zen 5: 0.89 at
// ~28; stop 37, zones: 0.76-0.82 the channel).
inline constexpr double kSimdPerDestNeighbours = 0.0;

// The lines around the out-of-class phases of a split solver (EmitOptions::splitUnits).
inline constexpr const char* kPhasesBeginMarker =
    "// ---- sphc: the phases, a translation unit of their own when sphc builds";
inline constexpr const char* kPhasesEndMarker = "// ---- sphc: end of the phases";

// The solver's C++ for a schedule (codegen/Schedule.h) of an analysed plan.
std::string emitCpp(const Schedule& sched, const DiagnosticEngine& diags,
                    const EmitOptions& opts);
// --report: a note per pair loop, each pair once for both particles or per destination and
// why, as the backend's printer prints it (codegen/SymmetricPairs.cpp).
std::vector<std::string> pairLoopNotes(const Schedule& sched, const DiagnosticEngine& diags,
                                       const EmitOptions& opts);
// --backend=opencl: the OpenCL C of the scene's kernels alone (what --emit=opencl prints).
std::string emitOpenCL(const Schedule& sched, const DiagnosticEngine& diags, EmitOptions opts);

}  // namespace sphc
