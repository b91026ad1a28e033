// The 2D dam break's fluid <- fluid pass with PySPH's effects (examples/dambreak.sph -D
// density_diffusion=off -D shifting=off: continuity, momentum with Monaghan's artificial
// viscosity, XSPH; WendlandQuintic 2D, h = 1.3 dx, support 2 h, ~19 neighbours), timed by
// hand in SIMD tiles against the scalar each-pair-once loop sphc prints today
// (docs/performance-log.md, "SIMD tiles in 2D, measured by hand (stop 38)"; issue 16). Not a test
// of the solver: a prototype that prints figures, self-checking (exit 1 if a form's sums
// disagree with form (a) beyond the tolerance, or a list misses a pair).
//
//   (a) today's scalar form (sphc's default in 2D: --simd-pairs=auto leaves 2D scalar): per
//       destination i its kept list (candidates within 1.1 x 2 h, index order), the pairs
//       j > i, the cut-off a branch, each pair once: i's sums in locals, j's in memory. The
//       loop and the bodies are the generated C++ of `sphc examples/dambreak.sph -D
//       density_diffusion=off -D shifting=off --emit=cpp` (main 9996b02), copied verbatim
//       (#line directives removed; the kernel is the runtime's, sphc/kernels.h).
//   (t) cluster-pair tiles in AVX-512 intrinsics on the runtime's layout and lists
//       (sphc/cluster_pairs.h), shape CI x CJ: i-clusters of CI, j-clusters of CJ, a zmm
//       register of 8 lanes holding RI = 8 / CJ i's x CJ j's:
//         t4x4  GROMACS' "2xMM" (layout of width 4; one zmm = 2 i's x the 4 j's, the j's
//               loaded once per tile into both halves, two registers per tile),
//         t4x8  i-clusters the halves of 8-clusters (layout of width 8) x j-clusters of 8,
//               one zmm per i (a row),
//         t8x8  stop 36-37's tile (layout of width 8), one zmm per i.
//       The pruned list (the outer list at 1.1 x 2 h pruned to 2 h with the boxes now; t4x8:
//       an 8x8 list with each half's own box tested), a register skipped where its mask is
//       empty; the cut-off (and j > i on the diagonal tile) the mask; i's sums in registers
//       across its list, reduced once per i-cluster; j's summed over the tile's registers and
//       added to memory once per tile (t4x4: the two halves folded first). No gathers.
//       Arithmetic: "exact" = the operations of (a) in the same order (correctly rounded
//       vdivpd and vsqrtpd, the same fma's; the mirrored terms with the negated vectors,
//       DWIJ_ji = -DWIJ and VIJ_ji = -VIJ exactly as (a)'s); "rcp" = the divisions and the
//       square root by vrcp14pd / vrsqrt14pd and two Newton steps (not (a)'s roundings).
//
// Results: (a) adds i's terms in list order into one scalar, j's in increasing i; (t) i's in 8
// lane partial sums, j's per tile. The check: per sum, max |X - a| / max |a| <= 1e-12 (the
// sums start from 0, so the pairs' terms are compared; the reassociation of ~19 terms of both
// signs gives ~1e-15; a pair missed or counted twice gives > 1e-3).
//
// Particles: --positions FILE (x y u v rho p per line: a snapshot of the scene, dx = 0.03),
// or the dam break's water column (--nx 33 --ny 66 at dx = 0.03, each coordinate moved by up
// to --pert dx; velocities random up to 1 m/s, the hydrostatic pressure) in the solver's
// order (cells of side 2 h). cs = c0 (rho / rho0)^3 as the scene's equation of state.
//
// Build (the flags of a solver: buildinfo cxxflags): c++ -std=c++17 -O3 -march=native
//   -fno-math-errno -ffp-contract=off -I runtime/include bench/cluster_pairs_2d.cpp
//   runtime/src/cluster_pairs.cpp -o cluster_pairs_2d   (tests/CMakeLists.txt:
//   cluster_pairs_2d_check, ctest bench.cluster_pairs_2d)
// Run: ./cluster_pairs_2d [--positions FILE] [--nx 33 --ny 66] [--pert 0.1] [--reps 7]
//   [--sweeps N] [--forms a,t4x4,t4x4rcp,...] [--dx 0.03] [--hdx 1.3] [--skin 0.1]
// Needs AVX-512F (exits 77 without it).
#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <time.h>

#include "bench_options.h"
#include "bench_tiles.h"
#include "sphc/cluster_pairs.h"
#include "sphc/kernels.h"

