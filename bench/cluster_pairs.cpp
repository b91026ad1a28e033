// The cube's fluid <- fluid interaction (bench/cube.sph: continuity, momentum with artificial
// viscosity, XSPH; cubic spline, h = 1.5 dx) on its 103,823-particle lattice, in three forms,
// timed by hand (docs/performance-log.md, "A cluster-pair SIMD tile kernel, measured by hand
// (stop 36)"; issue 16, the 25%-of-peak target). Not a test of the solver: a prototype that
// prints figures, self-checking (exit 1 if a form's sums disagree with form (a)).
//
//   (a) today's scalar form (--simd-pairs=off): per destination i, its kept list (candidates
//       within 1.1 x 2h, in index order), the pairs j > i, the cut-off a branch, each pair
//       once: i's sums in locals, j's added in memory (the mirrored calls).
//   (b) today's lane form (--simd-pairs=auto on this CPU, SimdPairs.cpp
//       emitSymmetricSimdLoops): the same lists, j > i in chunks of 8 lanes under
//       `#pragma omp simd`, the cut-off a mask, the source's values gathered and its sums
//       gathered and scattered back under the mask.
//   (c) cluster pairs (GROMACS' nbnxm scheme, Pall & Hess 2013): the particles sorted into
//       columns of the x-y plane, by z within a column, cut into clusters of 4 or 8; a list
//       of cluster pairs (i-cluster, j-cluster of 8) whose bounding boxes lie within the list
//       radius; per pair of clusters a tile of CI x 8 pairs: each i broadcast, the j-cluster's
//       values CONTIGUOUS vector loads, the cut-off (and j > i on the diagonal tile) a mask;
//       the j sums accumulated in registers over the tile's i's and added to memory with one
//       load-add-store per sum, the i sums in vectors across the i-cluster's list, reduced
//       once. No gathers, no scatters. AVX-512 intrinsics.
//       Arithmetic: "exact" = the operations of (a) (correctly rounded div and sqrt, the same
//       fma's); "rcp" = the divisions and the square root replaced by vrcp14pd / vrsqrt14pd
//       and two Newton steps each (results within a few ulp of the exact ones); "rcpdiv" the
//       divisions only; "lean" rcp with fewer vector operations. Lists at (1 + skin) 2h or,
//       "cut", at 2h (a per-step pruning's list). Also "omp": the tile as `#pragma omp simd`
//       over the 8 j's with the generated lane body verbatim (what GCC makes of it).
//
// The bodies of (a) and (b) are the generated C++ of `sphc bench/cube.sph` (main 6e571af,
// --simd-pairs=auto on this Intel Xeon: the lanes; --simd-pairs=off: the scalar loop),
// copied below verbatim (#line directives removed); the kernel is the runtime's
// (sphc/kernels.h). (c) does the same operations in vectors (the "exact" arithmetic).
//
// Results: the sums are the same up to the summation order: (a) adds i's terms in list order
// into one scalar and j's in increasing i; (b) i's terms in 8 lane partial sums (reduced at
// the end of i's list), j's in increasing i; (c) i's terms in 8 lane partial sums across its
// cluster pairs, j's summed over the tile's i's first, then added per tile. The check: per
// sum, max |X - a| / max |a| <= 1e-12 (the sums start from 0 here, so the pairs' terms are
// compared, not the initial values).
//
// Build (the flags of a solver with lanes: buildinfo cxxflags + simd_flags):
//   c++ -std=c++17 -O3 -march=native -fno-math-errno -ffp-contract=off -fopenmp-simd
//       -mtune-ctrl=use_gather -I runtime/include bench/cluster_pairs.cpp
//       runtime/src/cluster_pairs.cpp -o cluster_pairs
// (the sort into clusters, the 8 x 8 cluster-pair lists and their pruning are the runtime's,
// sphc/cluster_pairs.h, since stop 37; tests/CMakeLists.txt links the runtime library)
// Run: ./cluster_pairs [--nx 47] [--hdx 1.5] [--uniform-velocity] [--reps 7] [--pert 0.05]
//                      [--skin 0.1] [--column DX] [--forms LIST] (--help: the forms' names)
// Built for AVX-512F, needs it (exits 77 without it); built without, it has forms (a), (b) and
// the `omp` tiles only.
#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <new>
#include <numeric>
#include <utility>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include <time.h>

#include "bench_options.h"
#include "bench_tiles.h"
#include "sphc/cluster_pairs.h"
#include "sphc/kernels.h"

namespace {

using namespace bench::tiles;  // cpu_now, median, the vector operations, clock_estimate

constexpr int DIM = 3;
using Kernel = sphc::CubicSpline<DIM>;
constexpr double RADIUS2 = Kernel::radius_scale * Kernel::radius_scale;

// ---- The loop bodies: the generated C++ of bench/cube.sph, verbatim ----
// equation ContinuityEquation, method loop, from wcsph.sph:73
static inline void ContinuityEquation_loop(int d_idx, int s_idx, double t, double dt, const double* VIJ, const double* DWIJ, double* d_arho, const double* s_m, double pair_shared0) {
    double vijdotdwij = pair_shared0;
    d_arho[d_idx] = std::fma(s_m[s_idx], vijdotdwij, d_arho[d_idx]);
  
}

// equation ContinuityEquation, method loop, from wcsph.sph:73: a value the pair shares, the same for the mirrored pair (once per pair
// where each pair is evaluated once; codegen/PairShared.cpp; --pair-shared-values=off: in each call)
//   VIJ[0] * DWIJ[0] + VIJ[1] * DWIJ[1] + VIJ[2] * DWIJ[2]
static inline double ContinuityEquation_loop_pairshared0(int d_idx, int s_idx, double t, double dt, const double* VIJ, const double* DWIJ, const double* s_m) {
  return std::fma(VIJ[2], DWIJ[2], std::fma(VIJ[0], DWIJ[0], VIJ[1] * DWIJ[1]));
}

// equation ContinuityEquation, method loop, from wcsph.sph:73: the destination's sums in locals (acc_NAME, accK_NAME: component K;
// codegen/RegisterSums.cpp)
static inline void ContinuityEquation_loop_sums(int d_idx, int s_idx, double t, double dt, const double* VIJ, const double* DWIJ, double& acc_arho, const double* s_m, double pair_shared0) {
    double vijdotdwij = pair_shared0;
    acc_arho = std::fma(s_m[s_idx], vijdotdwij, acc_arho);
  
}

// equation ContinuityEquation, method loop, from wcsph.sph:73: the destination's sums in locals (acc_NAME, accK_NAME: component K;
// the pair quantities' components scalars, XIJ_0 for XIJ[0]: the SIMD pair loops,
// codegen/SimdPairs.cpp)
static inline void ContinuityEquation_loop_simd(int d_idx, int s_idx, double t, double dt, double VIJ_0, double VIJ_1, double VIJ_2, double DWIJ_0, double DWIJ_1, double DWIJ_2, double& acc_arho, const double* s_m, double pair_shared0) {
    double vijdotdwij = pair_shared0;
    acc_arho = std::fma(s_m[s_idx], vijdotdwij, acc_arho);
  
}

// equation ContinuityEquation, method loop, from wcsph.sph:73: a value the pair shares, the same for the mirrored pair (once per pair
// where each pair is evaluated once; codegen/PairShared.cpp; --pair-shared-values=off: in each call)
//   VIJ_0 * DWIJ_0 + VIJ_1 * DWIJ_1 + VIJ_2 * DWIJ_2
static inline double ContinuityEquation_loop_pairshared0_simd(int d_idx, int s_idx, double t, double dt, double VIJ_0, double VIJ_1, double VIJ_2, double DWIJ_0, double DWIJ_1, double DWIJ_2, const double* s_m) {
  return std::fma(VIJ_2, DWIJ_2, std::fma(VIJ_0, DWIJ_0, VIJ_1 * DWIJ_1));
}

// equation ContinuityEquation, method loop, from wcsph.sph:73: the destination's sums in locals (acc_NAME, accK_NAME: component K;
// the pair quantities' components scalars, XIJ_0 for XIJ[0]: the SIMD pair loops,
// codegen/SimdPairs.cpp)
// For the mirrored calls of each pair once in SIMD lanes: the source's properties as values
// (sval_NAME, particle d_idx's).
static inline void ContinuityEquation_loop_simd_mirror(int d_idx, int s_idx, double t, double dt, double VIJ_0, double VIJ_1, double VIJ_2, double DWIJ_0, double DWIJ_1, double DWIJ_2, double& acc_arho, double sval_m, double pair_shared0) {
    double vijdotdwij = pair_shared0;
    acc_arho = std::fma(sval_m, vijdotdwij, acc_arho);
  
}

// equation MomentumEquation, method loop, from wcsph.sph:99
static inline void MomentumEquation_loop(int d_idx, int s_idx, double t, double dt, const double* XIJ, const double* VIJ, const double* DWIJ, double R2IJ, double HIJ, double RHOIJ1, double EPS, double alpha, double beta, double* d_au, double* d_av, double* d_aw, const double* d_cs, const double* d_p, const double* d_rho, const double* s_cs, const double* s_m, const double* s_p, const double* s_rho, const double* s_hoisted0, double d_hoisted0, double pair_shared0, double pair_shared1, double pair_shared2) {
    double rhoi = d_rho[d_idx];
    double rhoj = s_rho[s_idx];
    double tmp = pair_shared0;

    double vijdotxij = pair_shared1;
    double piij = 0.0;
    piij = pair_shared2;





    double f = -s_m[s_idx] * (tmp + piij);
    d_au[d_idx] = std::fma(f, DWIJ[0], d_au[d_idx]);
    d_av[d_idx] = std::fma(f, DWIJ[1], d_av[d_idx]);
    d_aw[d_idx] = std::fma(f, DWIJ[2], d_aw[d_idx]);
  
}

// equation MomentumEquation, method loop, from wcsph.sph:99: once per source particle (hoisted out of the pair loop; --no-hoist: per pair)
//   s_p[s_idx] / (rhoj * rhoj)
static inline double MomentumEquation_loop_hoisted0(int s_idx, const double* s_p, const double* s_rho) {
  const double rhoj = s_rho[s_idx];
  return s_p[s_idx] / (rhoj * rhoj);
}

// equation MomentumEquation, method loop, from wcsph.sph:99: once per destination particle (hoisted out of the pair loop; --no-hoist: per pair)
//   d_p[d_idx] / (rhoi * rhoi)
static inline double MomentumEquation_loop_dhoisted0(int d_idx, const double* d_p, const double* d_rho) {
  const double rhoi = d_rho[d_idx];
  return d_p[d_idx] / (rhoi * rhoi);
}

// equation MomentumEquation, method loop, from wcsph.sph:99: a value the pair shares, the same for the mirrored pair (once per pair
// where each pair is evaluated once; codegen/PairShared.cpp; --pair-shared-values=off: in each call)
//   d_hoisted0 + s_hoisted0[s_idx]
static inline double MomentumEquation_loop_pairshared0(int d_idx, int s_idx, double t, double dt, const double* XIJ, const double* VIJ, const double* DWIJ, double R2IJ, double HIJ, double RHOIJ1, double EPS, double alpha, double beta, const double* d_cs, const double* d_p, const double* d_rho, const double* s_cs, const double* s_m, const double* s_p, const double* s_rho, const double* s_hoisted0, double d_hoisted0) {
  const double rhoi = d_rho[d_idx];
  const double rhoj = s_rho[s_idx];
  return d_hoisted0 + s_hoisted0[s_idx];
}

// equation MomentumEquation, method loop, from wcsph.sph:99: a value the pair shares, the same for the mirrored pair (once per pair
// where each pair is evaluated once; codegen/PairShared.cpp; --pair-shared-values=off: in each call)
//   VIJ[0] * XIJ[0] + VIJ[1] * XIJ[1] + VIJ[2] * XIJ[2]
static inline double MomentumEquation_loop_pairshared1(int d_idx, int s_idx, double t, double dt, const double* XIJ, const double* VIJ, const double* DWIJ, double R2IJ, double HIJ, double RHOIJ1, double EPS, double alpha, double beta, const double* d_cs, const double* d_p, const double* d_rho, const double* s_cs, const double* s_m, const double* s_p, const double* s_rho, const double* s_hoisted0, double d_hoisted0) {
  return std::fma(VIJ[2], XIJ[2], std::fma(VIJ[0], XIJ[0], VIJ[1] * XIJ[1]));
}

// equation MomentumEquation, method loop, from wcsph.sph:99: a value the pair shares, the same for the mirrored pair (once per pair
// where each pair is evaluated once; codegen/PairShared.cpp; --pair-shared-values=off: in each call)
//   piij after if (vijdotxij < 0.0) { double cij = 0.5 * (d_cs[d_idx] + s_cs[s_idx]); double muij = HI...
static inline double MomentumEquation_loop_pairshared2(int d_idx, int s_idx, double t, double dt, const double* XIJ, const double* VIJ, const double* DWIJ, double R2IJ, double HIJ, double RHOIJ1, double EPS, double alpha, double beta, const double* d_cs, const double* d_p, const double* d_rho, const double* s_cs, const double* s_m, const double* s_p, const double* s_rho, const double* s_hoisted0, double d_hoisted0) {
  const double vijdotxij = std::fma(VIJ[2], XIJ[2], std::fma(VIJ[0], XIJ[0], VIJ[1] * XIJ[1]));
  double piij = 0.0;
  if (vijdotxij < 0.0) {
      double cij = 0.5 * (d_cs[d_idx] + s_cs[s_idx]);
      double muij = HIJ * vijdotxij / (R2IJ + EPS);
      piij = std::fma(-alpha * cij, muij, beta * muij * muij) * RHOIJ1;
    }
  return piij;
}

// equation MomentumEquation, method loop, from wcsph.sph:99: the destination's sums in locals (acc_NAME, accK_NAME: component K;
// codegen/RegisterSums.cpp)
static inline void MomentumEquation_loop_sums(int d_idx, int s_idx, double t, double dt, const double* XIJ, const double* VIJ, const double* DWIJ, double R2IJ, double HIJ, double RHOIJ1, double EPS, double alpha, double beta, double& acc_au, double& acc_av, double& acc_aw, const double* d_cs, const double* d_p, const double* d_rho, const double* s_cs, const double* s_m, const double* s_p, const double* s_rho, const double* s_hoisted0, double d_hoisted0, double pair_shared0, double pair_shared1, double pair_shared2) {
    double rhoi = d_rho[d_idx];
    double rhoj = s_rho[s_idx];
    double tmp = pair_shared0;

    double vijdotxij = pair_shared1;
    double piij = 0.0;
    piij = pair_shared2;





    double f = -s_m[s_idx] * (tmp + piij);
    acc_au = std::fma(f, DWIJ[0], acc_au);
    acc_av = std::fma(f, DWIJ[1], acc_av);
    acc_aw = std::fma(f, DWIJ[2], acc_aw);
  
}

// equation MomentumEquation, method loop, from wcsph.sph:99: the destination's sums in locals (acc_NAME, accK_NAME: component K;
// the pair quantities' components scalars, XIJ_0 for XIJ[0]: the SIMD pair loops,
// codegen/SimdPairs.cpp)
static inline void MomentumEquation_loop_simd(int d_idx, int s_idx, double t, double dt, double XIJ_0, double XIJ_1, double XIJ_2, double VIJ_0, double VIJ_1, double VIJ_2, double DWIJ_0, double DWIJ_1, double DWIJ_2, double R2IJ, double HIJ, double RHOIJ1, double EPS, double alpha, double beta, double& acc_au, double& acc_av, double& acc_aw, double dval_cs, const double* d_p, double dval_rho, const double* s_cs, const double* s_m, const double* s_p, const double* s_rho, const double* s_hoisted0, double d_hoisted0, double pair_shared0, double pair_shared1, double pair_shared2) {
    double rhoi = dval_rho;
    double rhoj = s_rho[s_idx];
    double tmp = pair_shared0;

    double vijdotxij = pair_shared1;
    double piij = 0.0;
    piij = pair_shared2;





    double f = -s_m[s_idx] * (tmp + piij);
    acc_au = std::fma(f, DWIJ_0, acc_au);
    acc_av = std::fma(f, DWIJ_1, acc_av);
    acc_aw = std::fma(f, DWIJ_2, acc_aw);
  
}

// equation MomentumEquation, method loop, from wcsph.sph:99: a value the pair shares, the same for the mirrored pair (once per pair
// where each pair is evaluated once; codegen/PairShared.cpp; --pair-shared-values=off: in each call)
//   d_hoisted0 + s_hoisted0[s_idx]
static inline double MomentumEquation_loop_pairshared0_simd(int d_idx, int s_idx, double t, double dt, double XIJ_0, double XIJ_1, double XIJ_2, double VIJ_0, double VIJ_1, double VIJ_2, double DWIJ_0, double DWIJ_1, double DWIJ_2, double R2IJ, double HIJ, double RHOIJ1, double EPS, double alpha, double beta, double dval_cs, const double* d_p, double dval_rho, const double* s_cs, const double* s_m, const double* s_p, const double* s_rho, const double* s_hoisted0, double d_hoisted0) {
  const double rhoi = dval_rho;
  const double rhoj = s_rho[s_idx];
  return d_hoisted0 + s_hoisted0[s_idx];
}

// equation MomentumEquation, method loop, from wcsph.sph:99: a value the pair shares, the same for the mirrored pair (once per pair
// where each pair is evaluated once; codegen/PairShared.cpp; --pair-shared-values=off: in each call)
//   VIJ_0 * XIJ_0 + VIJ_1 * XIJ_1 + VIJ_2 * XIJ_2
static inline double MomentumEquation_loop_pairshared1_simd(int d_idx, int s_idx, double t, double dt, double XIJ_0, double XIJ_1, double XIJ_2, double VIJ_0, double VIJ_1, double VIJ_2, double DWIJ_0, double DWIJ_1, double DWIJ_2, double R2IJ, double HIJ, double RHOIJ1, double EPS, double alpha, double beta, double dval_cs, const double* d_p, double dval_rho, const double* s_cs, const double* s_m, const double* s_p, const double* s_rho, const double* s_hoisted0, double d_hoisted0) {
  return std::fma(VIJ_2, XIJ_2, std::fma(VIJ_0, XIJ_0, VIJ_1 * XIJ_1));
}

// equation MomentumEquation, method loop, from wcsph.sph:99: a value the pair shares, the same for the mirrored pair (once per pair
// where each pair is evaluated once; codegen/PairShared.cpp; --pair-shared-values=off: in each call)
//   piij after if (vijdotxij < 0.0) { double cij = 0.5 * (dval_cs + s_cs[s_idx]); double muij = HIJ * ...
static inline double MomentumEquation_loop_pairshared2_simd(int d_idx, int s_idx, double t, double dt, double XIJ_0, double XIJ_1, double XIJ_2, double VIJ_0, double VIJ_1, double VIJ_2, double DWIJ_0, double DWIJ_1, double DWIJ_2, double R2IJ, double HIJ, double RHOIJ1, double EPS, double alpha, double beta, double dval_cs, const double* d_p, double dval_rho, const double* s_cs, const double* s_m, const double* s_p, const double* s_rho, const double* s_hoisted0, double d_hoisted0) {
  const double vijdotxij = std::fma(VIJ_2, XIJ_2, std::fma(VIJ_0, XIJ_0, VIJ_1 * XIJ_1));
  double piij = 0.0;
  if (vijdotxij < 0.0) {
      double cij = 0.5 * (dval_cs + s_cs[s_idx]);
      double muij = HIJ * vijdotxij / (R2IJ + EPS);
      piij = std::fma(-alpha * cij, muij, beta * muij * muij) * RHOIJ1;
    }
  return piij;
}

// equation MomentumEquation, method loop, from wcsph.sph:99: the destination's sums in locals (acc_NAME, accK_NAME: component K;
// the pair quantities' components scalars, XIJ_0 for XIJ[0]: the SIMD pair loops,
// codegen/SimdPairs.cpp)
// For the mirrored calls of each pair once in SIMD lanes: the source's properties as values
// (sval_NAME, particle d_idx's).
static inline void MomentumEquation_loop_simd_mirror(int d_idx, int s_idx, double t, double dt, double XIJ_0, double XIJ_1, double XIJ_2, double VIJ_0, double VIJ_1, double VIJ_2, double DWIJ_0, double DWIJ_1, double DWIJ_2, double R2IJ, double HIJ, double RHOIJ1, double EPS, double alpha, double beta, double& acc_au, double& acc_av, double& acc_aw, double dval_cs, const double* d_p, double dval_rho, double sval_cs, double sval_m, const double* s_p, double sval_rho, const double* s_hoisted0, double d_hoisted0, double pair_shared0, double pair_shared1, double pair_shared2) {
    double rhoi = dval_rho;
    double rhoj = sval_rho;
    double tmp = pair_shared0;

    double vijdotxij = pair_shared1;
    double piij = 0.0;
    piij = pair_shared2;





    double f = -sval_m * (tmp + piij);
    acc_au = std::fma(f, DWIJ_0, acc_au);
    acc_av = std::fma(f, DWIJ_1, acc_av);
    acc_aw = std::fma(f, DWIJ_2, acc_aw);
  
}

// equation XSPHCorrection, method loop, from wcsph.sph:134
static inline void XSPHCorrection_loop(int d_idx, int s_idx, double t, double dt, const double* VIJ, double WIJ, double RHOIJ1, double eps, double* d_ax, double* d_ay, double* d_az, const double* s_m) {
    // VIJ = v_a - v_b, hence the minus sign.
    double f = -eps * s_m[s_idx] * RHOIJ1 * WIJ;
    d_ax[d_idx] = std::fma(f, VIJ[0], d_ax[d_idx]);
    d_ay[d_idx] = std::fma(f, VIJ[1], d_ay[d_idx]);
    d_az[d_idx] = std::fma(f, VIJ[2], d_az[d_idx]);
  
}

// equation XSPHCorrection, method loop, from wcsph.sph:134: the destination's sums in locals (acc_NAME, accK_NAME: component K;
// codegen/RegisterSums.cpp)
static inline void XSPHCorrection_loop_sums(int d_idx, int s_idx, double t, double dt, const double* VIJ, double WIJ, double RHOIJ1, double eps, double& acc_ax, double& acc_ay, double& acc_az, const double* s_m) {
    // VIJ = v_a - v_b, hence the minus sign.
    double f = -eps * s_m[s_idx] * RHOIJ1 * WIJ;
    acc_ax = std::fma(f, VIJ[0], acc_ax);
    acc_ay = std::fma(f, VIJ[1], acc_ay);
    acc_az = std::fma(f, VIJ[2], acc_az);
  
}

// equation XSPHCorrection, method loop, from wcsph.sph:134: the destination's sums in locals (acc_NAME, accK_NAME: component K;
// the pair quantities' components scalars, XIJ_0 for XIJ[0]: the SIMD pair loops,
// codegen/SimdPairs.cpp)
static inline void XSPHCorrection_loop_simd(int d_idx, int s_idx, double t, double dt, double VIJ_0, double VIJ_1, double VIJ_2, double WIJ, double RHOIJ1, double eps, double& acc_ax, double& acc_ay, double& acc_az, const double* s_m) {
    // VIJ = v_a - v_b, hence the minus sign.
    double f = -eps * s_m[s_idx] * RHOIJ1 * WIJ;
    acc_ax = std::fma(f, VIJ_0, acc_ax);
    acc_ay = std::fma(f, VIJ_1, acc_ay);
    acc_az = std::fma(f, VIJ_2, acc_az);
  
}

// equation XSPHCorrection, method loop, from wcsph.sph:134: the destination's sums in locals (acc_NAME, accK_NAME: component K;
// the pair quantities' components scalars, XIJ_0 for XIJ[0]: the SIMD pair loops,
// codegen/SimdPairs.cpp)
// For the mirrored calls of each pair once in SIMD lanes: the source's properties as values
// (sval_NAME, particle d_idx's).
static inline void XSPHCorrection_loop_simd_mirror(int d_idx, int s_idx, double t, double dt, double VIJ_0, double VIJ_1, double VIJ_2, double WIJ, double RHOIJ1, double eps, double& acc_ax, double& acc_ay, double& acc_az, double sval_m) {
    // VIJ = v_a - v_b, hence the minus sign.
    double f = -eps * sval_m * RHOIJ1 * WIJ;
    acc_ax = std::fma(f, VIJ_0, acc_ax);
    acc_ay = std::fma(f, VIJ_1, acc_ay);
    acc_az = std::fma(f, VIJ_2, acc_az);
  
}


// ---- The particles ----

// Arrays on 64-byte boundaries (a zmm load of 8 doubles in one cache line).
template <class T>
struct Aligned64 {
  using value_type = T;
  Aligned64() = default;
  template <class U>
  Aligned64(const Aligned64<U>&) {}
  T* allocate(std::size_t n) {
    void* p = std::aligned_alloc(64, (n * sizeof(T) + 63) / 64 * 64);
    if (!p) throw std::bad_alloc();
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t) { std::free(p); }
  bool operator==(const Aligned64&) const { return true; }
  bool operator!=(const Aligned64&) const { return false; }
};
using Doubles = std::vector<double, Aligned64<double>>;

// The properties the loop reads and the seven sums it writes, one array each (SoA).
struct Fluid {
  int n = 0;
  Doubles x, y, z, u, v, w, h, rho, m, cs, p;
  Doubles hoisted;  // p / rho^2 per particle (MomentumEquation_loop_hoisted0)
  Doubles sums[7];  // arho, au, av, aw, ax, ay, az
  void resize(int count) {
    n = count;
    for (Doubles* a : {&x, &y, &z, &u, &v, &w, &h, &rho, &m, &cs, &p, &hoisted}) a->assign(count, 0.0);
    for (Doubles& s : sums) s.assign(count, 0.0);
  }
  void zero_sums() {
    for (Doubles& s : sums) std::fill(s.begin(), s.end(), 0.0);
  }
};
const char* const kSumNames[7] = {"arho", "au", "av", "aw", "ax", "ay", "az"};

// The equations' constants (bench/cube.sph: MomentumEquation alpha = 0.5, beta = 0, XSPH
// eps = 0.5; TaitEOS rho0 = 1000, c0 = 10, gamma = 7).
struct Constants {
  double alpha = 0.5, beta = 0.0, eps = 0.5;
};

// The cube's lattice (bench/cube.sph: block 0..1 in each axis, dx = 1 / nx; the runtime's
// block puts x fastest), each coordinate moved by a uniform random amount in +-pert dx (not
// a perfect lattice: no pair exactly at the cut-off), a small random velocity and density
// (so that the viscosity's branch is taken by about half the pairs; with uniform_velocity
// every particle falls at the same speed, as in the cube's 5 steps: v.x = 0, the branch is
// never taken, and the continuity and XSPH sums are 0), p and cs by the Tait
// equation of state, m = rho0 dx^3, h = 1.5 dx. Then ordered as the solver orders the
// particles at its first neighbour update: by cell of the support's grid (side 2 h, x
// fastest), by index within a cell (CellList::cell_order, a stable counting sort).
Fluid make_cube(int nx, double hdx, double pert, bool uniform_velocity, unsigned seed) {
  const double dx = 1.0 / nx, rho0 = 1000.0, c0 = 10.0, gamma = 7.0;
  const double B = rho0 * c0 * c0 / gamma;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  Fluid lattice;
  lattice.resize(nx * nx * nx);
  int k = 0;
  for (int iz = 0; iz < nx; ++iz)
    for (int iy = 0; iy < nx; ++iy)
      for (int ix = 0; ix < nx; ++ix, ++k) {
        lattice.x[k] = (ix + 0.5) * dx + pert * dx * uni(rng);
        lattice.y[k] = (iy + 0.5) * dx + pert * dx * uni(rng);
        lattice.z[k] = (iz + 0.5) * dx + pert * dx * uni(rng);
        lattice.u[k] = 0.05 * uni(rng);
        lattice.v[k] = 0.05 * uni(rng);
        lattice.w[k] = 0.05 * uni(rng) - 0.01;
        if (uniform_velocity) lattice.u[k] = lattice.v[k] = 0.0, lattice.w[k] = -9.81 * 5e-4;
        lattice.rho[k] = rho0 * (1.0 + 0.002 * uni(rng));
        lattice.h[k] = hdx * dx;
        lattice.m[k] = rho0 * dx * dx * dx;
        const double ratio = lattice.rho[k] / rho0;
        lattice.p[k] = B * (std::pow(ratio, gamma) - 1.0);
        lattice.cs[k] = c0 * std::pow(ratio, 0.5 * (gamma - 1.0));
      }
  // The support's cells (side 2 h): the solver's order.
  const double cell = 2.0 * hdx * dx;
  const int nc = static_cast<int>(std::ceil(1.0 / cell)) + 1;
  auto cell_of = [&](int i) {
    auto c = [&](double q) { return std::clamp(static_cast<int>(std::floor(q / cell)), 0, nc - 1); };
    return (c(lattice.z[i]) * nc + c(lattice.y[i])) * nc + c(lattice.x[i]);
  };
  std::vector<int> order(lattice.n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return cell_of(a) < cell_of(b); });
  Fluid f;
  f.resize(lattice.n);
  for (int i = 0; i < f.n; ++i) {
    const int o = order[i];
    f.x[i] = lattice.x[o]; f.y[i] = lattice.y[o]; f.z[i] = lattice.z[o];
    f.u[i] = lattice.u[o]; f.v[i] = lattice.v[o]; f.w[i] = lattice.w[o];
    f.h[i] = lattice.h[o]; f.rho[i] = lattice.rho[o]; f.m[i] = lattice.m[o];
    f.cs[i] = lattice.cs[o]; f.p[i] = lattice.p[o];
  }
  for (int i = 0; i < f.n; ++i) f.hoisted[i] = MomentumEquation_loop_hoisted0(i, f.p.data(), f.rho.data());
  return f;
}

// A uniform grid over the particles (side `cell`), for building lists (not timed).
struct Grid {
  double lo[3] = {0, 0, 0}, cell = 1;
  int nc[3] = {1, 1, 1};
  std::vector<int> start, items;
  Grid(const Fluid& f, double cell_side) : cell(cell_side) {
    double hi[3] = {-1e300, -1e300, -1e300};
    lo[0] = lo[1] = lo[2] = 1e300;
    for (int i = 0; i < f.n; ++i) {
      const double q[3] = {f.x[i], f.y[i], f.z[i]};
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], q[a]), hi[a] = std::max(hi[a], q[a]);
    }
    for (int a = 0; a < 3; ++a) nc[a] = static_cast<int>((hi[a] - lo[a]) / cell) + 1;
    start.assign(nc[0] * nc[1] * nc[2] + 1, 0);
    std::vector<int> c(f.n);
    for (int i = 0; i < f.n; ++i) c[i] = index(f.x[i], f.y[i], f.z[i]), ++start[c[i] + 1];
    for (size_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
    items.resize(f.n);
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (int i = 0; i < f.n; ++i) items[fill[c[i]]++] = i;
  }
  int coord(double q, int a) const {
    return std::clamp(static_cast<int>(std::floor((q - lo[a]) / cell)), 0, nc[a] - 1);
  }
  int index(double x, double y, double z) const {
    return (coord(z, 2) * nc[1] + coord(y, 1)) * nc[0] + coord(x, 0);
  }
};