namespace {

using namespace bench::tiles;  // cpu_now, median, the vector operations, clock_estimate

constexpr int DIM = 2;
using Kernel = sphc::WendlandQuintic<DIM>;
constexpr double RADIUS2 = Kernel::radius_scale * Kernel::radius_scale;

// ---- The loop bodies: the generated C++ of examples/dambreak.sph with PySPH's effects, verbatim ----
// equation ContinuityEquation, method loop, from wcsph.sph:73: a value the pair shares, the same for the mirrored pair (once per pair
// where each pair is evaluated once; codegen/PairShared.cpp; --pair-shared-values=off: in each call)
static inline double ContinuityEquation_loop_pairshared0(int d_idx, int s_idx, double t, double dt, const double* VIJ, const double* DWIJ, const double* s_m) {
  return std::fma(VIJ[0], DWIJ[0], VIJ[1] * DWIJ[1]);
}

// equation ContinuityEquation, method loop, from wcsph.sph:73: the destination's sums in locals (acc_NAME, accK_NAME: component K;
// codegen/RegisterSums.cpp)
static inline void ContinuityEquation_loop_sums(int d_idx, int s_idx, double t, double dt, const double* VIJ, const double* DWIJ, double& acc_arho, const double* s_m, double pair_shared0) {
    double vijdotdwij = pair_shared0;
    acc_arho = std::fma(s_m[s_idx], vijdotdwij, acc_arho);
  
}

// equation PressureGradient, method loop, from wcsph.sph:158: once per source particle (hoisted out of the pair loop; --no-hoist: per pair)
//   s_p[s_idx] / (rhoj * rhoj)
static inline double PressureGradient_loop_hoisted0(int s_idx, const double* s_p, const double* s_rho) {
  const double rhoj = s_rho[s_idx];
  return s_p[s_idx] / (rhoj * rhoj);
}

// equation PressureGradient, method loop, from wcsph.sph:158: once per destination particle (hoisted out of the pair loop; --no-hoist: per pair)
//   d_p[d_idx] / (rhoi * rhoi)
static inline double PressureGradient_loop_dhoisted0(int d_idx, const double* d_p, const double* d_rho) {
  const double rhoi = d_rho[d_idx];
  return d_p[d_idx] / (rhoi * rhoi);
}

// equation PressureGradient, method loop, from wcsph.sph:158: a value the pair shares, the same for the mirrored pair (once per pair
// where each pair is evaluated once; codegen/PairShared.cpp; --pair-shared-values=off: in each call)
//   d_hoisted0 + s_hoisted0[s_idx]
static inline double PressureGradient_loop_pairshared0(int d_idx, int s_idx, double t, double dt, const double* DWIJ, const double* d_p, const double* d_rho, const double* s_m, const double* s_p, const double* s_rho, const double* s_hoisted0, double d_hoisted0) {
  const double rhoi = d_rho[d_idx];
  const double rhoj = s_rho[s_idx];
  return d_hoisted0 + s_hoisted0[s_idx];
}

// equation PressureGradient, method loop, from wcsph.sph:158: the destination's sums in locals (acc_NAME, accK_NAME: component K;
// codegen/RegisterSums.cpp)
static inline void PressureGradient_loop_sums(int d_idx, int s_idx, double t, double dt, const double* DWIJ, double& acc_au, double& acc_av, const double* d_p, const double* d_rho, const double* s_m, const double* s_p, const double* s_rho, const double* s_hoisted0, double d_hoisted0, double pair_shared0) { double sphc_sink = 0.0; (void)sphc_sink;
    double rhoi = d_rho[d_idx];
    double rhoj = s_rho[s_idx];
    double tmp = pair_shared0;

    double f = -s_m[s_idx] * tmp;
    acc_au = std::fma(f, DWIJ[0], acc_au);
    acc_av = std::fma(f, DWIJ[1], acc_av);
    (void)0;
  
}

static inline double MonaghanArtificialViscosity_loop_pairshared0(int d_idx, int s_idx, double t, double dt, const double* XIJ, const double* VIJ, const double* DWIJ, double R2IJ, double HIJ, double RHOIJ1, double EPS, double alpha, double beta, const double* d_cs, const double* s_cs, const double* s_m) {
  return std::fma(VIJ[0], XIJ[0], VIJ[1] * XIJ[1]);
}

// equation MonaghanArtificialViscosity, method loop, from wcsph.sph:173: a value the pair shares, the same for the mirrored pair (once per pair
// where each pair is evaluated once; codegen/PairShared.cpp; --pair-shared-values=off: in each call)
//   piij after if (vijdotxij < 0.0) { double cij = 0.5 * (d_cs[d_idx] + s_cs[s_idx]); double muij = HI...
static inline double MonaghanArtificialViscosity_loop_pairshared1(int d_idx, int s_idx, double t, double dt, const double* XIJ, const double* VIJ, const double* DWIJ, double R2IJ, double HIJ, double RHOIJ1, double EPS, double alpha, double beta, const double* d_cs, const double* s_cs, const double* s_m) {
  const double vijdotxij = std::fma(VIJ[0], XIJ[0], VIJ[1] * XIJ[1]);
  double piij = 0.0;
  if (vijdotxij < 0.0) {
      double cij = 0.5 * (d_cs[d_idx] + s_cs[s_idx]);
      double muij = HIJ * vijdotxij / (R2IJ + EPS);
      piij = std::fma(-alpha * cij, muij, beta * muij * muij) * RHOIJ1;
    }
  return piij;
}

// equation MonaghanArtificialViscosity, method loop, from wcsph.sph:173: the destination's sums in locals (acc_NAME, accK_NAME: component K;
// codegen/RegisterSums.cpp)
static inline void MonaghanArtificialViscosity_loop_sums(int d_idx, int s_idx, double t, double dt, const double* XIJ, const double* VIJ, const double* DWIJ, double R2IJ, double HIJ, double RHOIJ1, double EPS, double alpha, double beta, double& acc_au, double& acc_av, const double* d_cs, const double* s_cs, const double* s_m, double pair_shared0, double pair_shared1) { double sphc_sink = 0.0; (void)sphc_sink;
    double vijdotxij = pair_shared0;
    double piij = 0.0;
    piij = pair_shared1;





    double f = -s_m[s_idx] * piij;
    acc_au = std::fma(f, DWIJ[0], acc_au);
    acc_av = std::fma(f, DWIJ[1], acc_av);
    (void)0;
  
}

static inline void XSPHCorrection_loop_sums(int d_idx, int s_idx, double t, double dt, const double* VIJ, double WIJ, double RHOIJ1, double eps, double& acc_ax, double& acc_ay, const double* s_m) { double sphc_sink = 0.0; (void)sphc_sink;
    // VIJ = v_a - v_b, hence the minus sign.
    double f = -eps * s_m[s_idx] * RHOIJ1 * WIJ;
    acc_ax = std::fma(f, VIJ[0], acc_ax);
    acc_ay = std::fma(f, VIJ[1], acc_ay);
    (void)0;
  
}

// ---- The own effects' rates add FourtakasDensityDiffusion (`sphc examples/dambreak.sph
// --emit=cpp`, main 9996b02; the other bodies of that loop are the ones above, the same text) ----
static inline void FourtakasDensityDiffusion_initialize(int d_idx, double t, double dt, double B, double* d_bpinv, const double* d_p, const double* d_rho, double* d_rhoeos) {
    double base = 1.0 + d_p[d_idx] / B;
    d_rhoeos[d_idx] = base > 0.0 ? d_rho[d_idx] : 0.0;
    d_bpinv[d_idx] = base > 0.0 ? 1.0 / (B * base) : 0.0;
  
}

static inline double FourtakasDensityDiffusion_loop_hoisted0(int s_idx, const double* s_m, const double* s_rho) {
  return s_m[s_idx] / s_rho[s_idx];
}

// equation FourtakasDensityDiffusion, method loop, from delta_sph.sph:146: a value the pair shares, negated for the mirrored pair (once per pair
// where each pair is evaluated once; codegen/PairShared.cpp; --pair-shared-values=off: in each call)
//   -rho0 * (gx * XIJ[0] + gy * XIJ[1])
static inline double FourtakasDensityDiffusion_loop_pairshared0(int d_idx, int s_idx, double t, double dt, const double* XIJ, const double* DWIJ, double R2IJ, double HIJ, double delta, double c0, double rho0, double gx, double gy, double gz, double B, double invgamma, double s2, const double* d_bpinv, const double* d_p, const double* d_rhoeos, const double* s_m, const double* s_rho, const double* s_hoisted0) {
  return -rho0 * std::fma(gx, XIJ[0], gy * XIJ[1]);
}

// equation FourtakasDensityDiffusion, method loop, from delta_sph.sph:146: a value the pair shares, the same for the mirrored pair (once per pair
// where each pair is evaluated once; codegen/PairShared.cpp; --pair-shared-values=off: in each call)
//   -(XIJ[0] * DWIJ[0] + XIJ[1] * DWIJ[1])
static inline double FourtakasDensityDiffusion_loop_pairshared1(int d_idx, int s_idx, double t, double dt, const double* XIJ, const double* DWIJ, double R2IJ, double HIJ, double delta, double c0, double rho0, double gx, double gy, double gz, double B, double invgamma, double s2, const double* d_bpinv, const double* d_p, const double* d_rhoeos, const double* s_m, const double* s_rho, const double* s_hoisted0) {
  return -std::fma(XIJ[0], DWIJ[0], XIJ[1] * DWIJ[1]);
}

// equation FourtakasDensityDiffusion, method loop, from delta_sph.sph:146: a value the pair shares, the same for the mirrored pair (once per pair
// where each pair is evaluated once; codegen/PairShared.cpp; --pair-shared-values=off: in each call)
//   delta * HIJ * c0 * 2.0
static inline double FourtakasDensityDiffusion_loop_pairshared2(int d_idx, int s_idx, double t, double dt, const double* XIJ, const double* DWIJ, double R2IJ, double HIJ, double delta, double c0, double rho0, double gx, double gy, double gz, double B, double invgamma, double s2, const double* d_bpinv, const double* d_p, const double* d_rhoeos, const double* s_m, const double* s_rho, const double* s_hoisted0) {
  return delta * HIJ * c0 * 2.0;
}

// equation FourtakasDensityDiffusion, method loop, from delta_sph.sph:146: the destination's sums in locals (acc_NAME, accK_NAME: component K;
// codegen/RegisterSums.cpp)
static inline void FourtakasDensityDiffusion_loop_sums(int d_idx, int s_idx, double t, double dt, const double* XIJ, const double* DWIJ, double R2IJ, double HIJ, double delta, double c0, double rho0, double gx, double gy, double gz, double B, double invgamma, double s2, double& acc_arho, const double* d_bpinv, const double* d_p, const double* d_rhoeos, const double* s_m, const double* s_rho, const double* s_hoisted0, double pair_shared0, double pair_shared1, double pair_shared2) {
    if (R2IJ > 0.0) {
      double vb = s_hoisted0[s_idx];
      // x_b - x_a = -XIJ
      double dph = pair_shared0;
      // rho^H_b|a = rho0 (1 + (p_a + dph) / B)^(1/gamma) = rho^EOS_a (1 + x)^(1/gamma),
      // x = dph / (B + p_a): |x| <= rho0 |g| 2h / B, 1.4e-3 in the dam break at dx = 0.03.
      // Below |x| = 0.01 the series to x^2 (error below 0.038 |x|^3 / (1 - |x|)^3 relative:
      // 4e-8 at 0.01, 1e-10 in the dam break); beyond it (never in a weakly compressible
      // run: it needs dph above 1% of B) the power itself.
      double x = dph * d_bpinv[d_idx];
      double rhoh = 0.0;
      if (fabs(x) < 0.01) {
        rhoh = d_rhoeos[d_idx] * std::fma(x, std::fma(s2, x, invgamma), 1.0);
      } else {
        double base = 1.0 + (d_p[d_idx] + dph) / B;
        rhoh = base > 0.0 ? rho0 * pow(base, invgamma) : 0.0;
      }
      double rhoba = s_rho[s_idx] - rhoh;
      double xdotdw = pair_shared1;
      acc_arho = std::fma(pair_shared2 * rhoba * xdotdw / R2IJ, vb, acc_arho);
    }
  
}

// ---- The shifting pass's bodies: the generated C++ of examples/dambreak.sph (its own effects:
// `sphc examples/dambreak.sph --emit=cpp`, main 9996b02), verbatim ----
static inline double KERNEL_W(double r, double h) { return Kernel::w(r, h); }

// equation DeltaPlusShiftingSums, method loop, from shifting_sun2017.sph:191: once per source particle (hoisted out of the pair loop; --no-hoist: per pair)
//   s_m[s_idx] / s_rho[s_idx]
static inline double DeltaPlusShiftingSums_loop_hoisted0(int s_idx, const double* s_m, const double* s_rho) {
  return s_m[s_idx] / s_rho[s_idx];
}

// equation DeltaPlusShiftingSums, method loop, from shifting_sun2017.sph:191: once per destination particle (hoisted out of the pair loop; --no-hoist: per pair)
//   (1.0 / KERNEL_W(1.0 / hdx, 1.0))
static inline double DeltaPlusShiftingSums_loop_dhoisted0(int d_idx, double hdx) {
  (void)d_idx;  // scalars only
  return (1.0 / KERNEL_W(1.0 / hdx, 1.0));
}

// equation DeltaPlusShiftingSums, method loop, from shifting_sun2017.sph:191: a value the pair shares, the same for the mirrored pair (once per pair
// where each pair is evaluated once; codegen/PairShared.cpp; --pair-shared-values=off: in each call)
//   dim == 1 ? HIJ : (dim == 2 ? HIJ * HIJ : HIJ * HIJ * HIJ)
static inline double DeltaPlusShiftingSums_loop_pairshared0(int d_idx, int s_idx, double t, double dt, const double* XIJ, const double* DWIJ, double HIJ, double WIJ, double R, double hdx, double dim, const double* s_m, const double* s_rho, const double* s_hoisted0, double d_hoisted0) {
  return dim == 1 ? HIJ : (dim == 2 ? HIJ * HIJ : HIJ * HIJ * HIJ);
}

// equation DeltaPlusShiftingSums, method loop, from shifting_sun2017.sph:191: a value the pair shares, the same for the mirrored pair (once per pair
// where each pair is evaluated once; codegen/PairShared.cpp; --pair-shared-values=off: in each call)
//   WIJ * hd * d_hoisted0
static inline double DeltaPlusShiftingSums_loop_pairshared1(int d_idx, int s_idx, double t, double dt, const double* XIJ, const double* DWIJ, double HIJ, double WIJ, double R, double hdx, double dim, const double* s_m, const double* s_rho, const double* s_hoisted0, double d_hoisted0) {
  const double hd = dim == 1 ? HIJ : (dim == 2 ? HIJ * HIJ : HIJ * HIJ * HIJ);
  return WIJ * hd * d_hoisted0;
}

// equation DeltaPlusShiftingSums, method loop, from shifting_sun2017.sph:191: a value the pair shares, the same for the mirrored pair (once per pair
// where each pair is evaluated once; codegen/PairShared.cpp; --pair-shared-values=off: in each call)
//   (1.0 + R * wr * wr * wr * wr)
static inline double DeltaPlusShiftingSums_loop_pairshared2(int d_idx, int s_idx, double t, double dt, const double* XIJ, const double* DWIJ, double HIJ, double WIJ, double R, double hdx, double dim, const double* s_m, const double* s_rho, const double* s_hoisted0, double d_hoisted0) {
  const double hd = dim == 1 ? HIJ : (dim == 2 ? HIJ * HIJ : HIJ * HIJ * HIJ);
  const double wr = WIJ * hd * d_hoisted0;
  return std::fma(R * wr * wr * wr, wr, 1.0);
}

// equation DeltaPlusShiftingSums, method loop, from shifting_sun2017.sph:191: the destination's sums in locals (acc_NAME, accK_NAME: component K;
// codegen/RegisterSums.cpp)
static inline void DeltaPlusShiftingSums_loop_sums(int d_idx, int s_idx, double t, double dt, const double* XIJ, const double* DWIJ, double HIJ, double WIJ, double R, double hdx, double dim, double& acc0_binv, double& acc1_binv, double& acc2_binv, double& acc3_binv, double& acc0_gradc, double& acc1_gradc, double& acc0_gradcw, double& acc1_gradcw, const double* s_m, const double* s_rho, const double* s_hoisted0, double d_hoisted0, double pair_shared0, double pair_shared1, double pair_shared2) { double sphc_sink = 0.0; (void)sphc_sink;
    double vb = s_hoisted0[s_idx];
    // W_ab / W(h_ab / hdx, h_ab) = W_ab h_ab^dim / W(1 / hdx, 1), as W(r, h) = sigma h^-dim
    // f(r / h): the divisor a constant of the equation (hoisted out of the pair loop).
    double hd = pair_shared0;
    double wr = pair_shared1;
    double f = vb * pair_shared2;
    acc0_gradcw = std::fma(f, DWIJ[0], acc0_gradcw);
    acc1_gradcw = std::fma(f, DWIJ[1], acc1_gradcw);
    (void)0;
    acc0_gradc = std::fma(vb, DWIJ[0], acc0_gradc);
    acc1_gradc = std::fma(vb, DWIJ[1], acc1_gradc);
    (void)0;
    // x_b - x_a = -XIJ
    acc0_binv = std::fma(-(vb * XIJ[0]), DWIJ[0], acc0_binv);
    acc1_binv = std::fma(-(vb * XIJ[0]), DWIJ[1], acc1_binv);
    (void)0;
    acc2_binv = std::fma(-(vb * XIJ[1]), DWIJ[0], acc2_binv);
    acc3_binv = std::fma(-(vb * XIJ[1]), DWIJ[1], acc3_binv);
    (void)0;
    (void)0;
    (void)0;
    (void)0;
  
}

// equation ShiftingCorrectionGradients, method loop, from shifting.sph:224: a value the pair shares, negated for the mirrored pair (once per pair
// where each pair is evaluated once; codegen/PairShared.cpp; --pair-shared-values=off: in each call)
//   s_rho[s_idx] - d_rho[d_idx]
static inline double ShiftingCorrectionGradients_loop_pairshared0(int d_idx, int s_idx, double t, double dt, const double* VIJ, const double* DWIJ, const double* d_rho, const double* s_m, const double* s_rho, const double* s_hoisted0) {
  return s_rho[s_idx] - d_rho[d_idx];
}

// equation ShiftingCorrectionGradients, method loop, from shifting.sph:224: the destination's sums in locals (acc_NAME, accK_NAME: component K;
// codegen/RegisterSums.cpp)
static inline void ShiftingCorrectionGradients_loop_sums(int d_idx, int s_idx, double t, double dt, const double* VIJ, const double* DWIJ, double& acc0_gradrhos, double& acc1_gradrhos, double& acc0_gradu, double& acc1_gradu, double& acc2_gradu, double& acc3_gradu, const double* d_rho, const double* s_m, const double* s_rho, const double* s_hoisted0, double pair_shared0) { double sphc_sink = 0.0; (void)sphc_sink;
    double vb = s_hoisted0[s_idx];
    double rhoba = pair_shared0;
    acc0_gradrhos = std::fma(vb * rhoba, DWIJ[0], acc0_gradrhos);
    acc1_gradrhos = std::fma(vb * rhoba, DWIJ[1], acc1_gradrhos);
    (void)0;
    // VIJ = u_a - u_b
    acc0_gradu = std::fma(-(vb * VIJ[0]), DWIJ[0], acc0_gradu);
    acc1_gradu = std::fma(-(vb * VIJ[0]), DWIJ[1], acc1_gradu);
    (void)0;
    acc2_gradu = std::fma(-(vb * VIJ[1]), DWIJ[0], acc2_gradu);
    acc3_gradu = std::fma(-(vb * VIJ[1]), DWIJ[1], acc3_gradu);
    (void)0;
    (void)0;
    (void)0;
    (void)0;
  
}
// ---- end of the generated bodies ----

struct Eq6 {
  double alpha = 0.1;
  static constexpr double beta = (0.0);
};
struct Eq7 {
  static constexpr double eps = (0.5);
};
struct Eq8 {  // FourtakasDensityDiffusion(dest = fluid): the scene's values (dambreak.sph)
  double delta = 0.1, c0 = 10.0 * std::sqrt(2.0 * 9.81 * 2.0), rho0 = 1000.0;
  static constexpr double gamma = (7.0);
  static constexpr double gx = (0.0);
  double gy = -9.81;
  static constexpr double gz = (0.0);
  double B = rho0 * c0 * c0 / gamma, invgamma = 1.0 / gamma, s2 = (0.5 / gamma) * ((1.0 / gamma) - 1.0);
};
struct Eq11 {  // DeltaPlusShiftingSums(dest = fluid): the scene's values
  static constexpr double R = (0.2);
  double hdx = 1.3;
  static constexpr double dim = (2.0);
};

// The water in particle order: positions, the properties the pass reads, its 5 sums.
struct Fluid {
  int n = 0;
  std::vector<double> x, y, u, v, h, rho, m, p, cs, hoisted;
  std::vector<double> arho, au, av, ax, ay;
  // The shifting pass: m / rho (hoisted), the destination-only value per particle, its sums
  // (components interleaved as the solver stores them: binv 4, gradc 2, gradcw 2, gradrhos 2,
  // gradu 4 per particle).
  std::vector<double> vb, dh;
  // The own effects' rates: FourtakasDensityDiffusion's per-particle values (its initialize).
  std::vector<double> rhoeos, bpinv;
  std::vector<double> binv, gradc, gradcw, gradrhos, gradu;
  void zero_sums() {
    for (auto* s : {&arho, &au, &av, &ax, &ay}) s->assign(n, 0.0);
    binv.assign(4 * n, 0.0), gradc.assign(2 * n, 0.0), gradcw.assign(2 * n, 0.0);
    gradrhos.assign(2 * n, 0.0), gradu.assign(4 * n, 0.0);
  }
};

// The kept lists as the solver keeps them (sphc/verlet.h): per destination its candidates
// within VERLET_RADIUS2 hmax^2, in index order; upper: where s_idx >= d_idx starts.
struct Kept {
  std::vector<std::vector<std::uint32_t>> lists;
  std::vector<std::uint32_t> upper;
};

Kept build_kept(const Fluid& f, double skin) {
  const double VERLET_RADIUS2 = RADIUS2 * (1.0 + skin) * (1.0 + skin);
  Kept k;
  k.lists.resize(f.n);
  k.upper.resize(f.n);
  double hmax = 0, lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
  for (int i = 0; i < f.n; ++i) {
    hmax = std::max(hmax, f.h[i]);
    lo[0] = std::min(lo[0], f.x[i]), hi[0] = std::max(hi[0], f.x[i]);
    lo[1] = std::min(lo[1], f.y[i]), hi[1] = std::max(hi[1], f.y[i]);
  }
  const double cell = std::sqrt(VERLET_RADIUS2) * hmax;
  const int nc[2] = {static_cast<int>((hi[0] - lo[0]) / cell) + 1, static_cast<int>((hi[1] - lo[1]) / cell) + 1};
  std::vector<std::vector<int>> cells(static_cast<std::size_t>(nc[0]) * nc[1]);
  auto cx = [&](int i) { return std::min(nc[0] - 1, static_cast<int>((f.x[i] - lo[0]) / cell)); };
  auto cy = [&](int i) { return std::min(nc[1] - 1, static_cast<int>((f.y[i] - lo[1]) / cell)); };
  for (int i = 0; i < f.n; ++i) cells[cy(i) * nc[0] + cx(i)].push_back(i);
  for (int i = 0; i < f.n; ++i) {
    std::vector<std::uint32_t>& l = k.lists[i];
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int qx = cx(i) + dx, qy = cy(i) + dy;
        if (qx < 0 || qy < 0 || qx >= nc[0] || qy >= nc[1]) continue;
        for (int j : cells[qy * nc[0] + qx]) {
          const double XIJ[2] = {f.x[i] - f.x[j], f.y[i] - f.y[j]};
          const double R2IJ = XIJ[0] * XIJ[0] + XIJ[1] * XIJ[1];
          const double hm = std::max(f.h[i], f.h[j]);
          if (R2IJ >= VERLET_RADIUS2 * hm * hm) continue;
          l.push_back(static_cast<std::uint32_t>(j));
        }
      }
    std::sort(l.begin(), l.end());
    k.upper[i] = static_cast<std::uint32_t>(std::lower_bound(l.begin(), l.end(), static_cast<std::uint32_t>(i)) - l.begin());
  }
  return k;
}