// The kept lists of --verlet-skin (default skin 0.1): per particle, every j with r_ij <
// (1 + skin) 2 max(h_i, h_j), in increasing index (sphc/verlet.h), and where j >= i starts.
struct KeptLists {
  std::vector<std::vector<std::uint32_t>> lists;
  std::vector<std::uint32_t> upper;
};
KeptLists build_kept_lists(const Fluid& f, double skin) {
  double hmax = 0;
  for (double hv : f.h) hmax = std::max(hmax, hv);
  const double VERLET_RADIUS2 = RADIUS2 * (1.0 + skin) * (1.0 + skin);
  Grid g(f, Kernel::radius_scale * hmax * (1.0 + skin));
  KeptLists k;
  k.lists.resize(f.n);
  k.upper.resize(f.n);
  for (int i = 0; i < f.n; ++i) {
    const int c[3] = {g.coord(f.x[i], 0), g.coord(f.y[i], 1), g.coord(f.z[i], 2)};
    std::vector<std::uint32_t>& L = k.lists[i];
    for (int cz = std::max(0, c[2] - 1); cz <= std::min(g.nc[2] - 1, c[2] + 1); ++cz)
      for (int cy = std::max(0, c[1] - 1); cy <= std::min(g.nc[1] - 1, c[1] + 1); ++cy)
        for (int cx = std::max(0, c[0] - 1); cx <= std::min(g.nc[0] - 1, c[0] + 1); ++cx) {
          const int cc = (cz * g.nc[1] + cy) * g.nc[0] + cx;
          for (int t = g.start[cc]; t < g.start[cc + 1]; ++t) {
            const int j = g.items[t];
            const double XIJ[3] = {f.x[i] - f.x[j], f.y[i] - f.y[j], f.z[i] - f.z[j]};
            const double R2IJ = XIJ[0] * XIJ[0] + XIJ[1] * XIJ[1] + XIJ[2] * XIJ[2];
            const double hm = std::max(f.h[i], f.h[j]);
            if (!(R2IJ >= VERLET_RADIUS2 * hm * hm)) L.push_back(j);
          }
        }
    std::sort(L.begin(), L.end());
    k.upper[i] = static_cast<std::uint32_t>(std::lower_bound(L.begin(), L.end(), static_cast<std::uint32_t>(i)) - L.begin());  // sphc::upper_start
  }
  return k;
}

// ---- (a) today's scalar form: each pair once, per destination, the cut-off a branch ----
// The generated loop of `sphc --simd-pairs=off bench/cube.sph` (its pair loop, from `for
// (int d_idx ...) {  // pairs (d_idx, s_idx > d_idx)`), with t, dt and the equations'
// constants as arguments.
__attribute__((noinline)) void form_a(Fluid& fl, const KeptLists& kl, const Constants& eq) {
  const int n = fl.n;
  const double t = 0.0, dt = 1e-4;
  const double *di_x = fl.x.data(), *sj_x = di_x, *di_y = fl.y.data(), *sj_y = di_y;
  const double *di_z = fl.z.data(), *sj_z = di_z, *di_u = fl.u.data(), *sj_u = di_u;
  const double *di_v = fl.v.data(), *sj_v = di_v, *di_w = fl.w.data(), *sj_w = di_w;
  const double *di_h = fl.h.data(), *sj_h = di_h, *di_rho = fl.rho.data(), *sj_rho = di_rho;
  const double *s_cs = fl.cs.data(), *d_cs = s_cs, *s_m = fl.m.data(), *s_p = fl.p.data();
  const double *d_p = s_p, *s_rho = fl.rho.data(), *d_rho = s_rho;
  const double* hoisted_eq2_0 = fl.hoisted.data();
  const double* dhoisted_all_eq2_0 = fl.hoisted.data();  // the same values: p / rho^2
  double *d_arho = fl.sums[0].data(), *d_au = fl.sums[1].data(), *d_av = fl.sums[2].data();
  double *d_aw = fl.sums[3].data(), *d_ax = fl.sums[4].data(), *d_ay = fl.sums[5].data();
  double* d_az = fl.sums[6].data();
  struct { double alpha, beta; } eq2{eq.alpha, eq.beta};
  struct { double eps; } eq3{eq.eps};
        for (int d_idx = 0; d_idx < n; ++d_idx) {  // pairs (d_idx, s_idx > d_idx)
          const double xi = di_x[d_idx];
          const double yi = di_y[d_idx];
          const double zi = di_z[d_idx];
          const double hi = di_h[d_idx];
          const double ui = di_u[d_idx];
          const double vi = di_v[d_idx];
          const double wi = di_w[d_idx];
          const double dhoisted_eq2_0 = dhoisted_all_eq2_0[d_idx];
          const std::vector<std::uint32_t>& kept = kl.lists[d_idx];
          const std::uint32_t* const k_end = kept.data() + kept.size();
          const std::uint32_t* k_first = kept.data() + kl.upper[d_idx];
          if (k_first != k_end && *k_first == static_cast<std::uint32_t>(d_idx)) ++k_first;  // the self pair
          double acc_arho = d_arho[d_idx];
          double acc_au = d_au[d_idx];
          double acc_av = d_av[d_idx];
          double acc_aw = d_aw[d_idx];
          double acc_ax = d_ax[d_idx];
          double acc_ay = d_ay[d_idx];
          double acc_az = d_az[d_idx];
          for (const std::uint32_t* k = k_first; k != k_end; ++k) {
            const int s_idx = static_cast<int>(*k);
            const double hj = sj_h[s_idx];
            const double XIJ[3] = {xi - sj_x[s_idx], yi - sj_y[s_idx], zi - sj_z[s_idx]};
            const double R2IJ = XIJ[0] * XIJ[0] + XIJ[1] * XIJ[1] + XIJ[2] * XIJ[2];
            const double hmax = hi > hj ? hi : hj;
            if (R2IJ >= RADIUS2 * hmax * hmax) continue;  // not a neighbour
            const double XIJ_ji[3] = {sj_x[s_idx] - xi, sj_y[s_idx] - yi, sj_z[s_idx] - zi};
            const double HIJ = 0.5 * (hi + hj);
            const double RIJ = std::sqrt(R2IJ);
            const double VIJ[3] = {ui - sj_u[s_idx], vi - sj_v[s_idx], wi - sj_w[s_idx]};
            const double VIJ_ji[3] = {sj_u[s_idx] - ui, sj_v[s_idx] - vi, sj_w[s_idx] - wi};
            const double WIJ = Kernel::w(RIJ, HIJ);
            double DWIJ[3], DWIJ_ji[3];
            Kernel::gradient_pair(XIJ, XIJ_ji, RIJ, HIJ, DWIJ, DWIJ_ji);
            const double RHOIJ = 0.5 * (di_rho[d_idx] + sj_rho[s_idx]);
            const double RHOIJ1 = 1.0 / RHOIJ;
            const double EPS = 0.01 * HIJ * HIJ;
            const double pshared_eq1_0 = ContinuityEquation_loop_pairshared0(d_idx, s_idx, t, dt, VIJ, DWIJ, s_m);  // ContinuityEquation: the same for (s_idx, d_idx)
            const double pshared_eq2_0 = MomentumEquation_loop_pairshared0(d_idx, s_idx, t, dt, XIJ, VIJ, DWIJ, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, d_cs, d_p, d_rho, s_cs, s_m, s_p, s_rho, hoisted_eq2_0, dhoisted_eq2_0);  // MomentumEquation: the same for (s_idx, d_idx)
            const double pshared_eq2_1 = MomentumEquation_loop_pairshared1(d_idx, s_idx, t, dt, XIJ, VIJ, DWIJ, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, d_cs, d_p, d_rho, s_cs, s_m, s_p, s_rho, hoisted_eq2_0, dhoisted_eq2_0);  // MomentumEquation: the same for (s_idx, d_idx)
            const double pshared_eq2_2 = MomentumEquation_loop_pairshared2(d_idx, s_idx, t, dt, XIJ, VIJ, DWIJ, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, d_cs, d_p, d_rho, s_cs, s_m, s_p, s_rho, hoisted_eq2_0, dhoisted_eq2_0);  // MomentumEquation: the same for (s_idx, d_idx)
            ContinuityEquation_loop_sums(d_idx, s_idx, t, dt, VIJ, DWIJ, acc_arho, s_m, pshared_eq1_0);  // ContinuityEquation, from cube.sph:32
            MomentumEquation_loop_sums(d_idx, s_idx, t, dt, XIJ, VIJ, DWIJ, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, acc_au, acc_av, acc_aw, d_cs, d_p, d_rho, s_cs, s_m, s_p, s_rho, hoisted_eq2_0, dhoisted_eq2_0, pshared_eq2_0, pshared_eq2_1, pshared_eq2_2);  // MomentumEquation, from cube.sph:33
            XSPHCorrection_loop_sums(d_idx, s_idx, t, dt, VIJ, WIJ, RHOIJ1, eq3.eps, acc_ax, acc_ay, acc_az, s_m);  // XSPHCorrection, from cube.sph:35
            // the same pair for particle s_idx
            ContinuityEquation_loop(s_idx, d_idx, t, dt, VIJ_ji, DWIJ_ji, d_arho, s_m, pshared_eq1_0);  // ContinuityEquation, from cube.sph:32: destination s_idx, source d_idx
            MomentumEquation_loop(s_idx, d_idx, t, dt, XIJ_ji, VIJ_ji, DWIJ_ji, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, d_au, d_av, d_aw, d_cs, d_p, d_rho, s_cs, s_m, s_p, s_rho, hoisted_eq2_0, dhoisted_all_eq2_0[s_idx], pshared_eq2_0, pshared_eq2_1, pshared_eq2_2);  // MomentumEquation, from cube.sph:33: destination s_idx, source d_idx
            XSPHCorrection_loop(s_idx, d_idx, t, dt, VIJ_ji, WIJ, RHOIJ1, eq3.eps, d_ax, d_ay, d_az, s_m);  // XSPHCorrection, from cube.sph:35: destination s_idx, source d_idx
          }
          d_arho[d_idx] = acc_arho;
          d_au[d_idx] = acc_au;
          d_av[d_idx] = acc_av;
          d_aw[d_idx] = acc_aw;
          d_ax[d_idx] = acc_ax;
          d_ay[d_idx] = acc_ay;
          d_az[d_idx] = acc_az;
        }
}