// ---- Form (a): the generated each-pair-once loop, verbatim (the pass's fluid <- fluid loop);
// OWN: the own effects' loop, the same with FourtakasDensityDiffusion's lines (`if constexpr`) ----
template <bool OWN = false>
__attribute__((noinline)) void form_a(Fluid& fluid, const Kept& verlet_fluid_fluid, const Eq6& eq6, const Eq7& eq7,
                                      std::vector<double>& dhoist_eq4_0, const Eq8& eq8 = Eq8()) {
  const double t = 0.0, dt = 0.0;
  const int n = fluid.n;
  const double* di_x = fluid.x.data();
  const double* di_y = fluid.y.data();
  const double* di_h = fluid.h.data();
  const double* di_u = fluid.u.data();
  const double* di_v = fluid.v.data();
  const double* di_rho = fluid.rho.data();
  const double* sj_x = di_x;
  const double* sj_y = di_y;
  const double* sj_h = di_h;
  const double* sj_u = di_u;
  const double* sj_v = di_v;
  const double* sj_rho = di_rho;
  const double* d_cs = fluid.cs.data();
  const double* d_p = fluid.p.data();
  const double* d_rho = di_rho;
  const double* s_cs = d_cs;
  const double* s_m = fluid.m.data();
  const double* s_p = d_p;
  const double* s_rho = di_rho;
  double* d_arho = fluid.arho.data();
  double* d_au = fluid.au.data();
  double* d_av = fluid.av.data();
  double* d_ax = fluid.ax.data();
  double* d_ay = fluid.ay.data();
  const double* hoisted_eq4_0 = fluid.hoisted.data();
  const double* hoisted_eq8_0 = fluid.vb.data();  // FourtakasDensityDiffusion: s_m[s_idx] / s_rho[s_idx]
  const double* d_bpinv = fluid.bpinv.data();
  const double* d_rhoeos = fluid.rhoeos.data();
        dhoist_eq4_0.resize(n);
        double* const dhoisted_all_eq4_0 = dhoist_eq4_0.data();
        for (int d_idx = 0; d_idx < n; ++d_idx) {
          const double dhoisted_eq4_0 = PressureGradient_loop_dhoisted0(d_idx, d_p, d_rho);  // PressureGradient: d_p[d_idx] / (rhoi * rhoi)
          dhoisted_all_eq4_0[d_idx] = dhoisted_eq4_0;
        }
        for (int d_idx = 0; d_idx < n; ++d_idx) {  // pairs (d_idx, s_idx > d_idx)
          const double xi = di_x[d_idx];
          const double yi = di_y[d_idx];
          const double zi = 0.0;
          const double hi = di_h[d_idx];
          const double ui = di_u[d_idx];
          const double vi = di_v[d_idx];
          const double dhoisted_eq4_0 = dhoisted_all_eq4_0[d_idx];
          const std::vector<std::uint32_t>& kept = verlet_fluid_fluid.lists[d_idx];
          const std::uint32_t* const k_end = kept.data() + kept.size();
          const std::uint32_t* k_first = kept.data() + verlet_fluid_fluid.upper[d_idx];
          if (k_first != k_end && *k_first == static_cast<std::uint32_t>(d_idx)) ++k_first;  // the self pair: every body adds zeros there (sphc
          // --no-self-pair-skip: evaluated; body/SelfPair.cpp)
          // The destination's sums in locals across its neighbours (codegen/RegisterSums.cpp;
          // sphc --no-register-sums: in memory at every pair): arho, au, av, ax, ay.
          double acc_arho = d_arho[d_idx];
          double acc_au = d_au[d_idx];
          double acc_av = d_av[d_idx];
          double acc_ax = d_ax[d_idx];
          double acc_ay = d_ay[d_idx];
          for (const std::uint32_t* k = k_first; k != k_end; ++k) {
            const int s_idx = static_cast<int>(*k);
            const double hj = sj_h[s_idx];
            const double XIJ[3] = {xi - sj_x[s_idx], yi - sj_y[s_idx], 0.0};
            const double R2IJ = XIJ[0] * XIJ[0] + XIJ[1] * XIJ[1];
            const double hmax = hi > hj ? hi : hj;
            if (R2IJ >= RADIUS2 * hmax * hmax) continue;  // not a neighbour
            const double XIJ_ji[3] = {sj_x[s_idx] - xi, sj_y[s_idx] - yi, 0.0};
            const double HIJ = 0.5 * (hi + hj);
            const double RIJ = std::sqrt(R2IJ);
            const double VIJ[3] = {ui - sj_u[s_idx], vi - sj_v[s_idx], 0.0};
            const double VIJ_ji[3] = {sj_u[s_idx] - ui, sj_v[s_idx] - vi, 0.0};
            const double WIJ = Kernel::w(RIJ, HIJ);
            double DWIJ[3], DWIJ_ji[3];
            Kernel::gradient_pair(XIJ, XIJ_ji, RIJ, HIJ, DWIJ, DWIJ_ji);
            const double RHOIJ = 0.5 * (di_rho[d_idx] + sj_rho[s_idx]);
            const double RHOIJ1 = 1.0 / RHOIJ;
            const double EPS = 0.01 * HIJ * HIJ;
            const double pshared_eq2_0 = ContinuityEquation_loop_pairshared0(d_idx, s_idx, t, dt, VIJ, DWIJ, s_m);  // ContinuityEquation: the same for (s_idx, d_idx)
            const double pshared_eq4_0 = PressureGradient_loop_pairshared0(d_idx, s_idx, t, dt, DWIJ, d_p, d_rho, s_m, s_p, s_rho, hoisted_eq4_0, dhoisted_eq4_0);  // PressureGradient: the same for (s_idx, d_idx)
            const double pshared_eq6_0 = MonaghanArtificialViscosity_loop_pairshared0(d_idx, s_idx, t, dt, XIJ, VIJ, DWIJ, R2IJ, HIJ, RHOIJ1, EPS, eq6.alpha, eq6.beta, d_cs, s_cs, s_m);  // MonaghanArtificialViscosity: the same for (s_idx, d_idx)
            const double pshared_eq6_1 = MonaghanArtificialViscosity_loop_pairshared1(d_idx, s_idx, t, dt, XIJ, VIJ, DWIJ, R2IJ, HIJ, RHOIJ1, EPS, eq6.alpha, eq6.beta, d_cs, s_cs, s_m);  // MonaghanArtificialViscosity: the same for (s_idx, d_idx)
            double pshared_eq8_0 = 0, pshared_eq8_1 = 0, pshared_eq8_2 = 0;
            if constexpr (OWN) {
            pshared_eq8_0 = FourtakasDensityDiffusion_loop_pairshared0(d_idx, s_idx, t, dt, XIJ, DWIJ, R2IJ, HIJ, eq8.delta, eq8.c0, eq8.rho0, eq8.gx, eq8.gy, eq8.gz, eq8.B, eq8.invgamma, eq8.s2, d_bpinv, d_p, d_rhoeos, s_m, s_rho, hoisted_eq8_0);  // FourtakasDensityDiffusion: minus this for (s_idx, d_idx)
            pshared_eq8_1 = FourtakasDensityDiffusion_loop_pairshared1(d_idx, s_idx, t, dt, XIJ, DWIJ, R2IJ, HIJ, eq8.delta, eq8.c0, eq8.rho0, eq8.gx, eq8.gy, eq8.gz, eq8.B, eq8.invgamma, eq8.s2, d_bpinv, d_p, d_rhoeos, s_m, s_rho, hoisted_eq8_0);  // FourtakasDensityDiffusion: the same for (s_idx, d_idx)
            pshared_eq8_2 = FourtakasDensityDiffusion_loop_pairshared2(d_idx, s_idx, t, dt, XIJ, DWIJ, R2IJ, HIJ, eq8.delta, eq8.c0, eq8.rho0, eq8.gx, eq8.gy, eq8.gz, eq8.B, eq8.invgamma, eq8.s2, d_bpinv, d_p, d_rhoeos, s_m, s_rho, hoisted_eq8_0);  // FourtakasDensityDiffusion: the same for (s_idx, d_idx)
            }
            ContinuityEquation_loop_sums(d_idx, s_idx, t, dt, VIJ, DWIJ, acc_arho, s_m, pshared_eq2_0);  // ContinuityEquation, from wcsph_scheme.sph:140
            PressureGradient_loop_sums(d_idx, s_idx, t, dt, DWIJ, acc_au, acc_av, d_p, d_rho, s_m, s_p, s_rho, hoisted_eq4_0, dhoisted_eq4_0, pshared_eq4_0);  // PressureGradient, from wcsph_scheme.sph:142
            MonaghanArtificialViscosity_loop_sums(d_idx, s_idx, t, dt, XIJ, VIJ, DWIJ, R2IJ, HIJ, RHOIJ1, EPS, eq6.alpha, eq6.beta, acc_au, acc_av, d_cs, s_cs, s_m, pshared_eq6_0, pshared_eq6_1);  // MonaghanArtificialViscosity, from wcsph_scheme.sph:147
            XSPHCorrection_loop_sums(d_idx, s_idx, t, dt, VIJ, WIJ, RHOIJ1, eq7.eps, acc_ax, acc_ay, s_m);  // XSPHCorrection, from wcsph_scheme.sph:160
            if constexpr (OWN)
            FourtakasDensityDiffusion_loop_sums(d_idx, s_idx, t, dt, XIJ, DWIJ, R2IJ, HIJ, eq8.delta, eq8.c0, eq8.rho0, eq8.gx, eq8.gy, eq8.gz, eq8.B, eq8.invgamma, eq8.s2, acc_arho, d_bpinv, d_p, d_rhoeos, s_m, s_rho, hoisted_eq8_0, pshared_eq8_0, pshared_eq8_1, pshared_eq8_2);  // FourtakasDensityDiffusion, from wcsph_scheme.sph:176
            // the same pair for particle s_idx
            // s_idx's sums in locals for its calls (codegen/SymmetricPairs.cpp)
            double m_acc_arho = d_arho[s_idx];
            double m_acc_au = d_au[s_idx];
            double m_acc_av = d_av[s_idx];
            double m_acc_ax = d_ax[s_idx];
            double m_acc_ay = d_ay[s_idx];
            ContinuityEquation_loop_sums(s_idx, d_idx, t, dt, VIJ_ji, DWIJ_ji, m_acc_arho, s_m, pshared_eq2_0);  // ContinuityEquation, from wcsph_scheme.sph:140: destination s_idx, source d_idx
            PressureGradient_loop_sums(s_idx, d_idx, t, dt, DWIJ_ji, m_acc_au, m_acc_av, d_p, d_rho, s_m, s_p, s_rho, hoisted_eq4_0, dhoisted_all_eq4_0[s_idx], pshared_eq4_0);  // PressureGradient, from wcsph_scheme.sph:142: destination s_idx, source d_idx
            MonaghanArtificialViscosity_loop_sums(s_idx, d_idx, t, dt, XIJ_ji, VIJ_ji, DWIJ_ji, R2IJ, HIJ, RHOIJ1, EPS, eq6.alpha, eq6.beta, m_acc_au, m_acc_av, d_cs, s_cs, s_m, pshared_eq6_0, pshared_eq6_1);  // MonaghanArtificialViscosity, from wcsph_scheme.sph:147: destination s_idx, source d_idx
            XSPHCorrection_loop_sums(s_idx, d_idx, t, dt, VIJ_ji, WIJ, RHOIJ1, eq7.eps, m_acc_ax, m_acc_ay, s_m);  // XSPHCorrection, from wcsph_scheme.sph:160: destination s_idx, source d_idx
            if constexpr (OWN)
            FourtakasDensityDiffusion_loop_sums(s_idx, d_idx, t, dt, XIJ_ji, DWIJ_ji, R2IJ, HIJ, eq8.delta, eq8.c0, eq8.rho0, eq8.gx, eq8.gy, eq8.gz, eq8.B, eq8.invgamma, eq8.s2, m_acc_arho, d_bpinv, d_p, d_rhoeos, s_m, s_rho, hoisted_eq8_0, -pshared_eq8_0, pshared_eq8_1, pshared_eq8_2);  // FourtakasDensityDiffusion, from wcsph_scheme.sph:176: destination s_idx, source d_idx
            d_arho[s_idx] = m_acc_arho;
            d_au[s_idx] = m_acc_au;
            d_av[s_idx] = m_acc_av;
            d_ax[s_idx] = m_acc_ax;
            d_ay[s_idx] = m_acc_ay;
          }
          d_arho[d_idx] = acc_arho;
          d_au[d_idx] = acc_au;
          d_av[d_idx] = acc_av;
          d_ax[d_idx] = acc_ax;
          d_ay[d_idx] = acc_ay;
        }
}

// ---- Form (a) of the shifting pass: the generated each-pair-once loop, verbatim ----
__attribute__((noinline)) void form_a_shift(Fluid& fluid, const Kept& verlet_fluid_fluid, const Eq11& eq11,
                                            std::vector<double>& dhoist_eq11_0) {
  const double t = 0.0, dt = 0.0;
  const int n = fluid.n;
  const double* di_x = fluid.x.data();
  const double* di_y = fluid.y.data();
  const double* di_h = fluid.h.data();
  const double* di_u = fluid.u.data();
  const double* di_v = fluid.v.data();
  const double* sj_x = di_x;
  const double* sj_y = di_y;
  const double* sj_h = di_h;
  const double* sj_u = di_u;
  const double* sj_v = di_v;
  const double* d_rho = fluid.rho.data();
  const double* s_m = fluid.m.data();
  const double* s_rho = d_rho;
  double* d_binv = fluid.binv.data();
  double* d_gradc = fluid.gradc.data();
  double* d_gradcw = fluid.gradcw.data();
  double* d_gradrhos = fluid.gradrhos.data();
  double* d_gradu = fluid.gradu.data();
  const double* hoisted_eq11_0 = fluid.vb.data();
  const double* hoisted_eq12_0 = hoisted_eq11_0;  // ShiftingCorrectionGradients: s_m[s_idx] / s_rho[s_idx], computed above
        const double pass_dhoisted_eq11_0 = DeltaPlusShiftingSums_loop_dhoisted0(0, eq11.hdx);  // DeltaPlusShiftingSums: (1.0 / KERNEL_W(1.0 / hdx, 1.0)), of the parameters only: once per pass
        dhoist_eq11_0.resize(n);
        double* const dhoisted_all_eq11_0 = dhoist_eq11_0.data();
        for (int d_idx = 0; d_idx < n; ++d_idx) {
          const double dhoisted_eq11_0 = pass_dhoisted_eq11_0;  // DeltaPlusShiftingSums: once per pass
          dhoisted_all_eq11_0[d_idx] = dhoisted_eq11_0;
        }
        for (int d_idx = 0; d_idx < n; ++d_idx) {  // pairs (d_idx, s_idx > d_idx)
          const double xi = di_x[d_idx];
          const double yi = di_y[d_idx];
          const double zi = 0.0;
          const double hi = di_h[d_idx];
          const double ui = di_u[d_idx];
          const double vi = di_v[d_idx];
          const double dhoisted_eq11_0 = dhoisted_all_eq11_0[d_idx];
          const std::vector<std::uint32_t>& kept = verlet_fluid_fluid.lists[d_idx];
          const std::uint32_t* const k_end = kept.data() + kept.size();
          const std::uint32_t* k_first = kept.data() + verlet_fluid_fluid.upper[d_idx];
          if (k_first != k_end && *k_first == static_cast<std::uint32_t>(d_idx)) ++k_first;  // the self pair: every body adds zeros there (sphc
          // --no-self-pair-skip: evaluated; body/SelfPair.cpp)
          // The destination's sums in locals across its neighbours (codegen/RegisterSums.cpp;
          // sphc --no-register-sums: in memory at every pair): binv, gradc, gradcw, gradrhos, gradu.
          double acc0_binv = d_binv[4 * d_idx + 0];
          double acc1_binv = d_binv[4 * d_idx + 1];
          double acc2_binv = d_binv[4 * d_idx + 2];
          double acc3_binv = d_binv[4 * d_idx + 3];
          double acc0_gradc = d_gradc[2 * d_idx + 0];
          double acc1_gradc = d_gradc[2 * d_idx + 1];
          double acc0_gradcw = d_gradcw[2 * d_idx + 0];
          double acc1_gradcw = d_gradcw[2 * d_idx + 1];
          double acc0_gradrhos = d_gradrhos[2 * d_idx + 0];
          double acc1_gradrhos = d_gradrhos[2 * d_idx + 1];
          double acc0_gradu = d_gradu[4 * d_idx + 0];
          double acc1_gradu = d_gradu[4 * d_idx + 1];
          double acc2_gradu = d_gradu[4 * d_idx + 2];
          double acc3_gradu = d_gradu[4 * d_idx + 3];
          for (const std::uint32_t* k = k_first; k != k_end; ++k) {
            const int s_idx = static_cast<int>(*k);
            const double hj = sj_h[s_idx];
            const double XIJ[3] = {xi - sj_x[s_idx], yi - sj_y[s_idx], 0.0};
            const double R2IJ = XIJ[0] * XIJ[0] + XIJ[1] * XIJ[1];
            const double hmax = hi > hj ? hi : hj;
            if (R2IJ >= RADIUS2 * hmax * hmax) continue;  // not a neighbour
            const double XIJ_ji[3] = {sj_x[s_idx] - xi, sj_y[s_idx] - yi, 0.0};
            const double HIJ = 0.5 * (hi + hj);
            const double RIJ = std::sqrt(R2IJ);
            const double VIJ[3] = {ui - sj_u[s_idx], vi - sj_v[s_idx], 0.0};
            const double VIJ_ji[3] = {sj_u[s_idx] - ui, sj_v[s_idx] - vi, 0.0};
            const double WIJ = Kernel::w(RIJ, HIJ);
            double DWIJ[3], DWIJ_ji[3];
            Kernel::gradient_pair(XIJ, XIJ_ji, RIJ, HIJ, DWIJ, DWIJ_ji);
            const double pshared_eq11_0 = DeltaPlusShiftingSums_loop_pairshared0(d_idx, s_idx, t, dt, XIJ, DWIJ, HIJ, WIJ, eq11.R, eq11.hdx, eq11.dim, s_m, s_rho, hoisted_eq11_0, dhoisted_eq11_0);  // DeltaPlusShiftingSums: the same for (s_idx, d_idx)
            const double pshared_eq11_1 = DeltaPlusShiftingSums_loop_pairshared1(d_idx, s_idx, t, dt, XIJ, DWIJ, HIJ, WIJ, eq11.R, eq11.hdx, eq11.dim, s_m, s_rho, hoisted_eq11_0, dhoisted_eq11_0);  // DeltaPlusShiftingSums: the same for (s_idx, d_idx)
            const double pshared_eq11_2 = DeltaPlusShiftingSums_loop_pairshared2(d_idx, s_idx, t, dt, XIJ, DWIJ, HIJ, WIJ, eq11.R, eq11.hdx, eq11.dim, s_m, s_rho, hoisted_eq11_0, dhoisted_eq11_0);  // DeltaPlusShiftingSums: the same for (s_idx, d_idx)
            const double pshared_eq12_0 = ShiftingCorrectionGradients_loop_pairshared0(d_idx, s_idx, t, dt, VIJ, DWIJ, d_rho, s_m, s_rho, hoisted_eq12_0);  // ShiftingCorrectionGradients: minus this for (s_idx, d_idx)
            DeltaPlusShiftingSums_loop_sums(d_idx, s_idx, t, dt, XIJ, DWIJ, HIJ, WIJ, eq11.R, eq11.hdx, eq11.dim, acc0_binv, acc1_binv, acc2_binv, acc3_binv, acc0_gradc, acc1_gradc, acc0_gradcw, acc1_gradcw, s_m, s_rho, hoisted_eq11_0, dhoisted_eq11_0, pshared_eq11_0, pshared_eq11_1, pshared_eq11_2);  // DeltaPlusShiftingSums, from wcsph_scheme.sph:211
            ShiftingCorrectionGradients_loop_sums(d_idx, s_idx, t, dt, VIJ, DWIJ, acc0_gradrhos, acc1_gradrhos, acc0_gradu, acc1_gradu, acc2_gradu, acc3_gradu, d_rho, s_m, s_rho, hoisted_eq12_0, pshared_eq12_0);  // ShiftingCorrectionGradients, from wcsph_scheme.sph:214
            // the same pair for particle s_idx
            // s_idx's sums in locals for its calls (codegen/SymmetricPairs.cpp)
            double m_acc0_binv = d_binv[4 * s_idx + 0];
            double m_acc1_binv = d_binv[4 * s_idx + 1];
            double m_acc2_binv = d_binv[4 * s_idx + 2];
            double m_acc3_binv = d_binv[4 * s_idx + 3];
            double m_acc0_gradc = d_gradc[2 * s_idx + 0];
            double m_acc1_gradc = d_gradc[2 * s_idx + 1];
            double m_acc0_gradcw = d_gradcw[2 * s_idx + 0];
            double m_acc1_gradcw = d_gradcw[2 * s_idx + 1];
            double m_acc0_gradrhos = d_gradrhos[2 * s_idx + 0];
            double m_acc1_gradrhos = d_gradrhos[2 * s_idx + 1];
            double m_acc0_gradu = d_gradu[4 * s_idx + 0];
            double m_acc1_gradu = d_gradu[4 * s_idx + 1];
            double m_acc2_gradu = d_gradu[4 * s_idx + 2];
            double m_acc3_gradu = d_gradu[4 * s_idx + 3];
            DeltaPlusShiftingSums_loop_sums(s_idx, d_idx, t, dt, XIJ_ji, DWIJ_ji, HIJ, WIJ, eq11.R, eq11.hdx, eq11.dim, m_acc0_binv, m_acc1_binv, m_acc2_binv, m_acc3_binv, m_acc0_gradc, m_acc1_gradc, m_acc0_gradcw, m_acc1_gradcw, s_m, s_rho, hoisted_eq11_0, dhoisted_all_eq11_0[s_idx], pshared_eq11_0, pshared_eq11_1, pshared_eq11_2);  // DeltaPlusShiftingSums, from wcsph_scheme.sph:211: destination s_idx, source d_idx
            ShiftingCorrectionGradients_loop_sums(s_idx, d_idx, t, dt, VIJ_ji, DWIJ_ji, m_acc0_gradrhos, m_acc1_gradrhos, m_acc0_gradu, m_acc1_gradu, m_acc2_gradu, m_acc3_gradu, d_rho, s_m, s_rho, hoisted_eq12_0, -pshared_eq12_0);  // ShiftingCorrectionGradients, from wcsph_scheme.sph:214: destination s_idx, source d_idx
            d_binv[4 * s_idx + 0] = m_acc0_binv;
            d_binv[4 * s_idx + 1] = m_acc1_binv;
            d_binv[4 * s_idx + 2] = m_acc2_binv;
            d_binv[4 * s_idx + 3] = m_acc3_binv;
            d_gradc[2 * s_idx + 0] = m_acc0_gradc;
            d_gradc[2 * s_idx + 1] = m_acc1_gradc;
            d_gradcw[2 * s_idx + 0] = m_acc0_gradcw;
            d_gradcw[2 * s_idx + 1] = m_acc1_gradcw;
            d_gradrhos[2 * s_idx + 0] = m_acc0_gradrhos;
            d_gradrhos[2 * s_idx + 1] = m_acc1_gradrhos;
            d_gradu[4 * s_idx + 0] = m_acc0_gradu;
            d_gradu[4 * s_idx + 1] = m_acc1_gradu;
            d_gradu[4 * s_idx + 2] = m_acc2_gradu;
            d_gradu[4 * s_idx + 3] = m_acc3_gradu;
          }
          d_binv[4 * d_idx + 0] = acc0_binv;
          d_binv[4 * d_idx + 1] = acc1_binv;
          d_binv[4 * d_idx + 2] = acc2_binv;
          d_binv[4 * d_idx + 3] = acc3_binv;
          d_gradc[2 * d_idx + 0] = acc0_gradc;
          d_gradc[2 * d_idx + 1] = acc1_gradc;
          d_gradcw[2 * d_idx + 0] = acc0_gradcw;
          d_gradcw[2 * d_idx + 1] = acc1_gradcw;
          d_gradrhos[2 * d_idx + 0] = acc0_gradrhos;
          d_gradrhos[2 * d_idx + 1] = acc1_gradrhos;
          d_gradu[4 * d_idx + 0] = acc0_gradu;
          d_gradu[4 * d_idx + 1] = acc1_gradu;
          d_gradu[4 * d_idx + 2] = acc2_gradu;
          d_gradu[4 * d_idx + 3] = acc3_gradu;
        }
}