// ---- (b) today's lane form: each pair once in SIMD lanes, gathers and scatters ----
// The generated loop of `sphc bench/cube.sph` (--simd-pairs=auto on this CPU; serial: one
// block, b_end = n), from `for (int d_idx ...) {  // pairs (d_idx, s_idx >= d_idx)`.
__attribute__((noinline)) void form_b(Fluid& fl, const KeptLists& kl, const Constants& eq) {
  const int n = fl.n;
  const double t = 0.0, dt = 1e-4;
  const double *di_x = fl.x.data(), *sj_x = di_x, *di_y = fl.y.data(), *sj_y = di_y;
  const double *di_z = fl.z.data(), *sj_z = di_z, *di_u = fl.u.data(), *sj_u = di_u;
  const double *di_v = fl.v.data(), *sj_v = di_v, *di_w = fl.w.data(), *sj_w = di_w;
  const double *di_h = fl.h.data(), *sj_h = di_h, *di_rho = fl.rho.data(), *sj_rho = di_rho;
  const double *s_cs = fl.cs.data(), *d_cs = s_cs, *s_m = fl.m.data(), *s_p = fl.p.data();
  const double *d_p = s_p, *s_rho = fl.rho.data(), *d_rho = s_rho;
  const double* hoisted_eq2_0 = fl.hoisted.data();
  const double* dhoisted_all_eq2_0 = fl.hoisted.data();
  double *d_arho = fl.sums[0].data(), *d_au = fl.sums[1].data(), *d_av = fl.sums[2].data();
  double *d_aw = fl.sums[3].data(), *d_ax = fl.sums[4].data(), *d_ay = fl.sums[5].data();
  double* d_az = fl.sums[6].data();
  struct { double alpha, beta; } eq2{eq.alpha, eq.beta};
  struct { double eps; } eq3{eq.eps};
        {
          const int b_end = n;  // one block: the OpenMP form's loop
          for (int d_idx = 0; d_idx < n; ++d_idx) {  // pairs (d_idx, s_idx >= d_idx)
            const double xi = di_x[d_idx];
            const double yi = di_y[d_idx];
            const double zi = di_z[d_idx];
            const double hi = di_h[d_idx];
            const double ui = di_u[d_idx];
            const double vi = di_v[d_idx];
            const double wi = di_w[d_idx];
            const double dhoisted_eq2_0 = dhoisted_all_eq2_0[d_idx];
            const std::vector<std::uint32_t>& kept = kl.lists[d_idx];
            const std::uint32_t* const k_end = kept.data() + kept.size();
            double acc_arho = d_arho[d_idx];
            double acc_au = d_au[d_idx];
            double acc_av = d_av[d_idx];
            double acc_aw = d_aw[d_idx];
            double acc_ax = d_ax[d_idx];
            double acc_ay = d_ay[d_idx];
            double acc_az = d_az[d_idx];
            const double dval_cs = d_cs[d_idx];
            const double dval_rho = d_rho[d_idx];
            const std::uint32_t* k_lanes = kept.data() + kl.upper[d_idx];  // s_idx >= d_idx
            if (k_lanes != k_end && *k_lanes == static_cast<std::uint32_t>(d_idx)) {  // the self pair, scalar: d_idx alone
              ++k_lanes;
              const int s_idx = d_idx;
              const double hj = sj_h[s_idx];
              const double XIJ_0 = xi - sj_x[s_idx];
              const double XIJ_1 = yi - sj_y[s_idx];
              const double XIJ_2 = zi - sj_z[s_idx];
              const double R2IJ = XIJ_0 * XIJ_0 + XIJ_1 * XIJ_1 + XIJ_2 * XIJ_2;
              const double HIJ = 0.5 * (hi + hj);
              const double RIJ = std::sqrt(R2IJ);
              const double VIJ_0 = ui - sj_u[s_idx];
              const double VIJ_1 = vi - sj_v[s_idx];
              const double VIJ_2 = wi - sj_w[s_idx];
              const double WIJ = Kernel::w(RIJ, HIJ);
              const double DWIJ_f = Kernel::gradient_factor(RIJ, HIJ);
              const double DWIJ_0 = DWIJ_f * XIJ_0;
              const double DWIJ_1 = DWIJ_f * XIJ_1;
              const double DWIJ_2 = DWIJ_f * XIJ_2;
              const double RHOIJ = 0.5 * (di_rho[d_idx] + sj_rho[s_idx]);
              const double RHOIJ1 = 1.0 / RHOIJ;
              const double EPS = 0.01 * HIJ * HIJ;
              const double hmax = hi > hj ? hi : hj;
              const bool in_support = !(R2IJ >= RADIUS2 * hmax * hmax);  // the cut-off
              if (in_support) {
                const double pshared_eq1_0 = ContinuityEquation_loop_pairshared0_simd(d_idx, s_idx, t, dt, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, s_m);  // ContinuityEquation: the same for (s_idx, d_idx)
                const double pshared_eq2_0 = MomentumEquation_loop_pairshared0_simd(d_idx, s_idx, t, dt, XIJ_0, XIJ_1, XIJ_2, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, dval_cs, d_p, dval_rho, s_cs, s_m, s_p, s_rho, hoisted_eq2_0, dhoisted_eq2_0);  // MomentumEquation: the same for (s_idx, d_idx)
                const double pshared_eq2_1 = MomentumEquation_loop_pairshared1_simd(d_idx, s_idx, t, dt, XIJ_0, XIJ_1, XIJ_2, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, dval_cs, d_p, dval_rho, s_cs, s_m, s_p, s_rho, hoisted_eq2_0, dhoisted_eq2_0);  // MomentumEquation: the same for (s_idx, d_idx)
                const double pshared_eq2_2 = MomentumEquation_loop_pairshared2_simd(d_idx, s_idx, t, dt, XIJ_0, XIJ_1, XIJ_2, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, dval_cs, d_p, dval_rho, s_cs, s_m, s_p, s_rho, hoisted_eq2_0, dhoisted_eq2_0);  // MomentumEquation: the same for (s_idx, d_idx)
                ContinuityEquation_loop_simd(d_idx, s_idx, t, dt, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, acc_arho, s_m, pshared_eq1_0);  // ContinuityEquation, from cube.sph:32
                MomentumEquation_loop_simd(d_idx, s_idx, t, dt, XIJ_0, XIJ_1, XIJ_2, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, acc_au, acc_av, acc_aw, dval_cs, d_p, dval_rho, s_cs, s_m, s_p, s_rho, hoisted_eq2_0, dhoisted_eq2_0, pshared_eq2_0, pshared_eq2_1, pshared_eq2_2);  // MomentumEquation, from cube.sph:33
                XSPHCorrection_loop_simd(d_idx, s_idx, t, dt, VIJ_0, VIJ_1, VIJ_2, WIJ, RHOIJ1, eq3.eps, acc_ax, acc_ay, acc_az, s_m);  // XSPHCorrection, from cube.sph:35
              }
            }
            const int n_lanes = static_cast<int>(k_end - k_lanes);
            const double sval_m = s_m[d_idx];
            const double sval_cs = s_cs[d_idx];
            const double sval_rho = s_rho[d_idx];
            #pragma omp simd reduction(+: acc_arho, acc_au, acc_av, acc_aw, acc_ax, acc_ay, acc_az)
            for (int k_nbr = 0; k_nbr < n_lanes; ++k_nbr) {
              const int s_idx = static_cast<int>(k_lanes[k_nbr]);
              const double hj = sj_h[s_idx];
              const double XIJ_0 = xi - sj_x[s_idx];
              const double XIJ_1 = yi - sj_y[s_idx];
              const double XIJ_2 = zi - sj_z[s_idx];
              const double XIJ_ji_0 = sj_x[s_idx] - xi;
              const double XIJ_ji_1 = sj_y[s_idx] - yi;
              const double XIJ_ji_2 = sj_z[s_idx] - zi;
              const double R2IJ = XIJ_0 * XIJ_0 + XIJ_1 * XIJ_1 + XIJ_2 * XIJ_2;
              const double HIJ = 0.5 * (hi + hj);
              const double RIJ = std::sqrt(R2IJ);
              const double VIJ_0 = ui - sj_u[s_idx];
              const double VIJ_1 = vi - sj_v[s_idx];
              const double VIJ_2 = wi - sj_w[s_idx];
              const double VIJ_ji_0 = sj_u[s_idx] - ui;
              const double VIJ_ji_1 = sj_v[s_idx] - vi;
              const double VIJ_ji_2 = sj_w[s_idx] - wi;
              const double WIJ = Kernel::w(RIJ, HIJ);
              const double DWIJ_f = Kernel::gradient_factor(RIJ, HIJ);
              const double DWIJ_0 = DWIJ_f * XIJ_0;
              const double DWIJ_1 = DWIJ_f * XIJ_1;
              const double DWIJ_2 = DWIJ_f * XIJ_2;
              const double DWIJ_ji_0 = DWIJ_f * XIJ_ji_0;
              const double DWIJ_ji_1 = DWIJ_f * XIJ_ji_1;
              const double DWIJ_ji_2 = DWIJ_f * XIJ_ji_2;
              const double RHOIJ = 0.5 * (di_rho[d_idx] + sj_rho[s_idx]);
              const double RHOIJ1 = 1.0 / RHOIJ;
              const double EPS = 0.01 * HIJ * HIJ;
              const double hmax = hi > hj ? hi : hj;
              const bool in_support = !(R2IJ >= RADIUS2 * hmax * hmax);  // the cut-off
              const double pshared_eq1_0 = ContinuityEquation_loop_pairshared0_simd(d_idx, s_idx, t, dt, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, s_m);  // ContinuityEquation: the same for (s_idx, d_idx)
              const double pshared_eq2_0 = MomentumEquation_loop_pairshared0_simd(d_idx, s_idx, t, dt, XIJ_0, XIJ_1, XIJ_2, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, dval_cs, d_p, dval_rho, s_cs, s_m, s_p, s_rho, hoisted_eq2_0, dhoisted_eq2_0);  // MomentumEquation: the same for (s_idx, d_idx)
              const double pshared_eq2_1 = MomentumEquation_loop_pairshared1_simd(d_idx, s_idx, t, dt, XIJ_0, XIJ_1, XIJ_2, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, dval_cs, d_p, dval_rho, s_cs, s_m, s_p, s_rho, hoisted_eq2_0, dhoisted_eq2_0);  // MomentumEquation: the same for (s_idx, d_idx)
              const double pshared_eq2_2 = MomentumEquation_loop_pairshared2_simd(d_idx, s_idx, t, dt, XIJ_0, XIJ_1, XIJ_2, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, dval_cs, d_p, dval_rho, s_cs, s_m, s_p, s_rho, hoisted_eq2_0, dhoisted_eq2_0);  // MomentumEquation: the same for (s_idx, d_idx)
              double pd_acc_arho = 0.0, pd_acc_au = 0.0, pd_acc_av = 0.0, pd_acc_aw = 0.0, pd_acc_ax = 0.0, pd_acc_ay = 0.0, pd_acc_az = 0.0;  // the pair's terms for d_idx
              // s_idx's sums (in this block; a later block adds the pair in its (1))
              double ps_acc_arho = s_idx < b_end ? d_arho[s_idx] : 0.0;
              double ps_acc_au = s_idx < b_end ? d_au[s_idx] : 0.0;
              double ps_acc_av = s_idx < b_end ? d_av[s_idx] : 0.0;
              double ps_acc_aw = s_idx < b_end ? d_aw[s_idx] : 0.0;
              double ps_acc_ax = s_idx < b_end ? d_ax[s_idx] : 0.0;
              double ps_acc_ay = s_idx < b_end ? d_ay[s_idx] : 0.0;
              double ps_acc_az = s_idx < b_end ? d_az[s_idx] : 0.0;
              ContinuityEquation_loop_simd(d_idx, s_idx, t, dt, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, pd_acc_arho, s_m, pshared_eq1_0);  // ContinuityEquation, from cube.sph:32
              MomentumEquation_loop_simd(d_idx, s_idx, t, dt, XIJ_0, XIJ_1, XIJ_2, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, pd_acc_au, pd_acc_av, pd_acc_aw, dval_cs, d_p, dval_rho, s_cs, s_m, s_p, s_rho, hoisted_eq2_0, dhoisted_eq2_0, pshared_eq2_0, pshared_eq2_1, pshared_eq2_2);  // MomentumEquation, from cube.sph:33
              XSPHCorrection_loop_simd(d_idx, s_idx, t, dt, VIJ_0, VIJ_1, VIJ_2, WIJ, RHOIJ1, eq3.eps, pd_acc_ax, pd_acc_ay, pd_acc_az, s_m);  // XSPHCorrection, from cube.sph:35
              ContinuityEquation_loop_simd_mirror(s_idx, d_idx, t, dt, VIJ_ji_0, VIJ_ji_1, VIJ_ji_2, DWIJ_ji_0, DWIJ_ji_1, DWIJ_ji_2, ps_acc_arho, sval_m, pshared_eq1_0);  // ContinuityEquation, from cube.sph:32: destination s_idx, source d_idx
              MomentumEquation_loop_simd_mirror(s_idx, d_idx, t, dt, XIJ_ji_0, XIJ_ji_1, XIJ_ji_2, VIJ_ji_0, VIJ_ji_1, VIJ_ji_2, DWIJ_ji_0, DWIJ_ji_1, DWIJ_ji_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, ps_acc_au, ps_acc_av, ps_acc_aw, s_cs[s_idx], d_p, s_rho[s_idx], sval_cs, sval_m, s_p, sval_rho, hoisted_eq2_0, dhoisted_all_eq2_0[s_idx], pshared_eq2_0, pshared_eq2_1, pshared_eq2_2);  // MomentumEquation, from cube.sph:33: destination s_idx, source d_idx
              XSPHCorrection_loop_simd_mirror(s_idx, d_idx, t, dt, VIJ_ji_0, VIJ_ji_1, VIJ_ji_2, WIJ, RHOIJ1, eq3.eps, ps_acc_ax, ps_acc_ay, ps_acc_az, sval_m);  // XSPHCorrection, from cube.sph:35: destination s_idx, source d_idx
              acc_arho += in_support ? pd_acc_arho : 0.0;
              acc_au += in_support ? pd_acc_au : 0.0;
              acc_av += in_support ? pd_acc_av : 0.0;
              acc_aw += in_support ? pd_acc_aw : 0.0;
              acc_ax += in_support ? pd_acc_ax : 0.0;
              acc_ay += in_support ? pd_acc_ay : 0.0;
              acc_az += in_support ? pd_acc_az : 0.0;
              if (in_support && s_idx < b_end) {  // later blocks: in their (1)
                d_arho[s_idx] = ps_acc_arho;
                d_au[s_idx] = ps_acc_au;
                d_av[s_idx] = ps_acc_av;
                d_aw[s_idx] = ps_acc_aw;
                d_ax[s_idx] = ps_acc_ax;
                d_ay[s_idx] = ps_acc_ay;
                d_az[s_idx] = ps_acc_az;
              }
            }
            d_arho[d_idx] = acc_arho;
            d_au[d_idx] = acc_au;
            d_av[d_idx] = acc_av;
            d_aw[d_idx] = acc_aw;
            d_ax[d_idx] = acc_ax;
            d_ay[d_idx] = acc_ay;
            d_az[d_idx] = acc_az;
          }
        }
}

// ---- (c) cluster pairs: CI x 8 tiles in AVX-512 ----

constexpr int CJ = 8;  // the j-cluster: one zmm register of doubles

// The particles in cluster order: the runtime's layout (sphc/cluster_pairs.h; GROMACS' grid,
// Pall & Hess 2013: columns of side `col` in the x-y plane, x fastest, the particles of a
// column sorted by z and cut into clusters of 8, a column's count padded to a multiple of 8, so
// that every j-cluster (8) and i-cluster (1, 2, 4 or 8) lies in one column) and a copy of the
// properties in its slot order (gather_slots). Padding slots take the values of their
// cluster's first particle and positions (gather_positions) at least 4 supports from every
// other slot, so every pair with one is beyond the cut-off: masked like any other.
struct Clusters {
  sphc::ClusterLayout layout;
  Fluid f;                        // properties in cluster order (f.n: padded count)
  std::vector<int> of_original;   // sorted position of original particle i
  std::vector<char> real;         // 0 for padding
  int ncj = 0;                    // j-clusters (8 particles each)
};

Clusters make_clusters(const Fluid& src, double col) {
  Clusters cl;
  sphc::build_cluster_layout(cl.layout, src.x.data(), src.y.data(), src.z.data(), src.n, 3, col);
  const int total = static_cast<int>(cl.layout.slots());
  cl.f.resize(total);
  double hmax = 0;
  for (double hv : src.h) hmax = std::max(hmax, hv);
  sphc::gather_positions(cl.layout, src.x.data(), src.y.data(), src.z.data(), cl.f.x.data(), cl.f.y.data(),
                         cl.f.z.data(), 4 * Kernel::radius_scale * hmax);
  Doubles Fluid::*const fields[] = {&Fluid::u, &Fluid::v, &Fluid::w, &Fluid::h, &Fluid::rho,
                                    &Fluid::m, &Fluid::cs, &Fluid::p, &Fluid::hoisted};
  for (Doubles Fluid::*q : fields) sphc::gather_slots(cl.layout, (src.*q).data(), (cl.f.*q).data());
  cl.of_original.assign(cl.layout.slot_of.begin(), cl.layout.slot_of.end());
  cl.real.assign(total, 0);
  for (int s = 0; s < total; ++s) cl.real[s] = cl.layout.slot[s] != sphc::kPadSlot;
  cl.ncj = static_cast<int>(cl.layout.n_clusters);
  return cl;
}

// Bounding box of particles [b, b + size) (real ones only; an empty box if none).
struct Box {
  double lo[3], hi[3];
  bool empty;
};
Box box_of(const Clusters& cl, int b, int size) {
  Box bx{{1e300, 1e300, 1e300}, {-1e300, -1e300, -1e300}, true};
  for (int i = b; i < b + size; ++i) {
    if (!cl.real[i]) continue;
    const double q[3] = {cl.f.x[i], cl.f.y[i], cl.f.z[i]};
    for (int a = 0; a < 3; ++a) bx.lo[a] = std::min(bx.lo[a], q[a]), bx.hi[a] = std::max(bx.hi[a], q[a]);
    bx.empty = false;
  }
  return bx;
}
double box_distance2(const Box& a, const Box& b) {
  double d2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double gap = std::max({0.0, b.lo[k] - a.hi[k], a.lo[k] - b.hi[k]});
    d2 += gap * gap;
  }
  return d2;
}

// The cluster-pair list: per i-cluster (CI particles from ci * CI), the j-clusters cj whose
// bounding box lies within `rlist` of its own, and only those with a particle after the
// i-cluster's first (each pair once: j > i; the j-cluster that holds the i-cluster is the
// diagonal tile, masked to j > i). The runtime's list of 8 x 8 cluster pairs
// (build_cluster_pairs: from its grid of columns, j >= i); for i-clusters of 1, 2 or 4 (and,
// counted only, j-clusters of 4) the pairs of the i-cluster's cluster of 8 filtered with the
// smaller clusters' boxes (a smaller cluster's box lies within its cluster of 8's: none is
// lost). Not timed.
struct PairList {
  int ci_size = 4;
  std::vector<std::uint32_t> start;  // per i-cluster, into cj (sphc::ClusterPairList::begin)
  std::vector<std::uint32_t> cj;     // (sphc::ClusterPairList::j)
};
PairList build_pair_list(const Clusters& cl, int CI, double rlist, int cjs = CJ) {
  sphc::ClusterPairList l8;
  sphc::build_cluster_pairs(cl.layout, cl.layout, rlist, true, l8);
  PairList pl;
  pl.ci_size = CI;
  if (CI == CJ && cjs == CJ) {
    pl.start.swap(l8.begin);
    pl.cj.swap(l8.j);
    return pl;
  }
  const int nci = cl.f.n / CI, ncj = cl.f.n / cjs, halves = CJ / cjs;
  std::vector<Box> jb(ncj);
  for (int c = 0; c < ncj; ++c) jb[c] = box_of(cl, c * cjs, cjs);
  pl.start.assign(nci + 1, 0);
  const double r2 = rlist * rlist;
  for (int ci = 0; ci < nci; ++ci) {
    const Box ib = box_of(cl, ci * CI, CI);
    const int cj_min = ci * CI / cjs, parent = ci * CI / CJ;
    if (!ib.empty)
      for (std::uint32_t e = l8.begin[parent]; e < l8.begin[parent + 1]; ++e)
        for (int q = 0; q < halves; ++q) {
          const int c = static_cast<int>(l8.j[e]) * halves + q;
          if (c >= cj_min && !jb[c].empty && box_distance2(ib, jb[c]) < r2) pl.cj.push_back(c);
        }
    pl.start[ci + 1] = static_cast<std::uint32_t>(pl.cj.size());
  }
  return pl;
}