#ifdef __AVX512F__
// ---- The tiles ----
enum Arith { EXACT = 0, RCP = 1 };
// The fields the tiles read: x y u v h rho m cs hoisted (p / rho^2) for the rates; x y u v h
// rho vb (m / rho) dh for the shifting pass.
// The own effects' rates add vb (m / rho), rhoeos, bpinv and p (the density diffusion's).
enum Field { FX, FY, FU, FV, FH, FRHO, FM, FCS, FHO, FVB, FDH, FREOS, FBPI, FP, NF };
constexpr int RATES_FIELDS[] = {FX, FY, FU, FV, FH, FRHO, FM, FCS, FHO};
constexpr int SHIFT_FIELDS[] = {FX, FY, FU, FV, FH, FRHO, FVB, FDH};
constexpr int OWN_FIELDS[] = {FX, FY, FU, FV, FH, FRHO, FM, FCS, FHO, FVB, FREOS, FBPI, FP};
constexpr int NS = 5;    // the rates' sums: arho au av ax ay
constexpr int NSS = 14;  // the shifting's: binv 0-3, gradc 4-5, gradcw 6-7, gradrhos 8-9, gradu 10-13

// One layout's slot-order copies (the per-evaluation gathers) and slot sums.
struct Slots {
  sphc::ClusterLayout L;
  sphc::ClusterPairList outer, pruned;
  std::vector<double> f[NF], s[NS], ss[NSS];
};

// i values of one register: RI = 1: particle i in every lane; RI = 2: i0 in lanes 0-3, i1 in 4-7.
template <int RI>
inline V ival(const double* F, int i) {
  if (RI == 1) return bc(F[i]);
  return _mm512_insertf64x4(bc(F[i]), _mm256_set1_pd(F[i + 1]), 1);
}
// j values: CJ = 8: the cluster; CJ = 4: the 4 j's in both halves.
template <int CJ>
inline V jval(const double* F, int j0) {
  if (CJ == 8) return _mm512_loadu_pd(F + j0);
  return _mm512_broadcast_f64x4(_mm256_loadu_pd(F + j0));
}

// The cut-off of a register (RI i's from slot i x the j-cluster at j0): !(R2IJ >= RADIUS2 *
// hmax^2), and j > i on a diagonal tile (lane l: i = i + l / CJ, j = j0 + l % CJ).
template <int RI, int CJ>
__attribute__((always_inline)) inline M register_mask(V R2IJ, V hi, V hj, bool diagonal, int i, int j0) {
  const __m512i lane_i = RI == 1 ? _mm512_setzero_si512() : _mm512_set_epi64(1, 1, 1, 1, 0, 0, 0, 0);
  const __m512i lane_j = CJ == 8 ? _mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0) : _mm512_set_epi64(3, 2, 1, 0, 3, 2, 1, 0);
  const V hmax = _mm512_max_pd(hi, hj);
  M in = _mm512_cmp_pd_mask(R2IJ, mul(mul(bc(RADIUS2), hmax), hmax), _CMP_NGE_UQ);
  if (diagonal)
    in &= _mm512_cmpgt_epi64_mask(_mm512_add_epi64(lane_j, _mm512_set1_epi64(j0)),
                                  _mm512_add_epi64(lane_i, _mm512_set1_epi64(i)));
  return in;
}

// Kernel::w and gradient_pair (sphc/kernels.h: WendlandQuintic 2D, sigma / h^2 f(q)) of a
// register: WIJ and the gradient's factor DWIJ_f (DWIJ = DWIJ_f XIJ; 0 for coincident
// particles). EXACT: (a)'s correctly rounded divisions and square root; RCP: rcp / rsqrt.
template <int ARITH>
__attribute__((always_inline)) inline void wendland_register(V R2IJ, V HIJ, V& WIJ, V& DWIJ_f) {
  const V one = bc(1.0), half = bc(0.5), two = bc(2.0), zero = _mm512_setzero_pd();
  V RIJ, ih, q, s_den_inv = zero;
  if (ARITH == EXACT) {
    RIJ = _mm512_sqrt_pd(R2IJ);
    ih = div(one, HIJ);
    q = div(RIJ, HIJ);
  } else {
    const V rinv = rsqrt(R2IJ);
    RIJ = sel(_mm512_cmp_pd_mask(R2IJ, zero, _CMP_GT_OQ), mul(R2IJ, rinv), zero);
    ih = rcp(HIJ);
    q = mul(RIJ, ih);
    s_den_inv = mul(ih, rinv);  // 1 / (h rij)
  }
  const V sk = mul(bc(Kernel::sigma), mul(ih, ih));
  const M inside = _mm512_cmp_pd_mask(q, two, _CMP_LT_OQ);  // f, df: 0 where q >= 2
  const V t = sub(one, mul(half, q));
  const V t2 = mul(t, t);
  const V fq = mul(mul(t2, t2), add(mul(two, q), one));
  const V dfq = mul(mul(mul(mul(bc(-5.0), q), t), t), t);
  WIJ = mul(sk, sel(inside, fq, zero));
  const V dwdq = mul(sk, sel(inside, dfq, zero));
  const M apart = _mm512_cmp_pd_mask(RIJ, bc(1e-12), _CMP_GT_OQ);
  const V s = ARITH == EXACT ? div(dwdq, mul(HIJ, sel(apart, RIJ, one))) : mul(dwdq, s_den_inv);
  DWIJ_f = sel(apart, s, zero);
}

// A tile's j sums added to memory once: CJ = 8, a load-add-store per sum; CJ = 4, the two
// halves (i's of the register) folded, then added to the 4 j's.
template <int CJ>
__attribute__((always_inline)) inline void add_j_sums(double* const* SUM, int nsums, const V* jacc, int j0) {
  if (CJ == 8) {
    for (int k = 0; k < nsums; ++k) _mm512_storeu_pd(SUM[k] + j0, add(_mm512_loadu_pd(SUM[k] + j0), jacc[k]));
  } else {
    for (int k = 0; k < nsums; ++k) {
      const __m256d lo = _mm512_castpd512_pd256(jacc[k]), hi = _mm512_extractf64x4_pd(jacc[k], 1);
      _mm256_storeu_pd(SUM[k] + j0, _mm256_add_pd(_mm256_loadu_pd(SUM[k] + j0), _mm256_add_pd(lo, hi)));
    }
  }
}

// A register's i sums (lane partial sums across its list) reduced and added to slot i (RI = 2:
// lanes 0-3 to i, 4-7 to i + 1).
template <int RI>
__attribute__((always_inline)) inline void add_i_sums(double* const* SUM, int nsums, const V* iacc, int i) {
  for (int k = 0; k < nsums; ++k) {
    if (RI == 1) {
      SUM[k][i] += _mm512_reduce_add_pd(iacc[k]);
    } else {
      SUM[k][i] += _mm512_mask_reduce_add_pd(0x0f, iacc[k]);
      SUM[k][i + 1] += _mm512_mask_reduce_add_pd(0xf0, iacc[k]);
    }
  }
}

// The tile loop: i-clusters of CI slots (CI = 8 / the layout's width, or half of it: t4x8),
// j-clusters of CJ = the layout's width, registers of RI = 8 / CJ i's. `list`: per i-cluster
// (of CI slots: for CI < CJ, cluster ci of the list's own numbering, ci * CI its first slot)
// its j-clusters.
// OWN: the own effects' rates (+ FourtakasDensityDiffusion: its series in the lanes; a lane
// whose |x| >= 0.01, never in a weakly compressible run, takes the power in a scalar fallback).
template <int CI, int CJ, int ARITH, bool OWN = false>
__attribute__((noinline)) void form_t(Slots& S, const std::vector<std::uint32_t>& begin, const std::vector<std::uint32_t>& jl,
                                      const Eq6& eq6, const Eq7& eq7, const Eq8& eq8 = Eq8()) {
  constexpr int RI = 8 / CJ;
  const V one = bc(1.0), half = bc(0.5), two = bc(2.0), zero = _mm512_setzero_pd();
  const V neg_eps = bc(-eq7.eps), neg_alpha = bc(-eq6.alpha), beta = bc(eq6.beta);
  const V c001 = bc(0.01);
  const double *X = S.f[0].data(), *Y = S.f[1].data(), *U = S.f[2].data(), *VV = S.f[3].data();
  const double *H = S.f[4].data(), *RHO = S.f[5].data(), *MS = S.f[6].data(), *CS = S.f[7].data();
  const double* HO = S.f[8].data();
  const double *VB = S.f[FVB].data(), *REOS = S.f[FREOS].data(), *BPI = S.f[FBPI].data(), *PP = S.f[FP].data();
  const V neg_rho0 = bc(-eq8.rho0), gxv = bc(eq8.gx), gyv = bc(eq8.gy), deltav = bc(eq8.delta), c0v = bc(eq8.c0);
  const V s2v = bc(eq8.s2), invgv = bc(eq8.invgamma), lim = bc(0.01);
  // rhoh of the lanes in `big` by the power (the body's else branch), scalar.
  auto fallback = [&](M big, V rhoh, V dph, const double* p_of_lane) -> V {
    alignas(64) double r[8], d[8];
    _mm512_store_pd(r, rhoh);
    _mm512_store_pd(d, dph);
    for (int l = 0; l < 8; ++l)
      if (big >> l & 1) {
        const double base = 1.0 + (p_of_lane[l] + d[l]) / eq8.B;
        r[l] = base > 0.0 ? eq8.rho0 * pow(base, eq8.invgamma) : 0.0;
      }
    return _mm512_load_pd(r);
  };
  double* SUM[NS];
  for (int k = 0; k < NS; ++k) SUM[k] = S.s[k].data();
  const int nci = static_cast<int>(begin.size()) - 1;
  for (int ci = 0; ci < nci; ++ci) {
    const int i0 = ci * CI;
    if (begin[ci] == begin[ci + 1]) continue;
    V iacc[CI / RI][NS];
    for (int r = 0; r < CI / RI; ++r)
      for (int k = 0; k < NS; ++k) iacc[r][k] = zero;
    for (std::uint32_t e = begin[ci]; e < begin[ci + 1]; ++e) {
      const int j0 = static_cast<int>(jl[e]) * CJ;
      const V xj = jval<CJ>(X, j0), yj = jval<CJ>(Y, j0), uj = jval<CJ>(U, j0), vj = jval<CJ>(VV, j0);
      const V hj = jval<CJ>(H, j0), rhoj = jval<CJ>(RHO, j0), mj = jval<CJ>(MS, j0), csj = jval<CJ>(CS, j0);
      const V hoj = jval<CJ>(HO, j0);
      V vbj = zero, reosj = zero, bpij = zero;
      if (OWN) vbj = jval<CJ>(VB, j0), reosj = jval<CJ>(REOS, j0), bpij = jval<CJ>(BPI, j0);
      const V neg_mj = sub(zero, mj);  // -s_m[s_idx]
      const V neg_eps_mj = mul(neg_eps, mj);  // -eps * s_m[s_idx]
      V jacc[NS];
      for (int k = 0; k < NS; ++k) jacc[k] = zero;
      const bool diagonal = j0 < i0 + CI && i0 < j0 + CJ;  // the j-cluster holds the i's: j > i only
      for (int r = 0; r < CI / RI; ++r) {
        const int i = i0 + r * RI;
        const V xi = ival<RI>(X, i), yi = ival<RI>(Y, i);
        const V XIJ_0 = sub(xi, xj), XIJ_1 = sub(yi, yj);
        const V R2IJ = add(mul(XIJ_0, XIJ_0), mul(XIJ_1, XIJ_1));
        const V hi = ival<RI>(H, i);
        const M in = register_mask<RI, CJ>(R2IJ, hi, hj, diagonal, i, j0);
#ifndef NO_REGSKIP
        if (!in) continue;  // no pair of this register within the support (-DNO_REGSKIP: every register computed)
#endif
        const V HIJ = mul(half, add(hi, hj));
        const V VIJ_0 = sub(ival<RI>(U, i), uj), VIJ_1 = sub(ival<RI>(VV, i), vj);
        V WIJ, DWIJ_f;
        wendland_register<ARITH>(R2IJ, HIJ, WIJ, DWIJ_f);
        const V DWIJ_0 = mul(DWIJ_f, XIJ_0), DWIJ_1 = mul(DWIJ_f, XIJ_1);
        const V RHOIJ = mul(half, add(ival<RI>(RHO, i), rhoj));
        const V RHOIJ1 = ARITH == EXACT ? div(one, RHOIJ) : rcp(RHOIJ);
        const V EPS = mul(mul(c001, HIJ), HIJ);
        // the values the pair shares
        const V vdw = fma(VIJ_0, DWIJ_0, mul(VIJ_1, DWIJ_1));
        const V tmp = add(ival<RI>(HO, i), hoj);
        const V vdx = fma(VIJ_0, XIJ_0, mul(VIJ_1, XIJ_1));
        const V cij = mul(half, add(ival<RI>(CS, i), csj));
        const V muij = ARITH == EXACT ? div(mul(HIJ, vdx), add(R2IJ, EPS)) : mul(mul(HIJ, vdx), rcp(add(R2IJ, EPS)));
        const V pi_f = fma(mul(neg_alpha, cij), muij, mul(mul(beta, muij), muij));
        const M visc = _mm512_cmp_pd_mask(vdx, zero, _CMP_LT_OQ);
        const V piij = sel(visc, mul(pi_f, RHOIJ1), zero);
        // i's terms (destination i, source j) in (a)'s order, under the mask
        const V fp = mul(neg_mj, tmp), fv = mul(neg_mj, piij);
        const V fx = mul(mul(neg_eps_mj, RHOIJ1), WIJ);
        V* ia = iacc[r];
        ia[0] = _mm512_mask3_fmadd_pd(mj, vdw, ia[0], in);
        ia[1] = _mm512_mask3_fmadd_pd(fv, DWIJ_0, _mm512_mask3_fmadd_pd(fp, DWIJ_0, ia[1], in), in);
        ia[2] = _mm512_mask3_fmadd_pd(fv, DWIJ_1, _mm512_mask3_fmadd_pd(fp, DWIJ_1, ia[2], in), in);
        ia[3] = _mm512_mask3_fmadd_pd(fx, VIJ_0, ia[3], in);
        ia[4] = _mm512_mask3_fmadd_pd(fx, VIJ_1, ia[4], in);
        // j's terms (destination j, source i): DWIJ_ji = -DWIJ, VIJ_ji = -VIJ exactly
        const V mi = ival<RI>(MS, i);
        const V neg_mi = sub(zero, mi);
        const V gp = mul(neg_mi, tmp), gv = mul(neg_mi, piij);
        const V gx = mul(mul(mul(neg_eps, mi), RHOIJ1), WIJ);
        jacc[0] = _mm512_mask3_fmadd_pd(mi, vdw, jacc[0], in);
        jacc[1] = _mm512_mask3_fnmadd_pd(gv, DWIJ_0, _mm512_mask3_fnmadd_pd(gp, DWIJ_0, jacc[1], in), in);
        jacc[2] = _mm512_mask3_fnmadd_pd(gv, DWIJ_1, _mm512_mask3_fnmadd_pd(gp, DWIJ_1, jacc[2], in), in);
        jacc[3] = _mm512_mask3_fnmadd_pd(gx, VIJ_0, jacc[3], in);
        jacc[4] = _mm512_mask3_fnmadd_pd(gx, VIJ_1, jacc[4], in);
        if (OWN) {  // FourtakasDensityDiffusion, after the continuity's term on arho (as (a))
          const M pos = in & _mm512_cmp_pd_mask(R2IJ, zero, _CMP_GT_OQ);
          const V dph = mul(neg_rho0, fma(gxv, XIJ_0, mul(gyv, XIJ_1)));
          const V xdw = neg(fma(XIJ_0, DWIJ_0, mul(XIJ_1, DWIJ_1)));
          const V ps2f = mul(mul(mul(deltav, HIJ), c0v), two);
          const V r2inv = ARITH == EXACT ? zero : rcp(R2IJ);
          // i's term: dph, i's bpinv and rhoeos, source j
          const V xi_ = mul(dph, ival<RI>(BPI, i));
          V rhoh_i = mul(ival<RI>(REOS, i), fma(xi_, fma(s2v, xi_, invgv), one));
          const M big_i = pos & _mm512_cmp_pd_mask(_mm512_abs_pd(xi_), lim, _CMP_NLT_UQ);
          if (big_i) {
            alignas(64) double pl[8];
            _mm512_store_pd(pl, ival<RI>(PP, i));
            rhoh_i = fallback(big_i, rhoh_i, dph, pl);
          }
          const V ti = mul(mul(ps2f, sub(rhoj, rhoh_i)), xdw);
          ia[0] = _mm512_mask3_fmadd_pd(ARITH == EXACT ? div(ti, R2IJ) : mul(ti, r2inv), vbj, ia[0], pos);
          // j's term: -dph, j's bpinv and rhoeos, source i
          const V ndph = neg(dph);
          const V xj_ = mul(ndph, bpij);
          V rhoh_j = mul(reosj, fma(xj_, fma(s2v, xj_, invgv), one));
          const M big_j = pos & _mm512_cmp_pd_mask(_mm512_abs_pd(xj_), lim, _CMP_NLT_UQ);
          if (big_j) {
            alignas(64) double pl[8];
            _mm512_store_pd(pl, jval<CJ>(PP, j0));
            rhoh_j = fallback(big_j, rhoh_j, ndph, pl);
          }
          const V tj = mul(mul(ps2f, sub(ival<RI>(RHO, i), rhoh_j)), xdw);
          jacc[0] = _mm512_mask3_fmadd_pd(ARITH == EXACT ? div(tj, R2IJ) : mul(tj, r2inv), ival<RI>(VB, i), jacc[0], pos);
        }
      }
      add_j_sums<CJ>(SUM, NS, jacc, j0);
    }
    for (int r = 0; r < CI / RI; ++r) add_i_sums<RI>(SUM, NS, iacc[r], i0 + r * RI);
  }
}

// The shifting pass (DeltaPlusShiftingSums + ShiftingCorrectionGradients) in the same tiles.
// One register: RI i's from slot i against the j-cluster at j0 (its values J), i's NSS terms
// into `a`, j's into `jacc`, under the cut-off's mask; false where no lane is within it (then
// nothing is computed).
struct ShiftJ {
  V x, y, u, v, h, rho, vb;
};
template <int RI, int CJ, int ARITH>
__attribute__((always_inline)) inline bool shift_register(const Slots& S, const ShiftJ& J, V R, int i, int j0, bool diagonal, V* a, V* jacc) {
  const double *X = S.f[FX].data(), *Y = S.f[FY].data(), *U = S.f[FU].data(), *VV = S.f[FV].data();
  const double *H = S.f[FH].data(), *RHO = S.f[FRHO].data(), *VB = S.f[FVB].data(), *DH = S.f[FDH].data();
  const V XIJ_0 = sub(ival<RI>(X, i), J.x), XIJ_1 = sub(ival<RI>(Y, i), J.y);
  const V R2IJ = add(mul(XIJ_0, XIJ_0), mul(XIJ_1, XIJ_1));
  const V hi = ival<RI>(H, i);
  const M in = register_mask<RI, CJ>(R2IJ, hi, J.h, diagonal, i, j0);
#ifndef NO_REGSKIP
  if (!in) return false;
#endif
  const V HIJ = mul(bc(0.5), add(hi, J.h));
  const V VIJ_0 = sub(ival<RI>(U, i), J.u), VIJ_1 = sub(ival<RI>(VV, i), J.v);
  V WIJ, DWIJ_f;
  wendland_register<ARITH>(R2IJ, HIJ, WIJ, DWIJ_f);
  const V D0 = mul(DWIJ_f, XIJ_0), D1 = mul(DWIJ_f, XIJ_1);
  // the values the pair shares (eq11: hd, wr, 1 + R wr^4; eq12: rho_j - rho_i, negated for j)
  const V hd = mul(HIJ, HIJ);  // dim == 2
  const V wr = mul(mul(WIJ, hd), ival<RI>(DH, i));
  const V ps2 = fma(mul(mul(mul(R, wr), wr), wr), wr, bc(1.0));
  const V rhoba = sub(J.rho, ival<RI>(RHO, i));
  // i's terms (source j: vb = vb_j), in (a)'s order
  {
    const V vb = J.vb, f = mul(vb, ps2);
    const V nx0 = neg(mul(vb, XIJ_0)), nx1 = neg(mul(vb, XIJ_1));
    const V g = mul(vb, rhoba);
    const V nv0 = neg(mul(vb, VIJ_0)), nv1 = neg(mul(vb, VIJ_1));
    a[6] = _mm512_mask3_fmadd_pd(f, D0, a[6], in);
    a[7] = _mm512_mask3_fmadd_pd(f, D1, a[7], in);
    a[4] = _mm512_mask3_fmadd_pd(vb, D0, a[4], in);
    a[5] = _mm512_mask3_fmadd_pd(vb, D1, a[5], in);
    a[0] = _mm512_mask3_fmadd_pd(nx0, D0, a[0], in);
    a[1] = _mm512_mask3_fmadd_pd(nx0, D1, a[1], in);
    a[2] = _mm512_mask3_fmadd_pd(nx1, D0, a[2], in);
    a[3] = _mm512_mask3_fmadd_pd(nx1, D1, a[3], in);
    a[8] = _mm512_mask3_fmadd_pd(g, D0, a[8], in);
    a[9] = _mm512_mask3_fmadd_pd(g, D1, a[9], in);
    a[10] = _mm512_mask3_fmadd_pd(nv0, D0, a[10], in);
    a[11] = _mm512_mask3_fmadd_pd(nv0, D1, a[11], in);
    a[12] = _mm512_mask3_fmadd_pd(nv1, D0, a[12], in);
    a[13] = _mm512_mask3_fmadd_pd(nv1, D1, a[13], in);
  }
  // j's terms (source i: vb = vb_i; XIJ_ji = -XIJ, DWIJ_ji = -DWIJ, VIJ_ji = -VIJ, rhoba
  // negated, all exactly): fma(a, -D, c) = fnmadd(a, D, c); -(vb (-x)) = vb x.
  {
    const V vb = ival<RI>(VB, i), f = mul(vb, ps2);
    const V px0 = mul(vb, XIJ_0), px1 = mul(vb, XIJ_1);
    const V g = mul(vb, rhoba);  // vb (-rhoba) times -D: g D
    const V pv0 = mul(vb, VIJ_0), pv1 = mul(vb, VIJ_1);
    jacc[6] = _mm512_mask3_fnmadd_pd(f, D0, jacc[6], in);
    jacc[7] = _mm512_mask3_fnmadd_pd(f, D1, jacc[7], in);
    jacc[4] = _mm512_mask3_fnmadd_pd(vb, D0, jacc[4], in);
    jacc[5] = _mm512_mask3_fnmadd_pd(vb, D1, jacc[5], in);
    jacc[0] = _mm512_mask3_fnmadd_pd(px0, D0, jacc[0], in);
    jacc[1] = _mm512_mask3_fnmadd_pd(px0, D1, jacc[1], in);
    jacc[2] = _mm512_mask3_fnmadd_pd(px1, D0, jacc[2], in);
    jacc[3] = _mm512_mask3_fnmadd_pd(px1, D1, jacc[3], in);
    jacc[8] = _mm512_mask3_fmadd_pd(g, D0, jacc[8], in);
    jacc[9] = _mm512_mask3_fmadd_pd(g, D1, jacc[9], in);
    jacc[10] = _mm512_mask3_fnmadd_pd(pv0, D0, jacc[10], in);
    jacc[11] = _mm512_mask3_fnmadd_pd(pv0, D1, jacc[11], in);
    jacc[12] = _mm512_mask3_fnmadd_pd(pv1, D0, jacc[12], in);
    jacc[13] = _mm512_mask3_fnmadd_pd(pv1, D1, jacc[13], in);
  }
  return true;
}

template <int CJ>
__attribute__((always_inline)) inline ShiftJ shift_j(const Slots& S, int j0) {
  return {jval<CJ>(S.f[FX].data(), j0), jval<CJ>(S.f[FY].data(), j0), jval<CJ>(S.f[FU].data(), j0),
          jval<CJ>(S.f[FV].data(), j0), jval<CJ>(S.f[FH].data(), j0), jval<CJ>(S.f[FRHO].data(), j0),
          jval<CJ>(S.f[FVB].data(), j0)};
}

// RMAJOR false, tile-major: per i-cluster its list, per tile every register of the i-cluster
// (all their i sums live: 14 per register). RMAJOR, register-major: per i-cluster, per register
// (RI i's) its whole list, so that only one register's 14 i sums are live (tile-major: all of
// the i-cluster's, 28 for 2xMM); the j sums added to memory per register and tile (2xMM: the
// halves folded first).
template <int CI, int CJ, int ARITH, bool RMAJOR = false>
__attribute__((noinline)) void form_t_shift(Slots& S, const std::vector<std::uint32_t>& begin,
                                            const std::vector<std::uint32_t>& jl, const Eq11& eq11) {
  constexpr int RI = 8 / CJ;
  const V zero = _mm512_setzero_pd(), R = bc(eq11.R);
  double* SUM[NSS];
  for (int k = 0; k < NSS; ++k) SUM[k] = S.ss[k].data();
  const int nci = static_cast<int>(begin.size()) - 1;
  for (int ci = 0; ci < nci; ++ci) {
    const int i0 = ci * CI;
    if (begin[ci] == begin[ci + 1]) continue;
    if (RMAJOR) {
      for (int r = 0; r < CI / RI; ++r) {
        V iacc[NSS];
        for (int k = 0; k < NSS; ++k) iacc[k] = zero;
        for (std::uint32_t e = begin[ci]; e < begin[ci + 1]; ++e) {
          const int j0 = static_cast<int>(jl[e]) * CJ;
          V jacc[NSS];
          for (int k = 0; k < NSS; ++k) jacc[k] = zero;
          const bool diagonal = j0 < i0 + CI && i0 < j0 + CJ;
          if (shift_register<RI, CJ, ARITH>(S, shift_j<CJ>(S, j0), R, i0 + r * RI, j0, diagonal, iacc, jacc))
            add_j_sums<CJ>(SUM, NSS, jacc, j0);
        }
        add_i_sums<RI>(SUM, NSS, iacc, i0 + r * RI);
      }
      continue;
    }
    V iacc[CI / RI][NSS];
    for (int r = 0; r < CI / RI; ++r)
      for (int k = 0; k < NSS; ++k) iacc[r][k] = zero;
    for (std::uint32_t e = begin[ci]; e < begin[ci + 1]; ++e) {
      const int j0 = static_cast<int>(jl[e]) * CJ;
      const ShiftJ J = shift_j<CJ>(S, j0);
      V jacc[NSS];
      for (int k = 0; k < NSS; ++k) jacc[k] = zero;
      const bool diagonal = j0 < i0 + CI && i0 < j0 + CJ;
      for (int r = 0; r < CI / RI; ++r) shift_register<RI, CJ, ARITH>(S, J, R, i0 + r * RI, j0, diagonal, iacc[r], jacc);
      add_j_sums<CJ>(SUM, NSS, jacc, j0);
    }
    for (int r = 0; r < CI / RI; ++r) add_i_sums<RI>(SUM, NSS, iacc[r], i0 + r * RI);
  }
}