// The intrinsics need AVX-512F (a build for another CPU, e.g. -march=x86-64-v3 to count
// instructions under valgrind, has forms (a), (b) and the `omp` tiles only).
#ifdef __AVX512F__
// One sweep of form (c): tiles of CI i's x 8 j's. Arithmetic: EXACT, the divisions and the
// square root of (a); RCP, rcp / rsqrt with Newton steps for all of them; RCP_DIV, the
// divisions by rcp, the square root exact (which of the two limits); LEAN, RCP with fewer
// vector operations per row (not the operations of (a): the cubic as 0.25 (2-q)^3 - (1-q)^3
// with the pieces clamped at 0, no selects; -m_i and -eps m_i per particle, not per row; the
// selects folded into zero-masked multiplications): how far the operation count moves it. The j sums of a tile are accumulated over its
// i's in registers and added to memory once (a contiguous load-add-store per sum); the i
// sums in 8 lane partial sums across the i-cluster's list, reduced at its end.
enum Arith { EXACT, RCP, RCP_DIV, LEAN };
template <int CI, int ARITH>
__attribute__((noinline)) void form_c(Clusters& cl, const PairList& pl, const Constants& eq) {
  Fluid& f = cl.f;
  const double sigma = Kernel::sigma;
  const V one = bc(1.0), half = bc(0.5), two = bc(2.0), zero = _mm512_setzero_pd();
  const V neg_eps = bc(-eq.eps), neg_alpha = bc(-eq.alpha), beta = bc(eq.beta);
  const V radius2 = bc(RADIUS2);
  const double *X = f.x.data(), *Y = f.y.data(), *Z = f.z.data(), *U = f.u.data();
  const double *VV = f.v.data(), *W = f.w.data(), *H = f.h.data(), *RHO = f.rho.data();
  const double *MS = f.m.data(), *CS = f.cs.data(), *HO = f.hoisted.data();
  double* S[7];
  for (int k = 0; k < 7; ++k) S[k] = f.sums[k].data();
  // LEAN: -m and -eps m per particle (as the printer hoists a source's values)
  static Doubles negm, negepsm;
  if (ARITH == LEAN) {
    negm.resize(f.n);
    negepsm.resize(f.n);
    for (int i = 0; i < f.n; ++i) negm[i] = -MS[i], negepsm[i] = -eq.eps * MS[i];
  }
  const double *NEGM = negm.data(), *NEGEPSM = negepsm.data();
  const int nci = static_cast<int>(pl.start.size()) - 1;
  const __m512i lane = _mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0);
  for (int ci = 0; ci < nci; ++ci) {
    const int i0 = ci * CI;
    if (pl.start[ci] == pl.start[ci + 1]) continue;
    V iacc[CI][7];
    for (int ii = 0; ii < CI; ++ii)
      for (int k = 0; k < 7; ++k) iacc[ii][k] = zero;
    for (int e = pl.start[ci]; e < pl.start[ci + 1]; ++e) {
      const int j0 = pl.cj[e] * CJ;
      const V xj = _mm512_load_pd(X + j0), yj = _mm512_load_pd(Y + j0), zj = _mm512_load_pd(Z + j0);
      const V uj = _mm512_load_pd(U + j0), vj = _mm512_load_pd(VV + j0), wj = _mm512_load_pd(W + j0);
      const V hj = _mm512_load_pd(H + j0), rhoj = _mm512_load_pd(RHO + j0), mj = _mm512_load_pd(MS + j0);
      const V csj = _mm512_load_pd(CS + j0), hoj = _mm512_load_pd(HO + j0);
      const V neg_mj = sub(zero, mj);  // -s_m[s_idx]
      const V neg_eps_mj = mul(neg_eps, mj);  // -eps * s_m[s_idx]
      V jacc[7];
      for (int k = 0; k < 7; ++k) jacc[k] = zero;
      const bool diagonal = j0 < i0 + CI;  // the j-cluster holds i's: j > i only
      for (int ii = 0; ii < CI; ++ii) {
        const int i = i0 + ii;
        const V XIJ_0 = sub(bc(X[i]), xj), XIJ_1 = sub(bc(Y[i]), yj), XIJ_2 = sub(bc(Z[i]), zj);
        const V R2IJ = add(add(mul(XIJ_0, XIJ_0), mul(XIJ_1, XIJ_1)), mul(XIJ_2, XIJ_2));
        const V hi = bc(H[i]);
        const V hmax = _mm512_max_pd(hi, hj);
        // the cut-off: !(R2IJ >= RADIUS2 * hmax * hmax)
        M in = _mm512_cmp_pd_mask(R2IJ, mul(mul(radius2, hmax), hmax), _CMP_NGE_UQ);
        if (diagonal) in &= _mm512_cmpgt_epi64_mask(_mm512_add_epi64(lane, _mm512_set1_epi64(j0)), _mm512_set1_epi64(i));
#ifndef NO_ROWSKIP
        if (!in) continue;  // no pair of this row within the support
#endif
        const V HIJ = mul(half, add(hi, hj));
        const V VIJ_0 = sub(bc(U[i]), uj), VIJ_1 = sub(bc(VV[i]), vj), VIJ_2 = sub(bc(W[i]), wj);
        // Kernel::w and gradient_pair's factor (sphc/kernels.h, the cubic spline)
        V RIJ, ih, q, s_den_inv = zero;
        if (ARITH == EXACT) {
          RIJ = _mm512_sqrt_pd(R2IJ);
          ih = div(one, HIJ);
          q = div(RIJ, HIJ);
        } else if (ARITH == RCP_DIV) {
          RIJ = _mm512_sqrt_pd(R2IJ);
          ih = rcp(HIJ);
          q = mul(RIJ, ih);
        } else {
          const V rinv = rsqrt(R2IJ);
          RIJ = ARITH == LEAN ? _mm512_maskz_mul_pd(_mm512_cmp_pd_mask(R2IJ, zero, _CMP_GT_OQ), R2IJ, rinv)
                              : sel(_mm512_cmp_pd_mask(R2IJ, zero, _CMP_GT_OQ), mul(R2IJ, rinv), zero);
          ih = rcp(HIJ);
          q = mul(RIJ, ih);
          s_den_inv = mul(ih, rinv);  // 1 / (h rij)
        }
        const V sk = mul(bc(sigma), mul(mul(ih, ih), ih));
        V WIJ, dwdq;
        if (ARITH == LEAN) {  // f = t2^3 / 4 - t1^3, f' = 3 t1^2 - 3 t2^2 / 4, t2 = max(2 - q, 0), t1 = max(1 - q, 0)
          const V t2 = _mm512_max_pd(sub(two, q), zero), t1 = _mm512_max_pd(sub(one, q), zero);
          const V t22 = mul(t2, t2), t12 = mul(t1, t1);
          WIJ = mul(sk, _mm512_fmsub_pd(bc(0.25), mul(t22, t2), mul(t12, t1)));
          dwdq = mul(sk, fma(bc(3.0), t12, mul(bc(-0.75), t22)));
        } else {
          const M lt1 = _mm512_cmp_pd_mask(q, one, _CMP_LT_OQ), lt2 = _mm512_cmp_pd_mask(q, two, _CMP_LT_OQ);
          const V tq = sub(two, q);
          const V f1 = sub(one, mul(mul(mul(bc(1.5), q), q), sub(one, mul(half, q))));
          const V f2 = mul(mul(mul(bc(0.25), tq), tq), tq);
          const V df1 = mul(q, sub(mul(bc(2.25), q), bc(3.0)));
          const V df2 = mul(mul(bc(-0.75), tq), tq);
          WIJ = mul(sk, sel(lt1, f1, sel(lt2, f2, zero)));
          dwdq = mul(sk, sel(lt1, df1, sel(lt2, df2, zero)));
        }
        const M apart = _mm512_cmp_pd_mask(RIJ, bc(1e-12), _CMP_GT_OQ);
        const V s = ARITH == EXACT     ? div(dwdq, mul(HIJ, sel(apart, RIJ, one)))
                    : ARITH == RCP_DIV ? mul(dwdq, rcp(mul(HIJ, sel(apart, RIJ, one))))
                                       : mul(dwdq, s_den_inv);
        const V DWIJ_f = ARITH == LEAN ? _mm512_maskz_mul_pd(apart, dwdq, s_den_inv) : sel(apart, s, zero);
        const V DWIJ_0 = mul(DWIJ_f, XIJ_0), DWIJ_1 = mul(DWIJ_f, XIJ_1), DWIJ_2 = mul(DWIJ_f, XIJ_2);
        const V RHOIJ = mul(half, add(bc(RHO[i]), rhoj));
        const V RHOIJ1 = ARITH == EXACT ? div(one, RHOIJ) : rcp(RHOIJ);
        const V EPS = mul(mul(bc(0.01), HIJ), HIJ);
        // the values the pair shares
        const V vdw = fma(VIJ_2, DWIJ_2, fma(VIJ_0, DWIJ_0, mul(VIJ_1, DWIJ_1)));
        const V tmp = add(bc(HO[i]), hoj);
        const V vdx = fma(VIJ_2, XIJ_2, fma(VIJ_0, XIJ_0, mul(VIJ_1, XIJ_1)));
        const V cij = mul(half, add(bc(CS[i]), csj));
        const V muij = ARITH == EXACT ? div(mul(HIJ, vdx), add(R2IJ, EPS)) : mul(mul(HIJ, vdx), rcp(add(R2IJ, EPS)));
        const V pi_f = fma(mul(neg_alpha, cij), muij, mul(mul(beta, muij), muij));
        const M visc = _mm512_cmp_pd_mask(vdx, zero, _CMP_LT_OQ);
        const V piij = ARITH == LEAN ? _mm512_maskz_mul_pd(visc, pi_f, RHOIJ1) : sel(visc, mul(pi_f, RHOIJ1), zero);
        const V tp = add(tmp, piij);
        // i's terms (destination i, source j), under the mask
        const V fi = mul(neg_mj, tp);
        const V xi_f = mul(mul(neg_eps_mj, RHOIJ1), WIJ);
        V* ia = iacc[ii];
        ia[0] = _mm512_mask3_fmadd_pd(mj, vdw, ia[0], in);
        ia[1] = _mm512_mask3_fmadd_pd(fi, DWIJ_0, ia[1], in);
        ia[2] = _mm512_mask3_fmadd_pd(fi, DWIJ_1, ia[2], in);
        ia[3] = _mm512_mask3_fmadd_pd(fi, DWIJ_2, ia[3], in);
        ia[4] = _mm512_mask3_fmadd_pd(xi_f, VIJ_0, ia[4], in);
        ia[5] = _mm512_mask3_fmadd_pd(xi_f, VIJ_1, ia[5], in);
        ia[6] = _mm512_mask3_fmadd_pd(xi_f, VIJ_2, ia[6], in);
        // j's terms (destination j, source i): DWIJ_ji = -DWIJ, VIJ_ji = -VIJ exactly
        const V mi = bc(MS[i]);
        const V fj = ARITH == LEAN ? mul(bc(NEGM[i]), tp) : mul(sub(zero, mi), tp);
        const V xj_f = ARITH == LEAN ? mul(mul(bc(NEGEPSM[i]), RHOIJ1), WIJ) : mul(mul(mul(neg_eps, mi), RHOIJ1), WIJ);
        jacc[0] = _mm512_mask3_fmadd_pd(mi, vdw, jacc[0], in);
        jacc[1] = _mm512_mask3_fnmadd_pd(fj, DWIJ_0, jacc[1], in);
        jacc[2] = _mm512_mask3_fnmadd_pd(fj, DWIJ_1, jacc[2], in);
        jacc[3] = _mm512_mask3_fnmadd_pd(fj, DWIJ_2, jacc[3], in);
        jacc[4] = _mm512_mask3_fnmadd_pd(xj_f, VIJ_0, jacc[4], in);
        jacc[5] = _mm512_mask3_fnmadd_pd(xj_f, VIJ_1, jacc[5], in);
        jacc[6] = _mm512_mask3_fnmadd_pd(xj_f, VIJ_2, jacc[6], in);
      }
      for (int k = 0; k < 7; ++k) _mm512_store_pd(S[k] + j0, add(_mm512_load_pd(S[k] + j0), jacc[k]));
    }
    for (int ii = 0; ii < CI; ++ii)
      for (int k = 0; k < 7; ++k) S[k][i0 + ii] += _mm512_reduce_add_pd(iacc[ii][k]);
  }
}

#endif  // __AVX512F__

// Dynamic pruning (GROMACS): the list kept with a skin, pruned every step to the cluster
// pairs whose current bounding boxes lie within `rcut` (every box recomputed, then one box
// test per kept cluster pair). What a step would pay to run the `cut` lists. Clusters of 8:
// the runtime's (update_boxes from the positions in slot order, prune_cluster_pairs); smaller
// i-clusters: the same test with their boxes.
PairList prune(Clusters& cl, const PairList& outer, double rcut) {
  PairList pl;
  pl.ci_size = outer.ci_size;
  if (outer.ci_size == CJ) {
    // The runtime's form of the lists: the vectors swapped in and back (no copy; the lists
    // themselves are not const).
    PairList& o = const_cast<PairList&>(outer);
    sphc::ClusterPairList in, out;
    in.begin.swap(o.start), in.j.swap(o.cj);
    sphc::update_boxes(cl.layout, cl.f.x.data(), cl.f.y.data(), cl.f.z.data());
    sphc::prune_cluster_pairs(cl.layout, cl.layout, in, rcut, out);
    in.begin.swap(o.start), in.j.swap(o.cj);
    pl.start.swap(out.begin), pl.cj.swap(out.j);
    return pl;
  }
  const int CI = outer.ci_size, nci = static_cast<int>(outer.start.size()) - 1;
  std::vector<Box> ib(nci), jb(cl.ncj);
  for (int c = 0; c < nci; ++c) ib[c] = box_of(cl, c * CI, CI);
  for (int c = 0; c < cl.ncj; ++c) jb[c] = box_of(cl, c * CJ, CJ);
  pl.start.assign(nci + 1, 0);
  pl.cj.reserve(outer.cj.size());
  const double r2 = rcut * rcut;
  for (int ci = 0; ci < nci; ++ci) {
    for (int e = outer.start[ci]; e < outer.start[ci + 1]; ++e)
      if (box_distance2(ib[ci], jb[outer.cj[e]]) < r2) pl.cj.push_back(outer.cj[e]);
    pl.start[ci + 1] = static_cast<std::uint32_t>(pl.cj.size());
  }
  return pl;
}

// GROMACS' 2xMM layout for AVX-512 (not implemented here, counted only): j-clusters of 4,
// a zmm register holding 2 i's x 4 j's. Per cluster pair (i-cluster of 4, j-cluster of 4):
// 2 vectors (i's 0-1, 2-3); a vector is computed if one of its 8 lanes is within the
// support. Returns the lanes within the support over the lanes of the vectors computed, and
// the vectors computed.
std::pair<double, long> count_2xmm(const Clusters& cl, const PairList& pl4) {
  const Fluid& f = cl.f;
  long vectors = 0, inside = 0;
  for (size_t ci = 0; ci + 1 < pl4.start.size(); ++ci)
    for (int e = pl4.start[ci]; e < pl4.start[ci + 1]; ++e)
      for (int half = 0; half < 2; ++half) {
        long in = 0;
        for (int i = static_cast<int>(ci) * 4 + 2 * half; i < static_cast<int>(ci) * 4 + 2 * half + 2; ++i)
          for (int j = pl4.cj[e] * 4; j < pl4.cj[e] * 4 + 4; ++j) {
            if (j <= i) continue;
            const double XIJ[3] = {f.x[i] - f.x[j], f.y[i] - f.y[j], f.z[i] - f.z[j]};
            const double R2IJ = XIJ[0] * XIJ[0] + XIJ[1] * XIJ[1] + XIJ[2] * XIJ[2];
            const double hm = std::max(f.h[i], f.h[j]);
            if (!(R2IJ >= RADIUS2 * hm * hm)) ++in;
          }
        inside += in;
        vectors += in > 0;
      }
  return {double(inside) / (8.0 * vectors), vectors};
}