#endif  // __AVX512F__

// The water column of the dam break (a lattice, jittered) or a snapshot from a file.
Fluid make_fluid(const std::string& path, int nx, int ny, double dx, double hdx, double pert, unsigned seed) {
  Fluid f;
  const double ro = 1000.0, g = 9.81, H = 2.0;
  std::vector<double> x, y, u, v, rho, p;
  if (!path.empty()) {
    FILE* in = std::fopen(path.c_str(), "r");
    if (!in) return f;
    char line[1024];
    while (std::fgets(line, sizeof line, in)) {
      if (line[0] == '#') continue;
      double r[6];
      if (std::sscanf(line, "%lf %lf %lf %lf %lf %lf", &r[0], &r[1], &r[2], &r[3], &r[4], &r[5]) != 6) continue;
      x.push_back(r[0]), y.push_back(r[1]), u.push_back(r[2]), v.push_back(r[3]), rho.push_back(r[4]), p.push_back(r[5]);
    }
    std::fclose(in);
  } else {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> uni(-1.0, 1.0);
    const double co = 10.0 * std::sqrt(2.0 * g * H), B = co * co * ro / 7.0;
    for (int iy = 0; iy < ny; ++iy)
      for (int ix = 0; ix < nx; ++ix) {
        x.push_back((ix + 0.5) * dx + pert * dx * uni(rng));
        y.push_back((iy + 0.5) * dx + pert * dx * uni(rng));
        u.push_back(uni(rng)), v.push_back(uni(rng));
        const double ph = ro * g * (ny * dx - y.back());  // hydrostatic
        const double r = ro * std::pow(1.0 + ph / B, 1.0 / 7.0);
        rho.push_back(r), p.push_back(B * (std::pow(r / ro, 7.0) - 1.0));
      }
  }
  // The solver's order: cells of side 2 h (y then x).
  const double h = hdx * dx, cell = 2.0 * h;
  double lo[2] = {1e300, 1e300};
  for (std::size_t i = 0; i < x.size(); ++i) lo[0] = std::min(lo[0], x[i]), lo[1] = std::min(lo[1], y[i]);
  auto key = [&](std::size_t i) {
    return std::make_pair(static_cast<long>(std::floor((y[i] - lo[1]) / cell)), static_cast<long>(std::floor((x[i] - lo[0]) / cell)));
  };
  std::vector<std::size_t> order(x.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key(a) < key(b); });
  const double co = 10.0 * std::sqrt(2.0 * g * H);
  f.n = static_cast<int>(x.size());
  for (std::size_t o : order) {
    f.x.push_back(x[o]), f.y.push_back(y[o]), f.u.push_back(u[o]), f.v.push_back(v[o]);
    f.rho.push_back(rho[o]), f.p.push_back(p[o]);
    f.h.push_back(h), f.m.push_back(ro * dx * dx);
    f.cs.push_back(co * std::pow(rho[o] / ro, 3.0));  // the scene's equation of state (gamma 7)
  }
  f.hoisted.resize(f.n);
  for (int i = 0; i < f.n; ++i) f.hoisted[i] = PressureGradient_loop_hoisted0(i, f.p.data(), f.rho.data());
  f.vb.resize(f.n);
  for (int i = 0; i < f.n; ++i) f.vb[i] = DeltaPlusShiftingSums_loop_hoisted0(i, f.m.data(), f.rho.data());
  f.dh.assign(f.n, DeltaPlusShiftingSums_loop_dhoisted0(0, hdx));
  const Eq8 eq8;
  f.rhoeos.resize(f.n), f.bpinv.resize(f.n);
  for (int i = 0; i < f.n; ++i)
    FourtakasDensityDiffusion_initialize(i, 0.0, 0.0, eq8.B, f.bpinv.data(), f.p.data(), f.rho.data(), f.rhoeos.data());
  f.zero_sums();
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  std::string positions, forms_arg = "a,t4x4,t4x8,t8x8,t4x4rcp,t4x8rcp,t8x8rcp,sa,st4x4,st4x8,st8x8,st4x4rcp,st8x8rcp,oa,ot4x4,ot8x8,ot4x4rcp,ot8x8rcp";
  int nx = 33, ny = 66, reps = 7, sweeps = 0;
  double dx = 0.03, hdx = 1.3, pert = 0.1, skin = 0.1;
  bench::Options opts;
  opts.value("--positions", positions).value("--nx", nx).value("--ny", ny).value("--dx", dx);
  opts.value("--hdx", hdx).value("--pert", pert).value("--skin", skin).value("--reps", reps);
  opts.value("--sweeps", sweeps).value("--forms", forms_arg);
  if (!opts.parse(argc, argv,
                  "[--positions FILE] [--nx 33 --ny 66] [--dx 0.03] [--hdx 1.3] [--pert 0.1]"
                  " [--skin 0.1] [--reps 7] [--sweeps N] [--forms a,t4x4,t4x8,t8x8,t4x4rcp,t4x8rcp,t8x8rcp,sa,st4x4,...]"))
    return 2;
#ifndef __AVX512F__
  std::printf("built without AVX-512F: the tiles need it (skipped)\n");
  return 77;
#else
  if (!__builtin_cpu_supports("avx512f")) {
    std::printf("this CPU has no AVX-512F (skipped)\n");
    return 77;
  }
  Fluid fa = make_fluid(positions, nx, ny, dx, hdx, pert, 12345);
  if (fa.n == 0) {
    std::fprintf(stderr, "no particles\n");
    return 2;
  }
  const Eq6 eq6;
  const Eq7 eq7;
  double hmax = 0;
  for (double h : fa.h) hmax = std::max(hmax, h);
  const double support = Kernel::radius_scale * hmax, rlist = (1.0 + skin) * support;
  const Kept kept = build_kept(fa, skin);
  std::vector<double> dhoist;
  long pairs = 0, entries = 0, visc = 0;
  for (int i = 0; i < fa.n; ++i)
    for (std::size_t e = kept.upper[i]; e < kept.lists[i].size(); ++e) {
      const int j = static_cast<int>(kept.lists[i][e]);
      if (j == i) continue;
      ++entries;
      const double ex = fa.x[i] - fa.x[j], ey = fa.y[i] - fa.y[j];
      if (ex * ex + ey * ey < support * support) {
        ++pairs;
        visc += (fa.u[i] - fa.u[j]) * ex + (fa.v[i] - fa.v[j]) * ey < 0;
      }
    }
  std::printf("%s: %d particles, dx = %g, h = %.3g dx; %ld pairs within 2 h (%.1f ordered neighbours per particle; the "
              "viscosity's branch in %.0f%%), %.1f kept-list entries above i per particle\n",
              positions.empty() ? "the dam break's water column (lattice, jittered)" : positions.c_str(), fa.n, dx, hdx,
              pairs, 2.0 * pairs / fa.n, 100.0 * visc / pairs, double(entries) / fa.n);

  // The layouts (width 4 and 8; the columns 2 and 2.83 dx: clusters about square) and their
  // lists, built once (a rebuild); the per-evaluation pieces timed below.
  const Eq11 eq11{hdx};
  Slots s4, s8;
  const Eq8 eq8;
  const double* P[NF] = {fa.x.data(),  fa.y.data(),       fa.u.data(),  fa.v.data(),  fa.h.data(),
                         fa.rho.data(), fa.m.data(),      fa.cs.data(), fa.hoisted.data(), fa.vb.data(),
                         fa.dh.data(), fa.rhoeos.data(), fa.bpinv.data(), fa.p.data()};
  for (Slots* s : {&s4, &s8}) {
    const int w = s == &s4 ? 4 : 8;
    sphc::build_cluster_layout(s->L, fa.x.data(), fa.y.data(), nullptr, fa.n, 2, sphc::cluster_column_side(dx, 2, w), w);
    sphc::build_cluster_pairs(s->L, s->L, rlist, true, s->outer);
    for (auto& v : s->f) v.assign(s->L.slots(), 0.0);
    for (auto& v : s->s) v.assign(s->L.slots(), 0.0);
    for (auto& v : s->ss) v.assign(s->L.slots(), 0.0);
  }
  // t4x8's list: the halves of the 8-clusters, each against the j-clusters of its 8-cluster's
  // pruned list whose boxes lie within the support of the half's own box.
  std::vector<std::uint32_t> half_begin, half_j;
  // Per evaluation (pass 0: the rates, 1: the shifting, 2: the own rates): the positions and the pass's fields
  // into slot order, the boxes, the pruned list (t4x8: its half list), the slot sums zeroed.
  auto evaluate_pieces = [&](Slots& s, bool halves, int pass) {
    sphc::gather_positions(s.L, fa.x.data(), fa.y.data(), nullptr, s.f[FX].data(), s.f[FY].data(), nullptr, 4 * rlist);
    if (pass == 0)
      for (int k : RATES_FIELDS) {
        if (k != FX && k != FY) sphc::gather_slots(s.L, P[k], s.f[k].data());
      }
    else if (pass == 1)
      for (int k : SHIFT_FIELDS) {
        if (k != FX && k != FY) sphc::gather_slots(s.L, P[k], s.f[k].data());
      }
    else
      for (int k : OWN_FIELDS) {
        if (k != FX && k != FY) sphc::gather_slots(s.L, P[k], s.f[k].data());
      }
    sphc::update_boxes(s.L, s.f[FX].data(), s.f[FY].data(), nullptr);
    sphc::prune_cluster_pairs(s.L, s.L, s.outer, support, s.pruned);
    if (pass != 1)
      for (auto& v : s.s) std::fill(v.begin(), v.end(), 0.0);
    else
      for (auto& v : s.ss) std::fill(v.begin(), v.end(), 0.0);
    if (halves) {
      const std::size_t nc = s.L.n_clusters;
      half_begin.assign(2 * nc + 1, 0);
      half_j.clear();
      const double r2 = support * support * (1 + 1e-12);
      for (std::size_t ci = 0; ci < nc; ++ci)
        for (int hf = 0; hf < 2; ++hf) {
          double lo[2] = {HUGE_VAL, HUGE_VAL}, hi[2] = {-HUGE_VAL, -HUGE_VAL};
          bool any = false;
          for (std::size_t sl = ci * 8 + 4 * hf; sl < ci * 8 + 4 * hf + 4; ++sl) {
            if (s.L.slot[sl] == sphc::kPadSlot) continue;
            any = true;
            lo[0] = std::min(lo[0], s.f[FX][sl]), hi[0] = std::max(hi[0], s.f[FX][sl]);
            lo[1] = std::min(lo[1], s.f[FY][sl]), hi[1] = std::max(hi[1], s.f[FY][sl]);
          }
          if (any)
            for (std::uint32_t e = s.pruned.begin[ci]; e < s.pruned.begin[ci + 1]; ++e) {
              const double* jb = &s.L.box[6 * s.pruned.j[e]];
              const double gx = std::max({0.0, jb[0] - hi[0], lo[0] - jb[3]});
              const double gy = std::max({0.0, jb[1] - hi[1], lo[1] - jb[4]});
              if (gx * gx + gy * gy <= r2) half_j.push_back(s.pruned.j[e]);
            }
          half_begin[2 * ci + hf + 1] = static_cast<std::uint32_t>(half_j.size());
        }
    }
  };
  // The slot sums added back onto the particles' sums (the shifting's components interleaved).
  auto add_back = [&](Slots& s, Fluid& out, int pass) {
    if (pass != 1) {
      std::vector<double>* dst[NS] = {&out.arho, &out.au, &out.av, &out.ax, &out.ay};
      for (int k = 0; k < NS; ++k) sphc::add_slots(s.L, s.s[k].data(), dst[k]->data());
      return;
    }
    const std::uint32_t* slot_of = s.L.slot_of.data();
    double *binv = out.binv.data(), *gradc = out.gradc.data(), *gradcw = out.gradcw.data();
    double *gradrhos = out.gradrhos.data(), *gradu = out.gradu.data();
    for (int p = 0; p < out.n; ++p) {
      const std::uint32_t q = slot_of[p];
      for (int c = 0; c < 4; ++c) binv[4 * p + c] += s.ss[c][q], gradu[4 * p + c] += s.ss[10 + c][q];
      for (int c = 0; c < 2; ++c)
        gradc[2 * p + c] += s.ss[4 + c][q], gradcw[2 * p + c] += s.ss[6 + c][q], gradrhos[2 * p + c] += s.ss[8 + c][q];
    }
  };
  evaluate_pieces(s4, false, 0);
  evaluate_pieces(s8, true, 0);
  // Lanes: pairs within the support in each form's registers.
  auto count_regs = [&](const sphc::ClusterLayout& L, const std::vector<std::uint32_t>& b, const std::vector<std::uint32_t>& jl,
                        int CI, int CJ, long& regs, long& regs_pair, long& in) {
    const int RI = 8 / CJ;
    const double* X = L.width == 4 ? s4.f[FX].data() : s8.f[FX].data();
    const double* Y = L.width == 4 ? s4.f[FY].data() : s8.f[FY].data();
    regs = regs_pair = in = 0;
    for (std::size_t ci = 0; ci + 1 < b.size(); ++ci)
      for (std::uint32_t e = b[ci]; e < b[ci + 1]; ++e)
        for (int r = 0; r < CI / RI; ++r) {
          long c = 0;
          for (int i = static_cast<int>(ci) * CI + r * RI; i < static_cast<int>(ci) * CI + r * RI + RI; ++i)
            for (int j = static_cast<int>(jl[e]) * CJ; j < static_cast<int>(jl[e]) * CJ + CJ; ++j) {
              if (L.slot[i] == sphc::kPadSlot || L.slot[j] == sphc::kPadSlot || j <= i) continue;
              const double ex = X[i] - X[j], ey = Y[i] - Y[j];
              c += ex * ex + ey * ey < support * support;
            }
          ++regs;
          regs_pair += c > 0;
          in += c;
        }
  };

  struct Form {
    std::string name;
    int pass = 0;
    Slots* slots = nullptr;
    bool halves = false;
    std::function<void()> run;  // one sweep from zeroed sums
    long regs = 0, regs_pair = 0, in = 0;
    std::vector<double> times;
  };
  std::vector<Form> forms;
  std::vector<double> dhoist11;
  auto add_form = [&](const std::string& full) {
    Form F;
    F.name = full;
    F.pass = full[0] == 's' ? 1 : full[0] == 'o' ? 2 : 0;
    const std::string name = F.pass ? full.substr(1) : full;
    if (name == "a") {
      if (F.pass == 0)
        F.run = [&] {
          fa.zero_sums();
          form_a(fa, kept, eq6, eq7, dhoist);
        };
      else if (F.pass == 2)
        F.run = [&] {
          fa.zero_sums();
          form_a<true>(fa, kept, eq6, eq7, dhoist, eq8);
        };
      else
        F.run = [&] {
          fa.zero_sums();
          form_a_shift(fa, kept, eq11, dhoist11);
        };
      forms.push_back(std::move(F));
      return;
    }
    const bool rmajor = F.pass == 1 && name.size() > 4 && name.substr(4) == "r";
    const bool rcp = name.size() > 4 && name.substr(4) == "rcp";
    const std::string shape = name.substr(0, 4);
    if ((name.size() > 4 && !rcp && !rmajor) || (shape != "t4x4" && shape != "t4x8" && shape != "t8x8")) {
      std::fprintf(stderr, "unknown form %s\n", full.c_str());
      std::exit(2);
    }
    Slots* s = shape == "t4x4" ? &s4 : &s8;
    F.slots = s;
    F.halves = shape == "t4x8";
    const int pass = F.pass;
    auto zero = [s, pass] {
      if (pass == 1)
        for (auto& v : s->ss) std::fill(v.begin(), v.end(), 0.0);
      else
        for (auto& v : s->s) std::fill(v.begin(), v.end(), 0.0);
    };
    const std::vector<std::uint32_t>& b = shape == "t4x8" ? half_begin : s->pruned.begin;
    const std::vector<std::uint32_t>& j = shape == "t4x8" ? half_j : s->pruned.j;
#define SPHC_FORM(CI, CJ)                                                                   \
  if (pass == 0 && rcp) F.run = [=, &b, &j, &eq6, &eq7] { zero(); form_t<CI, CJ, RCP>(*s, b, j, eq6, eq7); };      \
  if (pass == 0 && !rcp) F.run = [=, &b, &j, &eq6, &eq7] { zero(); form_t<CI, CJ, EXACT>(*s, b, j, eq6, eq7); };   \
  if (pass == 1 && rcp) F.run = [=, &b, &j, &eq11] { zero(); form_t_shift<CI, CJ, RCP>(*s, b, j, eq11); };         \
  if (pass == 1 && !rcp && !rmajor) F.run = [=, &b, &j, &eq11] { zero(); form_t_shift<CI, CJ, EXACT>(*s, b, j, eq11); }; \
  if (pass == 1 && rmajor) F.run = [=, &b, &j, &eq11] { zero(); form_t_shift<CI, CJ, EXACT, true>(*s, b, j, eq11); }; \
  if (pass == 2 && rcp) F.run = [=, &b, &j, &eq6, &eq7, &eq8] { zero(); form_t<CI, CJ, RCP, true>(*s, b, j, eq6, eq7, eq8); }; \
  if (pass == 2 && !rcp) F.run = [=, &b, &j, &eq6, &eq7, &eq8] { zero(); form_t<CI, CJ, EXACT, true>(*s, b, j, eq6, eq7, eq8); }; \
  count_regs(s->L, b, j, CI, CJ, F.regs, F.regs_pair, F.in);
    if (shape == "t4x4") { SPHC_FORM(4, 4) }
    if (shape == "t4x8") { SPHC_FORM(4, 8) }
    if (shape == "t8x8") { SPHC_FORM(8, 8) }
#undef SPHC_FORM
    forms.push_back(std::move(F));
  };
  {
    std::size_t at = 0;
    while (at <= forms_arg.size()) {
      const std::size_t comma = std::min(forms_arg.find(',', at), forms_arg.size());
      if (comma > at) add_form(forms_arg.substr(at, comma - at));
      at = comma + 1;
    }
  }
  // The references: form (a) of each pass once (fref: the rates and the shifting; fown: the
  // own effects' rates).
  Fluid fref = fa, fown = fa;
  fref.zero_sums();
  form_a(fref, kept, eq6, eq7, dhoist);
  form_a_shift(fref, kept, eq11, dhoist11);
  fown.zero_sums();
  form_a<true>(fown, kept, eq6, eq7, dhoist, eq8);

  // Sweeps per timed rep: ~20 ms of form (a) of the rates.
  if (sweeps <= 0) {
    Fluid tmp = fa;
    const double t0 = cpu_now();
    int k = 0;
    do form_a(tmp, kept, eq6, eq7, dhoist), ++k;
    while (cpu_now() - t0 < 0.02);
    sweeps = std::max(1, k);
  }
  // Correctness of every form, then the timing rounds (interleaved).
  int bad = 0;
  struct Sum {
    const char* name;
    std::vector<double> Fluid::*v;
    int pass;
  };
  const Sum sums[] = {{"arho", &Fluid::arho, 0},        {"au", &Fluid::au, 0},         {"av", &Fluid::av, 0},
                      {"ax", &Fluid::ax, 0},            {"ay", &Fluid::ay, 0},         {"binv", &Fluid::binv, 1},
                      {"gradc", &Fluid::gradc, 1},      {"gradcw", &Fluid::gradcw, 1}, {"gradrhos", &Fluid::gradrhos, 1},
                      {"gradu", &Fluid::gradu, 1}};
  std::vector<double> worst(forms.size(), 0.0);
  for (std::size_t k = 0; k < forms.size(); ++k) {
    Form& F = forms[k];
    if (F.slots) evaluate_pieces(*F.slots, F.halves, F.pass);
    F.run();
    Fluid out = fa;
    if (F.slots) {
      out.zero_sums();
      add_back(*F.slots, out, F.pass);
    }
    for (const Sum& q : sums) {
      if (q.pass != (F.pass == 2 ? 0 : F.pass)) continue;
      const std::vector<double>& want = (F.pass == 2 ? fown : fref).*q.v;
      const std::vector<double>& got = out.*q.v;
      // per component (the shifting's sums interleave 2 or 4 components)
      const int nc = static_cast<int>(want.size()) / fa.n;
      for (int c = 0; c < nc; ++c) {
        double scale = 0, diff = 0;
        for (int i = 0; i < fa.n; ++i)
          scale = std::max(scale, std::fabs(want[nc * i + c])), diff = std::max(diff, std::fabs(got[nc * i + c] - want[nc * i + c]));
        const double rel = scale > 0 ? diff / scale : diff;
        worst[k] = std::max(worst[k], rel);
        if (!(rel <= 1e-12)) {
          std::printf("FAILED: form %s, sum %s[%d]: max |X - a| / max |a| = %.3g > 1e-12\n", F.name.c_str(), q.name, c, rel);
          bad = 1;
        }
      }
    }
    if (F.slots && F.in != pairs) {
      std::printf("FAILED: form %s's registers hold %ld of the %ld pairs within the support\n", F.name.c_str(), F.in, pairs);
      bad = 1;
    }
  }
  // Timing: per round every form (its tiles only: the pieces are timed apart), interleaved.
  double t_pieces[2][3], t_add[2][3];  // [layout 4, 8][pass]
  for (auto& a : t_pieces) a[0] = a[1] = a[2] = 1e30;
  for (auto& a : t_add) a[0] = a[1] = a[2] = 1e30;
  bool pass_used[3] = {false, false, false};
  for (const Form& F : forms) pass_used[F.pass] = true;
  Fluid scratch = fa;
  for (int r = 0; r < reps; ++r) {
    for (std::size_t k = 0; k < forms.size(); ++k) {
      Form& F = forms[k];
      if (F.slots) evaluate_pieces(*F.slots, F.halves, F.pass);
      const double t0 = cpu_now();
      for (int w = 0; w < sweeps; ++w) F.run();
      F.times.push_back((cpu_now() - t0) / sweeps);
    }
    for (int pass = 0; pass < 3; ++pass) {
      if (!pass_used[pass]) continue;
      for (int l = 0; l < 2; ++l) {
        Slots& s = l ? s8 : s4;
        double t0 = cpu_now();
        for (int w = 0; w < sweeps; ++w) evaluate_pieces(s, l == 1, pass);
        t_pieces[l][pass] = std::min(t_pieces[l][pass], (cpu_now() - t0) / sweeps);
        t0 = cpu_now();
        for (int w = 0; w < sweeps; ++w) add_back(s, scratch, pass);
        t_add[l][pass] = std::min(t_add[l][pass], (cpu_now() - t0) / sweeps);
      }
    }
  }
  const double clock = clock_estimate(20000000);
  for (int pass = 0; pass < 3; ++pass)
    if (pass_used[pass])
      std::printf("per evaluation besides the tiles, %s: width 4 layout %.2f us (positions, %d fields, boxes, pruning, slot sums"
                  " zeroed) + %.2f us (%d sums added back); width 8 %.2f + %.2f us (with t4x8's half list)\n",
                  pass == 1 ? "the shifting pass" : pass == 2 ? "the own effects' rates" : "the rates (PySPH's effects)",
                  1e6 * t_pieces[0][pass], pass == 1 ? 6 : pass == 2 ? 11 : 7, 1e6 * t_add[0][pass], pass == 1 ? NSS : NS,
                  1e6 * t_pieces[1][pass], 1e6 * t_add[1][pass]);
  std::printf("clock while running 512-bit FMAs: %.2f GHz; %d sweeps per rep, %d reps interleaved, thread CPU time\n\n",
              clock * 1e-9, sweeps, reps);
  std::printf("%-10s %11s %11s %9s %12s %12s %10s %10s %10s %12s\n", "form", "us/sweep", "median", "of (a)", "M pairs/s",
              "ns/pair", "regs/part", "lanes in", "cyc/reg", "max rel diff");
  double ta[3] = {0, 0, 0};
  for (Form& F : forms)
    if (!F.slots) ta[F.pass] = *std::min_element(F.times.begin(), F.times.end());
  for (std::size_t k = 0; k < forms.size(); ++k) {
    const Form& F = forms[k];
    const double tmin = *std::min_element(F.times.begin(), F.times.end());
    char regs[32] = "-", lanes[32] = "-", cyc[32] = "-";
    if (F.slots) {
      std::snprintf(regs, sizeof regs, "%.2f", double(F.regs_pair) / fa.n);
      std::snprintf(lanes, sizeof lanes, "%.1f%%", 100.0 * F.in / (8.0 * F.regs_pair));
      std::snprintf(cyc, sizeof cyc, "%.1f", tmin * clock / F.regs_pair);
    }
    std::printf("%-10s %11.2f %11.2f %9.3f %12.1f %12.2f %10s %10s %10s %12.2e\n", F.name.c_str(), 1e6 * tmin,
                1e6 * median(F.times), ta[F.pass] > 0 ? tmin / ta[F.pass] : 0.0, 2.0 * pairs / tmin * 1e-6,
                1e9 * tmin / pairs, regs, lanes, cyc, worst[k]);
  }
  std::printf("(forms s...: the shifting pass, o...: the own effects' rates; M pairs/s: ordered pairs within the support; ns/pair: per pair evaluated once;"
              " regs/part: registers with a pair computed per particle; cyc/reg: real cycles per register computed)\n");
  if (bad) return 1;
  std::printf("OK: every form within 1e-12 of form (a), every pair within the support in the tiles\n");
  return 0;
#endif
}