// Form (c) as a printer could emit it with the least change: the lane loop of form (b), its
// body verbatim (the generated _simd and _simd_mirror calls), over the 8 j's of a tile under
// `#pragma omp simd` with s_idx = j0 + lane (contiguous: GCC loads, no gathers), each i of
// the tile in turn; i's terms (pd_, from 0) into 8 lane partial sums per i across its list,
// j's (ps_, from 0) into 8 lane sums per tile, added to memory once per tile.
template <int CI>
__attribute__((noinline)) void form_c_omp(Clusters& cl, const PairList& pl, const Constants& eqc) {
  Fluid& fl = cl.f;
  const double t = 0.0, dt = 1e-4;
  const double *sj_x = fl.x.data(), *sj_y = fl.y.data(), *sj_z = fl.z.data();
  const double *sj_u = fl.u.data(), *sj_v = fl.v.data(), *sj_w = fl.w.data();
  const double *sj_h = fl.h.data(), *sj_rho = fl.rho.data(), *di_rho = sj_rho;
  const double *s_cs = fl.cs.data(), *s_m = fl.m.data(), *s_p = fl.p.data(), *s_rho = fl.rho.data();
  const double *d_p = s_p, *hoisted_eq2_0 = fl.hoisted.data();
  double* S[7];
  for (int k = 0; k < 7; ++k) S[k] = fl.sums[k].data();
  struct { double alpha, beta; } eq2{eqc.alpha, eqc.beta};
  struct { double eps; } eq3{eqc.eps};
  const int nci = static_cast<int>(pl.start.size()) - 1;
  const int n_lanes = pl.ci_size > 0 ? CJ : 0;  // CJ
  for (int ci = 0; ci < nci; ++ci) {
    const int i0 = ci * CI;
    if (pl.start[ci] == pl.start[ci + 1]) continue;
    alignas(64) double iacc[CI][7][CJ] = {};
    for (int e = pl.start[ci]; e < pl.start[ci + 1]; ++e) {
      const int j0 = pl.cj[e] * CJ;
      const bool diagonal = j0 < i0 + CI;
      alignas(64) double jacc[7][CJ] = {};
      for (int ii = 0; ii < CI; ++ii) {
        const int d_idx = i0 + ii;
        const double xi = sj_x[d_idx], yi = sj_y[d_idx], zi = sj_z[d_idx], hi = sj_h[d_idx];
        const double ui = sj_u[d_idx], vi = sj_v[d_idx], wi = sj_w[d_idx];
        const double dhoisted_eq2_0 = hoisted_eq2_0[d_idx];
        const double dval_cs = s_cs[d_idx], dval_rho = s_rho[d_idx];
        const double sval_m = s_m[d_idx], sval_cs = s_cs[d_idx], sval_rho = s_rho[d_idx];
        double* ia0 = iacc[ii][0]; double* ia1 = iacc[ii][1]; double* ia2 = iacc[ii][2];
        double* ia3 = iacc[ii][3]; double* ia4 = iacc[ii][4]; double* ia5 = iacc[ii][5];
        double* ia6 = iacc[ii][6];
        const int j_min = diagonal ? d_idx : -1;  // the diagonal tile: j > i only
        // (a trip count GCC 12 cannot see as 8: with `l < CJ` it does not vectorise the loop,
        // "control flow in loop"; so it does, in pairs of 256-bit vectors)
        #pragma omp simd
        for (int l = 0; l < n_lanes; ++l) {
          const int s_idx = j0 + l;
          const double hj = sj_h[s_idx];
          const double XIJ_0 = xi - sj_x[s_idx];
          const double XIJ_1 = yi - sj_y[s_idx];
          const double XIJ_2 = zi - sj_z[s_idx];
          const double XIJ_ji_0 = sj_x[s_idx] - xi;
          const double XIJ_ji_1 = sj_y[s_idx] - yi;
          const double XIJ_ji_2 = sj_z[s_idx] - zi;
          const double R2IJ = XIJ_0 * XIJ_0 + XIJ_1 * XIJ_1 + XIJ_2 * XIJ_2;
          const double HIJ = 0.5 * (hi + hj);
          const double RIJ = std::sqrt(R2IJ);
          const double VIJ_0 = ui - sj_u[s_idx];
          const double VIJ_1 = vi - sj_v[s_idx];
          const double VIJ_2 = wi - sj_w[s_idx];
          const double VIJ_ji_0 = sj_u[s_idx] - ui;
          const double VIJ_ji_1 = sj_v[s_idx] - vi;
          const double VIJ_ji_2 = sj_w[s_idx] - wi;
          const double WIJ = Kernel::w(RIJ, HIJ);
          const double DWIJ_f = Kernel::gradient_factor(RIJ, HIJ);
          const double DWIJ_0 = DWIJ_f * XIJ_0;
          const double DWIJ_1 = DWIJ_f * XIJ_1;
          const double DWIJ_2 = DWIJ_f * XIJ_2;
          const double DWIJ_ji_0 = DWIJ_f * XIJ_ji_0;
          const double DWIJ_ji_1 = DWIJ_f * XIJ_ji_1;
          const double DWIJ_ji_2 = DWIJ_f * XIJ_ji_2;
          const double RHOIJ = 0.5 * (di_rho[d_idx] + sj_rho[s_idx]);
          const double RHOIJ1 = 1.0 / RHOIJ;
          const double EPS = 0.01 * HIJ * HIJ;
          const double hmax = hi > hj ? hi : hj;
          const bool in_support = !(R2IJ >= RADIUS2 * hmax * hmax) & (s_idx > j_min);
          const double pshared_eq1_0 = ContinuityEquation_loop_pairshared0_simd(d_idx, s_idx, t, dt, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, s_m);
          const double pshared_eq2_0 = MomentumEquation_loop_pairshared0_simd(d_idx, s_idx, t, dt, XIJ_0, XIJ_1, XIJ_2, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, dval_cs, d_p, dval_rho, s_cs, s_m, s_p, s_rho, hoisted_eq2_0, dhoisted_eq2_0);
          const double pshared_eq2_1 = MomentumEquation_loop_pairshared1_simd(d_idx, s_idx, t, dt, XIJ_0, XIJ_1, XIJ_2, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, dval_cs, d_p, dval_rho, s_cs, s_m, s_p, s_rho, hoisted_eq2_0, dhoisted_eq2_0);
          const double pshared_eq2_2 = MomentumEquation_loop_pairshared2_simd(d_idx, s_idx, t, dt, XIJ_0, XIJ_1, XIJ_2, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, dval_cs, d_p, dval_rho, s_cs, s_m, s_p, s_rho, hoisted_eq2_0, dhoisted_eq2_0);
          double pd_acc_arho = 0.0, pd_acc_au = 0.0, pd_acc_av = 0.0, pd_acc_aw = 0.0, pd_acc_ax = 0.0, pd_acc_ay = 0.0, pd_acc_az = 0.0;
          double ps_acc_arho = 0.0, ps_acc_au = 0.0, ps_acc_av = 0.0, ps_acc_aw = 0.0, ps_acc_ax = 0.0, ps_acc_ay = 0.0, ps_acc_az = 0.0;
          ContinuityEquation_loop_simd(d_idx, s_idx, t, dt, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, pd_acc_arho, s_m, pshared_eq1_0);
          MomentumEquation_loop_simd(d_idx, s_idx, t, dt, XIJ_0, XIJ_1, XIJ_2, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, pd_acc_au, pd_acc_av, pd_acc_aw, dval_cs, d_p, dval_rho, s_cs, s_m, s_p, s_rho, hoisted_eq2_0, dhoisted_eq2_0, pshared_eq2_0, pshared_eq2_1, pshared_eq2_2);
          XSPHCorrection_loop_simd(d_idx, s_idx, t, dt, VIJ_0, VIJ_1, VIJ_2, WIJ, RHOIJ1, eq3.eps, pd_acc_ax, pd_acc_ay, pd_acc_az, s_m);
          ContinuityEquation_loop_simd_mirror(s_idx, d_idx, t, dt, VIJ_ji_0, VIJ_ji_1, VIJ_ji_2, DWIJ_ji_0, DWIJ_ji_1, DWIJ_ji_2, ps_acc_arho, sval_m, pshared_eq1_0);
          MomentumEquation_loop_simd_mirror(s_idx, d_idx, t, dt, XIJ_ji_0, XIJ_ji_1, XIJ_ji_2, VIJ_ji_0, VIJ_ji_1, VIJ_ji_2, DWIJ_ji_0, DWIJ_ji_1, DWIJ_ji_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, ps_acc_au, ps_acc_av, ps_acc_aw, s_cs[s_idx], d_p, s_rho[s_idx], sval_cs, sval_m, s_p, sval_rho, hoisted_eq2_0, hoisted_eq2_0[s_idx], pshared_eq2_0, pshared_eq2_1, pshared_eq2_2);
          XSPHCorrection_loop_simd_mirror(s_idx, d_idx, t, dt, VIJ_ji_0, VIJ_ji_1, VIJ_ji_2, WIJ, RHOIJ1, eq3.eps, ps_acc_ax, ps_acc_ay, ps_acc_az, sval_m);
          ia0[l] += in_support ? pd_acc_arho : 0.0;
          ia1[l] += in_support ? pd_acc_au : 0.0;
          ia2[l] += in_support ? pd_acc_av : 0.0;
          ia3[l] += in_support ? pd_acc_aw : 0.0;
          ia4[l] += in_support ? pd_acc_ax : 0.0;
          ia5[l] += in_support ? pd_acc_ay : 0.0;
          ia6[l] += in_support ? pd_acc_az : 0.0;
          jacc[0][l] += in_support ? ps_acc_arho : 0.0;
          jacc[1][l] += in_support ? ps_acc_au : 0.0;
          jacc[2][l] += in_support ? ps_acc_av : 0.0;
          jacc[3][l] += in_support ? ps_acc_aw : 0.0;
          jacc[4][l] += in_support ? ps_acc_ax : 0.0;
          jacc[5][l] += in_support ? ps_acc_ay : 0.0;
          jacc[6][l] += in_support ? ps_acc_az : 0.0;
        }
      }
      for (int k = 0; k < 7; ++k) {
        #pragma omp simd
        for (int l = 0; l < CJ; ++l) S[k][j0 + l] += jacc[k][l];
      }
    }
    for (int ii = 0; ii < CI; ++ii)
      for (int k = 0; k < 7; ++k) {
        double sum = 0;
        for (int l = 0; l < CJ; ++l) sum += iacc[ii][k][l];
        S[k][i0 + ii] += sum;
      }
  }
}

// The tile printable by sphc (stop 37, docs/performance-log.md "Cluster-pair tiles in the
// printer"): form_c_omp's lane body (the generated _simd / _simd_mirror calls) under
// `#pragma omp simd` over the 8 j's of a tile, with what makes GCC 12 vectorise it in 512-bit
// vectors: s_idx the lane (the source arrays offset to the j-cluster: no int arithmetic in
// the loop), the trip count the constant 8, and no jump threading in the function (GCC's
// threading of the kernel's branches before if-conversion leaves "control flow in loop":
// TILE_OPTIMIZE, -DTILE_OPTIMIZE= to see it). SKIP: a row whose lanes are all beyond the
// cut-off is skipped (a first `omp simd` loop over the 8 lanes: the cut-off only; SKIP = 1 a
// double sum of 0 or 1 per lane, SKIP = 2 an int OR reduction, which makes GCC 12 take 8
// lanes of int, so the loop in 256-bit vectors, and costs 10-12% more per sweep). ACC: the
// sums accumulated in the lane arrays in the calls (pd_acc_ = ia[l]; the body's fma onto it;
// kept under the mask), else the pair's terms from 0 added under the mask (as the lane form
// prints them). NEG: the mirrored vectors XIJ_ji, VIJ_ji as negations (the same doubles as
// the differences, a - b = -(b - a), but for the sign of a zero), else differences.
#ifndef TILE_OPTIMIZE
#define TILE_OPTIMIZE __attribute__((optimize("no-thread-jumps")))
#endif
template <int CI, int SKIP, int ACC, int NEG>
__attribute__((noinline)) TILE_OPTIMIZE void form_c_print(Clusters& cl, const PairList& pl, const Constants& eqc) {
  Fluid& fl = cl.f;
  const double t = 0.0, dt = 1e-4;
  const double *sj_x = fl.x.data(), *sj_y = fl.y.data(), *sj_z = fl.z.data();
  const double *sj_u = fl.u.data(), *sj_v = fl.v.data(), *sj_w = fl.w.data();
  const double *sj_h = fl.h.data(), *sj_rho = fl.rho.data(), *di_rho = sj_rho;
  const double *s_cs = fl.cs.data(), *s_m = fl.m.data(), *s_p = fl.p.data(), *s_rho = fl.rho.data();
  const double *d_p = s_p, *hoisted_eq2_0 = fl.hoisted.data();
  double* S[7];
  for (int k = 0; k < 7; ++k) S[k] = fl.sums[k].data();
  struct { double alpha, beta; } eq2{eqc.alpha, eqc.beta};
  struct { double eps; } eq3{eqc.eps};
  const int nci = static_cast<int>(pl.start.size()) - 1;
  constexpr int n_lanes = CJ;  // a constant trip count (a runtime one: 32-byte vectors, a scalar epilogue)
  for (int ci = 0; ci < nci; ++ci) {
    const int i0 = ci * CI;
    if (pl.start[ci] == pl.start[ci + 1]) continue;
    alignas(64) double iacc[CI][7][CJ] = {};
    for (int e = pl.start[ci]; e < pl.start[ci + 1]; ++e) {
      const int j0 = pl.cj[e] * CJ;
      const bool diagonal = j0 < i0 + CI;
      alignas(64) double jacc[7][CJ] = {};
      for (int ii = 0; ii < CI; ++ii) {
        const int d_idx = i0 + ii;
        const double xi = sj_x[d_idx], yi = sj_y[d_idx], zi = sj_z[d_idx], hi = sj_h[d_idx];
        const double ui = sj_u[d_idx], vi = sj_v[d_idx], wi = sj_w[d_idx];
        const double dhoisted_eq2_0 = hoisted_eq2_0[d_idx];
        const double dval_cs = s_cs[d_idx], dval_rho = s_rho[d_idx];
        const double sval_m = s_m[d_idx], sval_cs = s_cs[d_idx], sval_rho = s_rho[d_idx];
        double* ia0 = iacc[ii][0]; double* ia1 = iacc[ii][1]; double* ia2 = iacc[ii][2];
        double* ia3 = iacc[ii][3]; double* ia4 = iacc[ii][4]; double* ia5 = iacc[ii][5];
        double* ia6 = iacc[ii][6];
        const double j_min = diagonal ? double(d_idx - j0) : -1.0;  // the diagonal tile: j > i only
        static constexpr double lane_d[CJ] = {0, 1, 2, 3, 4, 5, 6, 7};
        const double *jx = sj_x + j0, *jy = sj_y + j0, *jz = sj_z + j0, *ju = sj_u + j0, *jv = sj_v + j0, *jw = sj_w + j0, *jh = sj_h + j0, *jrho = s_rho + j0, *jcs = s_cs + j0, *jm = s_m + j0, *jp = s_p + j0, *jho = hoisted_eq2_0 + j0;
        if (SKIP == 2) {  // an int OR reduction: GCC takes 2 x 256-bit vectors for the loop
          int any = 0;
          #pragma omp simd reduction(|: any)
          for (int l = 0; l < n_lanes; ++l) {
            const double XIJ_0 = xi - jx[l];
            const double XIJ_1 = yi - jy[l];
            const double XIJ_2 = zi - jz[l];
            const double R2IJ = XIJ_0 * XIJ_0 + XIJ_1 * XIJ_1 + XIJ_2 * XIJ_2;
            const double hj = jh[l];
            const double hmax = hi > hj ? hi : hj;
            any |= !(R2IJ >= RADIUS2 * hmax * hmax) & (lane_d[l] > j_min);
          }
          if (!any) continue;
        } else if (SKIP) {  // a double sum of 0 / 1: one 512-bit vector
          double any = 0.0;
          #pragma omp simd reduction(+: any)
          for (int l = 0; l < n_lanes; ++l) {
            const double XIJ_0 = xi - jx[l];
            const double XIJ_1 = yi - jy[l];
            const double XIJ_2 = zi - jz[l];
            const double R2IJ = XIJ_0 * XIJ_0 + XIJ_1 * XIJ_1 + XIJ_2 * XIJ_2;
            const double hj = jh[l];
            const double hmax = hi > hj ? hi : hj;
            any += !(R2IJ >= RADIUS2 * hmax * hmax) & (lane_d[l] > j_min) ? 1.0 : 0.0;
          }
          if (!(any > 0.0)) continue;
        }
        // s_idx = the lane: the source's arrays offset to the j-cluster (an int s_idx = j0 + l
        // in the loop makes GCC 12 take 16 lanes for its ints, so 256-bit vectors for the
        // doubles); vectorised in 512-bit vectors where jump threading is off (TILE_OPTIMIZE)
        #pragma omp simd
        for (int l = 0; l < n_lanes; ++l) {
          const int s_idx = l;
          const double hj = jh[s_idx];
          const double XIJ_0 = xi - jx[s_idx];
          const double XIJ_1 = yi - jy[s_idx];
          const double XIJ_2 = zi - jz[s_idx];
          const double XIJ_ji_0 = NEG ? -XIJ_0 : jx[s_idx] - xi;
          const double XIJ_ji_1 = NEG ? -XIJ_1 : jy[s_idx] - yi;
          const double XIJ_ji_2 = NEG ? -XIJ_2 : jz[s_idx] - zi;
          const double R2IJ = XIJ_0 * XIJ_0 + XIJ_1 * XIJ_1 + XIJ_2 * XIJ_2;
          const double HIJ = 0.5 * (hi + hj);
          const double RIJ = std::sqrt(R2IJ);
          const double VIJ_0 = ui - ju[s_idx];
          const double VIJ_1 = vi - jv[s_idx];
          const double VIJ_2 = wi - jw[s_idx];
          const double VIJ_ji_0 = NEG ? -VIJ_0 : ju[s_idx] - ui;
          const double VIJ_ji_1 = NEG ? -VIJ_1 : jv[s_idx] - vi;
          const double VIJ_ji_2 = NEG ? -VIJ_2 : jw[s_idx] - wi;
          const double WIJ = Kernel::w(RIJ, HIJ);
          const double DWIJ_f = Kernel::gradient_factor(RIJ, HIJ);
          const double DWIJ_0 = DWIJ_f * XIJ_0;
          const double DWIJ_1 = DWIJ_f * XIJ_1;
          const double DWIJ_2 = DWIJ_f * XIJ_2;
          const double DWIJ_ji_0 = DWIJ_f * XIJ_ji_0;
          const double DWIJ_ji_1 = DWIJ_f * XIJ_ji_1;
          const double DWIJ_ji_2 = DWIJ_f * XIJ_ji_2;
          const double RHOIJ = 0.5 * (di_rho[d_idx] + jrho[s_idx]);
          const double RHOIJ1 = 1.0 / RHOIJ;
          const double EPS = 0.01 * HIJ * HIJ;
          const double hmax = hi > hj ? hi : hj;
          const bool in_support = !(R2IJ >= RADIUS2 * hmax * hmax) & (lane_d[l] > j_min);
          const double pshared_eq1_0 = ContinuityEquation_loop_pairshared0_simd(d_idx, s_idx, t, dt, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, jm);
          const double pshared_eq2_0 = MomentumEquation_loop_pairshared0_simd(d_idx, s_idx, t, dt, XIJ_0, XIJ_1, XIJ_2, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, dval_cs, d_p, dval_rho, jcs, jm, jp, jrho, jho, dhoisted_eq2_0);
          const double pshared_eq2_1 = MomentumEquation_loop_pairshared1_simd(d_idx, s_idx, t, dt, XIJ_0, XIJ_1, XIJ_2, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, dval_cs, d_p, dval_rho, jcs, jm, jp, jrho, jho, dhoisted_eq2_0);
          const double pshared_eq2_2 = MomentumEquation_loop_pairshared2_simd(d_idx, s_idx, t, dt, XIJ_0, XIJ_1, XIJ_2, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, dval_cs, d_p, dval_rho, jcs, jm, jp, jrho, jho, dhoisted_eq2_0);
          double pd_acc_arho = ACC ? ia0[l] : 0.0, pd_acc_au = ACC ? ia1[l] : 0.0, pd_acc_av = ACC ? ia2[l] : 0.0, pd_acc_aw = ACC ? ia3[l] : 0.0, pd_acc_ax = ACC ? ia4[l] : 0.0, pd_acc_ay = ACC ? ia5[l] : 0.0, pd_acc_az = ACC ? ia6[l] : 0.0;
          double ps_acc_arho = ACC ? jacc[0][l] : 0.0, ps_acc_au = ACC ? jacc[1][l] : 0.0, ps_acc_av = ACC ? jacc[2][l] : 0.0, ps_acc_aw = ACC ? jacc[3][l] : 0.0, ps_acc_ax = ACC ? jacc[4][l] : 0.0, ps_acc_ay = ACC ? jacc[5][l] : 0.0, ps_acc_az = ACC ? jacc[6][l] : 0.0;
          ContinuityEquation_loop_simd(d_idx, s_idx, t, dt, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, pd_acc_arho, jm, pshared_eq1_0);
          MomentumEquation_loop_simd(d_idx, s_idx, t, dt, XIJ_0, XIJ_1, XIJ_2, VIJ_0, VIJ_1, VIJ_2, DWIJ_0, DWIJ_1, DWIJ_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, pd_acc_au, pd_acc_av, pd_acc_aw, dval_cs, d_p, dval_rho, jcs, jm, jp, jrho, jho, dhoisted_eq2_0, pshared_eq2_0, pshared_eq2_1, pshared_eq2_2);
          XSPHCorrection_loop_simd(d_idx, s_idx, t, dt, VIJ_0, VIJ_1, VIJ_2, WIJ, RHOIJ1, eq3.eps, pd_acc_ax, pd_acc_ay, pd_acc_az, jm);
          ContinuityEquation_loop_simd_mirror(s_idx, d_idx, t, dt, VIJ_ji_0, VIJ_ji_1, VIJ_ji_2, DWIJ_ji_0, DWIJ_ji_1, DWIJ_ji_2, ps_acc_arho, sval_m, pshared_eq1_0);
          MomentumEquation_loop_simd_mirror(s_idx, d_idx, t, dt, XIJ_ji_0, XIJ_ji_1, XIJ_ji_2, VIJ_ji_0, VIJ_ji_1, VIJ_ji_2, DWIJ_ji_0, DWIJ_ji_1, DWIJ_ji_2, R2IJ, HIJ, RHOIJ1, EPS, eq2.alpha, eq2.beta, ps_acc_au, ps_acc_av, ps_acc_aw, jcs[s_idx], d_p, jrho[s_idx], sval_cs, sval_m, s_p, sval_rho, jho, jho[s_idx], pshared_eq2_0, pshared_eq2_1, pshared_eq2_2);
          XSPHCorrection_loop_simd_mirror(s_idx, d_idx, t, dt, VIJ_ji_0, VIJ_ji_1, VIJ_ji_2, WIJ, RHOIJ1, eq3.eps, ps_acc_ax, ps_acc_ay, ps_acc_az, sval_m);
          if (ACC) ia0[l] = in_support ? pd_acc_arho : ia0[l]; else ia0[l] += in_support ? pd_acc_arho : 0.0;
          if (ACC) ia1[l] = in_support ? pd_acc_au : ia1[l]; else ia1[l] += in_support ? pd_acc_au : 0.0;
          if (ACC) ia2[l] = in_support ? pd_acc_av : ia2[l]; else ia2[l] += in_support ? pd_acc_av : 0.0;
          if (ACC) ia3[l] = in_support ? pd_acc_aw : ia3[l]; else ia3[l] += in_support ? pd_acc_aw : 0.0;
          if (ACC) ia4[l] = in_support ? pd_acc_ax : ia4[l]; else ia4[l] += in_support ? pd_acc_ax : 0.0;
          if (ACC) ia5[l] = in_support ? pd_acc_ay : ia5[l]; else ia5[l] += in_support ? pd_acc_ay : 0.0;
          if (ACC) ia6[l] = in_support ? pd_acc_az : ia6[l]; else ia6[l] += in_support ? pd_acc_az : 0.0;
          if (ACC) jacc[0][l] = in_support ? ps_acc_arho : jacc[0][l]; else jacc[0][l] += in_support ? ps_acc_arho : 0.0;
          if (ACC) jacc[1][l] = in_support ? ps_acc_au : jacc[1][l]; else jacc[1][l] += in_support ? ps_acc_au : 0.0;
          if (ACC) jacc[2][l] = in_support ? ps_acc_av : jacc[2][l]; else jacc[2][l] += in_support ? ps_acc_av : 0.0;
          if (ACC) jacc[3][l] = in_support ? ps_acc_aw : jacc[3][l]; else jacc[3][l] += in_support ? ps_acc_aw : 0.0;
          if (ACC) jacc[4][l] = in_support ? ps_acc_ax : jacc[4][l]; else jacc[4][l] += in_support ? ps_acc_ax : 0.0;
          if (ACC) jacc[5][l] = in_support ? ps_acc_ay : jacc[5][l]; else jacc[5][l] += in_support ? ps_acc_ay : 0.0;
          if (ACC) jacc[6][l] = in_support ? ps_acc_az : jacc[6][l]; else jacc[6][l] += in_support ? ps_acc_az : 0.0;
        }
      }
      for (int k = 0; k < 7; ++k) {
        #pragma omp simd
        for (int l = 0; l < CJ; ++l) S[k][j0 + l] += jacc[k][l];
      }
    }
    for (int ii = 0; ii < CI; ++ii)
      for (int k = 0; k < 7; ++k) {
        double sum = 0;
        for (int l = 0; l < CJ; ++l) sum += iacc[ii][k][l];
        S[k][i0 + ii] += sum;
      }
  }
}

// Counts of one list: tile lanes (CI x 8 per entry), pairs within the support among them.
struct TileCounts {
  long entries = 0, lanes = 0, in_support = 0;
  long rows = 0;  // tile rows (one i x 8 j's) with a pair within the support: the rows computed
};
TileCounts count_tiles(const Clusters& cl, const PairList& pl) {
  TileCounts tc;
  const Fluid& f = cl.f;
  const int CI = pl.ci_size;
  for (size_t ci = 0; ci + 1 < pl.start.size(); ++ci)
    for (int e = pl.start[ci]; e < pl.start[ci + 1]; ++e) {
      ++tc.entries;
      tc.lanes += CI * CJ;
      for (int i = static_cast<int>(ci) * CI; i < static_cast<int>(ci) * CI + CI; ++i) {
        long row = 0;
        for (int j = pl.cj[e] * CJ; j < pl.cj[e] * CJ + CJ; ++j) {
          if (j <= i) continue;
          const double XIJ[3] = {f.x[i] - f.x[j], f.y[i] - f.y[j], f.z[i] - f.z[j]};
          const double R2IJ = XIJ[0] * XIJ[0] + XIJ[1] * XIJ[1] + XIJ[2] * XIJ[2];
          const double hm = std::max(f.h[i], f.h[j]);
          if (!(R2IJ >= RADIUS2 * hm * hm)) ++row;
        }
        tc.in_support += row;
        tc.rows += row > 0;
      }
    }
  return tc;
}

// ---- Checks, timing, main ----

// Per sum: max |got - ref| / max |ref| over the particles (got in the reference's order).
double worst_difference(const Fluid& ref, const std::vector<double> (&got)[7], const char** which) {
  double worst = 0;
  for (int k = 0; k < 7; ++k) {
    double scale = 0, diff = 0;
    for (int i = 0; i < ref.n; ++i) {
      scale = std::max(scale, std::fabs(ref.sums[k][i]));
      diff = std::max(diff, std::fabs(got[k][i] - ref.sums[k][i]));
    }
    const double rel = scale > 0 ? diff / scale : diff;
    if (rel >= worst) worst = rel, *which = kSumNames[k];
  }
  return worst;
}

// The flops of form (a) per pair within the support (each pair once: one evaluation for the
// two ordered pairs), counted from its C++ above with the common values of Kernel::w and
// gradient_pair computed once (1 / h, sigma / h^3, q, 2 - q: GCC's CSE), div and sqrt 1,
// fma 2, max and compares 0:
//   every kept candidate j > i: XIJ 3, R2IJ 5, RADIUS2 hmax hmax 2                    = 10
//   within the support: XIJ_ji 3, HIJ 2, sqrt 1, VIJ and VIJ_ji 6, 1/h 1, sigma/h^3 3,
//     q 1, W 1 (the shape f: 6 for q < 1, else 4), dW/dq 1 (f': 3 for q < 1, else 2),
//     h rij and the division 2, DWIJ and DWIJ_ji 6, RHOIJ and 1/RHOIJ 3, EPS 2, the
//     shared values v.dw 5, p/rho^2 sum 1, v.x 5, continuity 2 + 2, momentum 8 + 7 (the
//     mirrored -eps m_i of XSPH is hoisted), XSPH 9 + 8                               = 79 + f + f'
//     the viscosity where v.x < 0: cij 2, muij 3 (a division), piij 6                 = 11
struct FlopCount {
  double per_pair = 0;  // per pair within the support, the rejected candidates' share included
  long lanes_b = 0;     // form (b)'s lanes: each list's j > i in chunks of 8
};
FlopCount count_flops_a(const Fluid& f, const KeptLists& kl, long& pairs) {
  long cand = 0, inside = 0, near = 0, visc = 0, lanes_b = 0;
  for (int i = 0; i < f.n; ++i) {
    const std::vector<std::uint32_t>& L = kl.lists[i];
    const long upper = static_cast<long>(L.size()) - kl.upper[i] - (kl.upper[i] < L.size() && L[kl.upper[i]] == static_cast<std::uint32_t>(i));
    lanes_b += (upper + 7) / 8 * 8;  // form (b): chunks of 8 lanes
    for (size_t t = kl.upper[i]; t < L.size(); ++t) {
      const int j = static_cast<int>(L[t]);
      if (j == i) continue;
      ++cand;
      const double XIJ[3] = {f.x[i] - f.x[j], f.y[i] - f.y[j], f.z[i] - f.z[j]};
      const double R2IJ = XIJ[0] * XIJ[0] + XIJ[1] * XIJ[1] + XIJ[2] * XIJ[2];
      const double hm = std::max(f.h[i], f.h[j]);
      if (R2IJ >= RADIUS2 * hm * hm) continue;
      ++inside;
      const double HIJ = 0.5 * (f.h[i] + f.h[j]);
      if (std::sqrt(R2IJ) / HIJ < 1.0) ++near;
      const double vdx = (f.u[i] - f.u[j]) * XIJ[0] + (f.v[i] - f.v[j]) * XIJ[1] + (f.w[i] - f.w[j]) * XIJ[2];
      if (vdx < 0) ++visc;
    }
  }
  pairs = inside;
  FlopCount fc;
  fc.lanes_b = lanes_b;
  fc.per_pair = (10.0 * cand + 79.0 * inside + (6.0 + 3.0) * near + (4.0 + 2.0) * (inside - near) + 11.0 * visc) /
                inside;
  std::printf("pairs j > i: %ld kept candidates, %ld within the support (%.1f ordered neighbours per particle), "
              "%.1f%% with q < 1, %.1f%% with v.x < 0; form (b)'s lanes (chunks of 8): %ld, %.1f%% within the support\n",
              cand, inside, 2.0 * inside / f.n, 100.0 * near / inside, 100.0 * visc / inside, lanes_b,
              100.0 * inside / lanes_b);
  return fc;
}

struct Result {
  std::string name;
  std::vector<double> times;
  double diff = 0;
  const char* diff_sum = "";
  double mask_in = -1;  // fraction of tile lanes within the support (c)
  long lanes = 0;
};

}  // namespace

int main(int argc, char** argv) {
  int nx = 47, reps = 7;
  double pert = 0.05, skin = 0.1, column = 0, hdx = 1.5;
  bool uniform = false;  // column side in dx (0: (8 / density)^(1/3))
  std::string forms = "a,b,c1x8,c1x8rcp,c1x8cut,c1x8rcpcut,c2x8cut,c2x8rcpcut,c4x8,c8x8,c4x8rcp,c8x8rcp,c4x8cut,c8x8cut,c4x8rcpcut,c8x8rcpcut,c4x8rcpdivcut,c8x8rcpdivcut,c4x8ompcut";
  double tol = 1e-12;
  bench::Options opts;
  opts.value("--nx", nx).value("--reps", reps).value("--pert", pert).value("--hdx", hdx);
  opts.flag("--uniform-velocity", uniform).value("--skin", skin).value("--column", column);
  opts.value("--forms", forms).value("--tol", tol);
  if (!opts.parse(argc, argv,
                  "[--nx 47] [--hdx 1.5] [--uniform-velocity] [--reps 7] [--pert 0.05] [--skin 0.1] [--column DX] [--tol 1e-12]\n"
                  "          [--forms a,b,c4x8,c8x8,c4x8rcp,c8x8rcp,c4x8cut,...]\n"
                  "  c<CI>x8[rcp|rcpdiv|lean][cut], CI = 1, 2, 4, 8: cluster-pair tiles, CI i's x 8 j's; rcp:\n"
                  "  reciprocal approximations (rcpdiv: for the divisions only; lean: rcp, fewer operations);\n"
                  "  cut: the cluster-pair list pruned at the support (no skin); omp: the tile as `omp simd`\n"
                  "  over the 8 j's with the generated lane body (no intrinsics)"))
    return 2;
#ifdef __AVX512F__
  if (!__builtin_cpu_supports("avx512f")) {
    std::printf("no AVX-512F on this CPU: skipped\n");
    return 77;
  }
#endif
  const double dx = 1.0 / nx, hmax = hdx * dx;
  Fluid fa = make_cube(nx, hdx, pert, uniform, 12345);
  const Constants eq;
  std::printf("cube nx = %d: %d particles, h = %.3g dx, positions +-%.3g dx, kept lists' skin %.2f, %s velocities\n",
              nx, fa.n, hdx, pert, skin, uniform ? "uniform (the cube's free fall)" : "random");
  double t0 = cpu_now();
  const KeptLists kl = build_kept_lists(fa, skin);
  const double t_kept = cpu_now() - t0;
  long pairs = 0;
  const FlopCount fc = count_flops_a(fa, kl, pairs);
  std::printf("flops of form (a) per pair within the support (one evaluation for both particles): %.2f "
              "(%.2f per ordered pair)\n",
              fc.per_pair, fc.per_pair / 2);
  // Cluster order: columns of side (8 / density)^(1/3) by default (2 dx on the lattice: a
  // j-cluster of 8 is 2 x 2 x 2 particles, an i-cluster of 4 one 2 x 2 layer).
  const double col = (column > 0 ? column : 2.0) * dx;
  t0 = cpu_now();
  Clusters cl = make_clusters(fa, col);
  const double t_sort = cpu_now() - t0;
  struct ListSet {
    int ci;
    double rlist;
    PairList pl;
    double build;
  };
  std::vector<ListSet> lists;
  for (int ci : {1, 2, 4, 8})
    for (double r : {Kernel::radius_scale * hmax * (1.0 + skin), Kernel::radius_scale * hmax}) {
      t0 = cpu_now();
      PairList pl = build_pair_list(cl, ci, r);
      lists.push_back({ci, r, std::move(pl), cpu_now() - t0});
    }
  std::printf("clusters: columns %.2f dx, %d particles with padding (%.1f%%), %d j-clusters; sort %.3f s, "
              "kept lists %.3f s CPU\n",
              col / dx, cl.f.n, 100.0 * (cl.f.n - fa.n) / fa.n, cl.ncj, t_sort, t_kept);
  for (const ListSet& ls : lists) {
    if (ls.rlist < Kernel::radius_scale * hmax * (1.0 + 0.5 * skin)) continue;
    double best = 1e30;
    size_t kept = 0;
    for (int r = 0; r < 3; ++r) {
      t0 = cpu_now();
      const PairList pruned = prune(cl, ls.pl, Kernel::radius_scale * hmax);
      best = std::min(best, cpu_now() - t0);
      kept = pruned.cj.size();
    }
    std::printf("  pruning the %dx8 list (radius %.2f h) to 2 h with the current boxes: %.4f s CPU, %zu of %zu cluster "
                "pairs kept\n", ls.ci, ls.rlist / hmax, best, kept, ls.pl.cj.size());
  }
  {
    const PairList pl44 = build_pair_list(cl, 4, Kernel::radius_scale * hmax, 4);
    const std::pair<double, long> mm = count_2xmm(cl, pl44);
    std::printf("  (counted only) 2xMM, j-clusters of 4, radius 2.00 h: %ld vectors of 2 i's x 4 j's computed, "
                "%.1f%% of their lanes within the support\n", mm.second, 100.0 * mm.first);
  }
  std::vector<TileCounts> counts;
  for (const ListSet& ls : lists) {
    const TileCounts tc = count_tiles(cl, ls.pl);
    counts.push_back(tc);
    std::printf("  list %dx8, radius %.2f h: %ld cluster pairs (%.1f per i-cluster), %ld tile lanes, %.1f%% within "
                "the support, %.1f%% of the rows computed (%.1f%% of their lanes within); build %.3f s CPU%s\n",
                ls.ci, ls.rlist / hmax, tc.entries, double(tc.entries) / (ls.pl.start.size() - 1), tc.lanes,
                100.0 * tc.in_support / tc.lanes, 100.0 * tc.rows * CJ / tc.lanes,
                100.0 * tc.in_support / (tc.rows * CJ), ls.build,
                tc.in_support == pairs ? "" : "  ** INCOMPLETE: pairs missing **");
    if (tc.in_support != pairs) return 1;
  }

  // The forms, interleaved: per round each form once, from sums at 0.
  struct Form {
    std::string name;
    std::function<void()> run;
    Fluid* data;
    const ListSet* ls;
  };
  Fluid fb = fa;
  Fluid ref = fa;  // form (a)'s sums: the reference
  ref.zero_sums();
  form_a(ref, kl, eq);
  std::vector<Form> all;
  all.push_back({"a", [&] { form_a(fa, kl, eq); }, &fa, nullptr});
  all.push_back({"b", [&] { form_b(fb, kl, eq); }, &fb, nullptr});
#ifdef __AVX512F__
  // c<CI>x8[rcp|rcpdiv][cut]: every tile size, arithmetic and list.
  for (const ListSet& l : lists)
    for (int arith : {EXACT, RCP, RCP_DIV, LEAN}) {
      const bool cut = l.rlist < Kernel::radius_scale * hmax * (1.0 + 0.5 * skin);
      const std::string name = "c" + std::to_string(l.ci) + "x8" +
                               (arith == RCP ? "rcp" : arith == RCP_DIV ? "rcpdiv" : arith == LEAN ? "lean" : "") +
                               (cut ? "cut" : "");
      Clusters* c = &cl;
      const Constants* e = &eq;
      const ListSet* ls = &l;
      std::function<void()> run;
      auto pick = [&](auto ci_tag) {
        constexpr int CI = decltype(ci_tag)::value;
        if (arith == EXACT) run = [c, ls, e] { form_c<CI, EXACT>(*c, ls->pl, *e); };
        if (arith == RCP) run = [c, ls, e] { form_c<CI, RCP>(*c, ls->pl, *e); };
        if (arith == RCP_DIV) run = [c, ls, e] { form_c<CI, RCP_DIV>(*c, ls->pl, *e); };
        if (arith == LEAN) run = [c, ls, e] { form_c<CI, LEAN>(*c, ls->pl, *e); };
      };
      if (l.ci == 1) pick(std::integral_constant<int, 1>());
      if (l.ci == 2) pick(std::integral_constant<int, 2>());
      if (l.ci == 4) pick(std::integral_constant<int, 4>());
      if (l.ci == 8) pick(std::integral_constant<int, 8>());
      all.push_back({name, run, &cl.f, ls});
    }
#endif
  for (int ci : {4, 8})
    for (bool cut : {false, true}) {
      const ListSet* ls = nullptr;
      for (const ListSet& l : lists)
        if (l.ci == ci && (l.rlist < Kernel::radius_scale * hmax * (1.0 + 0.5 * skin)) == cut) ls = &l;
      std::function<void()> run = ci == 4 ? std::function<void()>([&cl, ls, &eq] { form_c_omp<4>(cl, ls->pl, eq); })
                                          : std::function<void()>([&cl, ls, &eq] { form_c_omp<8>(cl, ls->pl, eq); });
      all.push_back({std::string("c") + (ci == 4 ? "4" : "8") + "x8omp" + (cut ? "cut" : ""), run, &cl.f, ls});
    }
  // The printable tiles: c<CI>x8print[skip|skipor][acc][neg]cut on the pruned lists (CI = 8:
  // every variant; CI = 4: skip, acc and neg only).
  {
    auto list_of = [&](int ci) {
      const ListSet* ls = nullptr;
      for (const ListSet& l : lists)
        if (l.ci == ci && l.rlist < Kernel::radius_scale * hmax * (1.0 + 0.5 * skin)) ls = &l;
      return ls;
    };
    const ListSet* l8 = list_of(8);
    const ListSet* l4 = list_of(4);
    auto add8 = [&](auto skip, auto acc, auto neg) {
      constexpr int S = decltype(skip)::value, A = decltype(acc)::value, N = decltype(neg)::value;
      all.push_back({std::string("c8x8print") + (S ? "skip" : "") + (A ? "acc" : "") + (N ? "neg" : "") + "cut",
                     [&cl, l8, &eq] { form_c_print<8, S, A, N>(cl, l8->pl, eq); }, &cl.f, l8});
    };
    using Z = std::integral_constant<int, 0>;
    using O = std::integral_constant<int, 1>;
    add8(Z(), Z(), Z()); add8(O(), Z(), Z()); add8(Z(), O(), Z()); add8(O(), O(), Z());
    add8(Z(), Z(), O()); add8(O(), Z(), O()); add8(Z(), O(), O()); add8(O(), O(), O());
    all.push_back({"c8x8printskiporaccnegcut", [&cl, l8, &eq] { form_c_print<8, 2, 1, 1>(cl, l8->pl, eq); }, &cl.f, l8});
    all.push_back({"c4x8printskipaccnegcut", [&cl, l4, &eq] { form_c_print<4, 1, 1, 1>(cl, l4->pl, eq); }, &cl.f, l4});
  }
  std::vector<Form> chosen;
  for (const Form& fm : all)
    if (("," + forms + ",").find("," + fm.name + ",") != std::string::npos) chosen.push_back(fm);
  std::vector<Result> results(chosen.size());
  for (size_t k = 0; k < chosen.size(); ++k) results[k].name = chosen[k].name;
  bool ok = true;
  for (int r = 0; r < reps; ++r)
    for (size_t k = 0; k < chosen.size(); ++k) {
      chosen[k].data->zero_sums();
      const double s = cpu_now();
      chosen[k].run();
      results[k].times.push_back(cpu_now() - s);
      if (r == 0) {  // the check against (a)
        std::vector<double> got[7];
        for (int q = 0; q < 7; ++q) {
          got[q].resize(fa.n);
          for (int i = 0; i < fa.n; ++i)
            got[q][i] = chosen[k].data == &cl.f ? cl.f.sums[q][cl.of_original[i]] : chosen[k].data->sums[q][i];
        }
        results[k].diff = worst_difference(ref, got, &results[k].diff_sum);
        if (!(results[k].diff <= tol)) ok = false;
      }
    }
  const double clock = 2.3e9, peak = clock * 2 * 2 * 8;  // this Xeon: 2 FMA units x 2 flops x 8 doubles
  std::printf("\nform           CPU s/sweep min (median)  M ordered pairs/s  cycles/pair  useful GFLOP/s  of peak"
              "  lanes in support  cycles/vector  max diff vs (a)\n");
  for (size_t k = 0; k < chosen.size(); ++k) {
    const Result& r = results[k];
    const double tmin = *std::min_element(r.times.begin(), r.times.end());
    const double rate = 2.0 * pairs / tmin;
    const double gflops = pairs * fc.per_pair / tmin * 1e-9;
    char in[32] = "-", cyc[32] = "-";
    if (chosen[k].ls) {  // (c): per tile row computed (one i x 8 j's)
      const TileCounts& tc = counts[chosen[k].ls - lists.data()];
      std::snprintf(in, sizeof in, "%.1f%%", 100.0 * tc.in_support / tc.lanes);
      std::snprintf(cyc, sizeof cyc, "%.1f", tmin * clock / tc.rows);
    } else if (chosen[k].name == "b") {  // (b): per chunk of 8 lanes
      std::snprintf(in, sizeof in, "%.1f%%", 100.0 * pairs / fc.lanes_b);
      std::snprintf(cyc, sizeof cyc, "%.1f", tmin * clock / (fc.lanes_b / 8));
    }
    std::printf("%-14s %8.4f (%8.4f)        %10.1f  %11.2f  %14.2f  %6.1f%%  %16s  %13s  %.2e (%s)\n", r.name.c_str(),
                tmin, median(r.times), rate * 1e-6, tmin * clock / (2.0 * pairs), gflops, 100.0 * gflops * 1e9 / peak,
                in, cyc, r.diff, r.diff_sum);
  }
#ifdef __AVX512F__
  std::printf("clock while running 512-bit FMAs (a chain of dependent vfmadd, 4 cycles each): %.2f GHz\n",
              clock_estimate(30000000) * 1e-9);
#endif
  std::printf("(peak %.1f GFLOP/s at %.1f GHz; useful = pairs within the support x %.2f flops of form (a); thread CPU\n"
              " time, best of %d interleaved rounds; cycles at the nominal clock, per ordered pair within the support\n"
              " and per vector of 8 lanes computed)\n",
              peak * 1e-9, clock * 1e-9, fc.per_pair, reps);
  if (!ok) {
    std::printf("FAILED: a form's sums differ from form (a)'s by more than %.1e of the largest\n", tol);
    return 1;
  }
  std::printf("OK: every form's sums within %.1e of form (a)'s (of each sum's largest value)\n", tol);
  return 0;
}
