// sphc runtime: SPH smoothing kernels (header only).
//
// Every kernel is a radial function W(r, h) = sigma_d / h^d * f(q), q = r / h, with compact
// support q < radius_scale. Each is a class template on the dimension so that generated code
// names the exact type (e.g. `sphc::CubicSpline<2>`) and the hot loop inlines it: all members
// are static and inline, with no virtual calls and no allocation.
//
// Interface of every kernel K = Kernel<Dim>:
//   K::radius_scale           support radius in units of h (W = 0 for r >= radius_scale * h)
//   K::name                   "CubicSpline", ...
//   K::w(rij, h)              W(r_ij, h)
//   K::dwdq(rij, h)           dW/dq = sigma_d / h^d * f'(q): the derivative with respect to q,
//                             normalisation included. Hence
//                                 grad_i W = dwdq(rij, h) / (h * rij) * xij
//   K::gradient(xij, rij, h, grad)
//                             grad_i W, the gradient with respect to x_i, where
//                             xij = x_i - x_j and rij = |xij|; it is zero for rij < 1e-12
//                             (the gradient of a radial kernel vanishes at r = 0, and this
//                             avoids 0/0).
//
// Kernels and normalisations sigma_d for d = 1, 2, 3:
//   CubicSpline     (Monaghan 1992, 2005), support 2h
//                   f = 1 - 3/2 q^2 + 3/4 q^3 (q < 1), 1/4 (2 - q)^3 (1 <= q < 2)
//                   sigma = 2/3, 10/(7 pi), 1/pi
//   QuinticSpline   (Morris et al. 1997), support 3h
//                   f = (3-q)^5 - 6 (2-q)^5 + 15 (1-q)^5, each term only where its base > 0
//                   sigma = 1/120, 7/(478 pi), 1/(120 pi)
//                   (the 3D value 3/(359 pi) found in some texts does not integrate to one:
//                   the exact integral of f over R^3 is 120 pi.)
//   WendlandQuintic (Wendland C2, Dehnen & Aly 2012), support 2h
//                   d = 2, 3: f = (1 - q/2)^4 (2q + 1), sigma = 7/(4 pi), 21/(16 pi)
//                   d = 1:    the C2 Wendland function of 1D, f = (1 - q/2)^3 (1.5q + 1),
//                             sigma = 5/8 (the 2D/3D function is not positive definite in 1D;
//                             PySPH offers this one as a separate 1D-only kernel).
//   Gaussian        truncated at 3h: f = exp(-q^2), sigma = 1/pi^(d/2).
//                   The truncation is not renormalised (as in PySPH): the integral over the
//                   support is erf(3) in 1D, 1 - e^-9 in 2D, erf(3) - 6/sqrt(pi) e^-9 in 3D,
//                   i.e. 1 - O(1e-4).
//   WendlandQuinticC4  (Wendland C4, Dehnen & Aly 2012), support 2h
//                   d = 2, 3: f = (1 - q/2)^6 (35/12 q^2 + 3q + 1),
//                             sigma = 9/(4 pi), 495/(256 pi)
//                   d = 1:    the C4 Wendland function of 1D, f = (1 - q/2)^5 (2q^2 + 2.5q + 1),
//                             sigma = 3/4 (PySPH's WendlandQuinticC4_1D).
//   WendlandQuinticC6  (Wendland C6, Dehnen & Aly 2012), support 2h
//                   d = 2, 3: f = (1 - q/2)^8 (4q^3 + 6.25q^2 + 4q + 1),
//                             sigma = 78/(28 pi), 1365/(512 pi)
//                   d = 1:    the C6 Wendland function of 1D,
//                             f = (1 - q/2)^7 (21/8 q^3 + 19/4 q^2 + 3.5q + 1), sigma = 55/64
//                             (PySPH's WendlandQuinticC6_1D).
//   SuperGaussian   (Monaghan 1992), truncated at 3h: f = exp(-q^2) (1 + d/2 - q^2),
//                   sigma = 1/pi^(d/2) as for the Gaussian. It is negative for q > sqrt(1 + d/2).
//                   Not renormalised either: integrating q^(d+1) e^(-q^2) by parts, the
//                   integral over the support is the Gaussian's plus S_d 3^d e^-9 / (2 pi^(d/2))
//                   (S_d = 2, 2 pi, 4 pi), i.e. erf(3) + 3/sqrt(pi) e^-9 in 1D, 1 + 8 e^-9 in 2D,
//                   erf(3) + 48/sqrt(pi) e^-9 in 3D.
// The names and normalisations are PySPH's (pysph.base.kernels); for the Wendland C4 and C6
// kernels PySPH has a separate 1D class, which sphc selects for dim = 1 under the same name.
#pragma once

#include <cmath>
#include <stdexcept>
#include <string>

namespace sphc {

namespace detail {

// Every kernel function below is inlined wherever it is called (GCC, Clang). Plain `inline`
// leaves it to the compiler's heuristics, and GCC splits a shape function (its `q >= 3`
// test inlined, the rest a function `.part.0`) and stops inlining that part where the caller
// has grown past its limits: the serial solver's phase, which holds every pair loop of a group
// (the channel's TVF scene: its eight summation-density loops), calls it, while the OpenMP
// solver, each loop in its own outlined function, inlines it. A call in a SIMD pair loop
// (codegen/SimdPairs.cpp) keeps that loop scalar, and a scalar `omp simd` reduction sums in
// another order than the vector one: serial and OpenMP then differed in the last bits
// (docs/performance-log.md, "Loose ends (stop 37)").
#if defined(__GNUC__)
#define SPHC_KERNEL_INLINE inline __attribute__((always_inline))
#else
#define SPHC_KERNEL_INLINE inline
#endif

constexpr double kPi = 3.14159265358979323846;
constexpr double kInvSqrtPi = 0.56418958354775628695;     // 1 / sqrt(pi)
constexpr double kInvPi32 = 0.17958712212516656169;       // 1 / pi^(3/2)

// The kernels are templates on the floating point type T of their arguments (double, or
// float for --precision=single): every literal is converted to T, so a float call computes in
// float, and a double call does the operations of the plain double formulas.

// 1 / h^Dim from 1 / h (inv_h_pow: from h).
template <int Dim, class T>
SPHC_KERNEL_INLINE T ih_pow(T ih) {
  static_assert(Dim >= 1 && Dim <= 3, "sphc kernels: Dim must be 1, 2 or 3");
  if constexpr (Dim == 1) {
    return ih;
  } else if constexpr (Dim == 2) {
    return ih * ih;
  } else {
    return ih * ih * ih;
  }
}
template <int Dim, class T>
SPHC_KERNEL_INLINE T inv_h_pow(T h) {
  return ih_pow<Dim>(T(1) / h);
}

// The shape functions f(q), f'(q) of every kernel, as templates on the floating point type
// (sphc/kernel_shapes.h: the same text is the OpenCL program's, see runtime/src/opencl.cpp).
namespace shapes {
#define SPHC_KERNEL_SHAPES(...) __VA_ARGS__
#define SPHC_SHAPE_FN template <class real> SPHC_KERNEL_INLINE real
#define SPHC_R(x) real(x)
#define SPHC_EXP(x) std::exp(x)
#include "sphc/kernel_shapes.h"
#undef SPHC_EXP
#undef SPHC_R
#undef SPHC_SHAPE_FN
#undef SPHC_KERNEL_SHAPES
}  // namespace shapes

// The part common to all kernels: W, dW/dq and the gradient from a shape `S` providing
// `S::sigma` (normalisation for the dimension), `S::radius_scale`, `S::f(q)` and `S::df(q)`.
// f and df must return 0 for q >= radius_scale.
template <class S, int Dim>
struct RadialKernel {
  static constexpr int dim = Dim;
  static constexpr double radius_scale = S::radius_scale;
  static constexpr double sigma = S::sigma;  // W = sigma / h^d f(r / h)

  // Each form is its `_ih` form below (h's factors 1 / h^Dim and 1 / h given) with the factors
  // computed from h: the same operations in the same order.
  // W = sigma / h^d f(r / h).
  template <class T>
  static SPHC_KERNEL_INLINE T w(T rij, T h) {
    return w_ih(rij, h, inv_h_dim(h));
  }
  template <class T>
  static SPHC_KERNEL_INLINE T dwdq(T rij, T h) {
    return dwdq_ih(rij, h, inv_h_dim(h));
  }
  // dW/dx_i = dW/dq * dq/dr * dr/dx_i = dwdq * (1/h) * xij / rij.
  template <class T>
  static SPHC_KERNEL_INLINE void gradient(const T xij[3], T rij, T h, T grad[3]) {
    gradient_ih(xij, rij, h, inv_h_dim(h), grad);
  }
  // The factor s of gradient() (grad = s * xij), its value bit for bit, as a select on a
  // safe divisor (no branch: the SIMD pair loops of sphc --simd-pairs, codegen/SimdPairs.cpp).
  template <class T>
  static SPHC_KERNEL_INLINE T gradient_factor(T rij, T h) {
    return gradient_factor_ih(rij, h, inv_h_dim(h));
  }
  // The cluster-pair tiles' forms (codegen/ClusterPairs.cpp, sphc --tile-math=recip, the
  // default; stop 41): w() and gradient_factor() with their divisions after the square root
  // turned into multiplications by reciprocals that do not wait for it: q = rij * (1 / h) and 1
  // / rij = rij * (1 / rij^2) (r2 = rij^2 as the caller has it, rij = sqrt(r2)), so that a
  // lane's kernel values take the divisions 1 / h (the same double as inv_h_pow's, shared by
  // every value of the pair with that h) and 1 / r2, both started before the square root ends,
  // and none after it (the exact forms: sqrt, then r / h, then dwdq / (h r) in one chain). In
  // the DualSPHysics scene's tiles 0.90x of the exact forms' time, the cube's 0.965x
  // (docs/performance-log.md, "The tiles' divisions and square root (stop 41)"). Error against
  // the exact forms, from the algebra (u = 2^-53; checked by tests/unit/test_kernels.cpp,
  // TileReciprocalFormsWithinBounds, over h in [1e-9, 1e9], q over the support and past it, r
  // down to 0): q within 3 ulp (two roundings against one); the gradient's 1 / (h rij) within 6
  // u relative (1 / h, 1 / r2, two products, rij^2 / r2 = (1 + e)^2); the kernel values then
  // differ by what f and f' do with q's 3 ulp and by the shapes' own rounding at two points:
  // within 64 u of the kernel's scale (sigma / h^d max f, resp. sigma / h^(d+1) max |f'| / rij;
  // observed 47 u for the quintic spline's gradient, whose terms cancel, 3.5-14 u for the
  // others). Exactly 0 beyond the support (q past the edge by more than 3 ulp) and, for the
  // gradient, at rij <= 1e-12 (1 / r2 of a safe divisor); within 3 ulp of the edge q may fall
  // on its other side (the truncated Gaussians: their jump, e^-9 of W(0)). Valid while 1 / r2
  // is a normal number: rij below 1.3e154 (double).
  template <class T>
  static SPHC_KERNEL_INLINE T w_tile(T rij, T h) {
    return w_tile_ih(rij, inv_h(h), inv_h_dim(h));
  }
  template <class T>
  static SPHC_KERNEL_INLINE T gradient_factor_tile(T rij, T r2, T h) {
    return gradient_factor_tile_ih(rij, r2, inv_h(h), inv_h_dim(h));
  }
  // The same forms from reciprocals the caller has (sphc --tile-math=batched, stop 45): ih =
  // 1 / h and ir2 = 1 / r2 (r2 guarded as tile_r2_guard does), ir2 as tile_reciprocals derives
  // it with RHOIJ1 from one division. With ih = T(1) / h they are w_tile's value bit for bit;
  // with tile_reciprocals' ir2, within 3 u of 1 / r2 (below), the gradient's 1 / (h rij) is
  // within a few u, W and the gradient factor within recip's 64 u of the kernel's scale
  // (tests/unit/test_kernels.cpp, TileBatchedFormsWithinBounds).
  template <class T>
  static SPHC_KERNEL_INLINE T w_tile_rcp(T rij, T ih) {
    return w_tile_ih(rij, ih, ih_pow<Dim>(ih));
  }
  template <class T>
  static SPHC_KERNEL_INLINE T gradient_factor_tile_rcp(T rij, T ir2, T ih) {
    const bool apart = rij > T(1e-12);
    const T irij = rij * ir2;
    const T s = T(S::sigma) * ih_pow<Dim>(ih) * S::df(rij * ih) * (ih * irij);
    return apart ? s : T(0);
  }
  // The gradients of one pair for both particles (sphc's pair loops that evaluate each pair
  // once): grad_ij = gradient(xij, rij, h) and grad_ji = gradient(xji, rij, h), xji = x_j -
  // x_i, with the factor s computed once; each is gradient()'s value bit for bit.
  template <class T>
  static SPHC_KERNEL_INLINE void gradient_pair(const T xij[3], const T xji[3], T rij, T h,
                                               T grad_ij[3], T grad_ji[3]) {
    gradient_pair_ih(xij, xji, rij, h, inv_h_dim(h), grad_ij, grad_ji);
  }
  // The forms above with h's factors given (stop 45: a pair loop whose arrays' h is one value
  // for the whole run, sphc's analysis/UniformH.cpp, computes them once per pass): ih =
  // inv_h(h) = 1 / h, ihd = inv_h_dim(h) = 1 / h^Dim, the doubles w, dwdq, w_tile, ... compute
  // from h; each form does the same operations in the same order as its model's, so its values
  // are the model's bit for bit (tests/unit/test_kernels.cpp, FactorFormsBitwise).
  template <class T>
  static SPHC_KERNEL_INLINE T inv_h(T h) {
    return T(1) / h;
  }
  template <class T>
  static SPHC_KERNEL_INLINE T inv_h_dim(T h) {
    return inv_h_pow<Dim>(h);
  }
  template <class T>
  static SPHC_KERNEL_INLINE T w_ih(T rij, T h, T ihd) {  // w
    return T(S::sigma) * ihd * S::f(rij / h);
  }
  template <class T>
  static SPHC_KERNEL_INLINE T dwdq_ih(T rij, T h, T ihd) {  // dwdq
    return T(S::sigma) * ihd * S::df(rij / h);
  }
  template <class T>
  static SPHC_KERNEL_INLINE void gradient_ih(const T xij[3], T rij, T h, T ihd, T grad[3]) {
    const T s = rij > T(1e-12) ? dwdq_ih(rij, h, ihd) / (h * rij) : T(0);  // gradient
    grad[0] = s * xij[0];
    grad[1] = s * xij[1];
    grad[2] = s * xij[2];
  }
  template <class T>
  static SPHC_KERNEL_INLINE T gradient_factor_ih(T rij, T h, T ihd) {  // gradient_factor
    const bool apart = rij > T(1e-12);
    const T s = dwdq_ih(rij, h, ihd) / (h * (apart ? rij : T(1)));
    return apart ? s : T(0);
  }
  template <class T>
  static SPHC_KERNEL_INLINE void gradient_pair_ih(const T xij[3], const T xji[3], T rij, T h,
                                                  T ihd, T grad_ij[3], T grad_ji[3]) {
    const T s = rij > T(1e-12) ? dwdq_ih(rij, h, ihd) / (h * rij) : T(0);  // gradient_pair
    grad_ij[0] = s * xij[0];
    grad_ij[1] = s * xij[1];
    grad_ij[2] = s * xij[2];
    grad_ji[0] = s * xji[0];
    grad_ji[1] = s * xji[1];
    grad_ji[2] = s * xji[2];
  }
  template <class T>
  static SPHC_KERNEL_INLINE T w_tile_ih(T rij, T ih, T ihd) {  // w_tile
    return T(S::sigma) * ihd * S::f(rij * ih);
  }
  template <class T>
  static SPHC_KERNEL_INLINE T gradient_factor_tile_ih(T rij, T r2, T ih, T ihd) {  // gradient_factor_tile
    const bool apart = rij > T(1e-12);
    const T irij = rij * (T(1) / (r2 > T(0) ? r2 : T(1)));
    const T s = T(S::sigma) * ihd * S::df(rij * ih) * (ih * irij);
    return apart ? s : T(0);
  }
};

// The members f(q) and df(q) of a shape: the functions NAME_f and NAME_df of kernel_shapes.h.
#define SPHC_SHAPE_FUNCTIONS(NAME)                   \
  template <class T>                                 \
  static SPHC_KERNEL_INLINE T f(T q) {               \
    return shapes::NAME##_f(q);                      \
  }                                                  \
  template <class T>                                 \
  static SPHC_KERNEL_INLINE T df(T q) {              \
    return shapes::NAME##_df(q);                     \
  }

template <int Dim>
struct CubicShape {
  static constexpr double radius_scale = 2.0;
  static constexpr double sigma =
      Dim == 1 ? 2.0 / 3.0 : Dim == 2 ? 10.0 / (7.0 * kPi) : 1.0 / kPi;
  SPHC_SHAPE_FUNCTIONS(sphc_cubic)
};

template <int Dim>
struct QuinticShape {
  static constexpr double radius_scale = 3.0;
  static constexpr double sigma =
      Dim == 1 ? 1.0 / 120.0 : Dim == 2 ? 7.0 / (478.0 * kPi) : 1.0 / (120.0 * kPi);
  SPHC_SHAPE_FUNCTIONS(sphc_quintic)
};

// Wendland C2 for d = 2, 3: (1 - q/2)^4 (2q + 1).
template <int Dim>
struct WendlandC2Shape {
  static constexpr double radius_scale = 2.0;
  static constexpr double sigma = Dim == 2 ? 7.0 / (4.0 * kPi) : 21.0 / (16.0 * kPi);
  SPHC_SHAPE_FUNCTIONS(sphc_wendland_c2)
};

// Wendland C2 for d = 1: (1 - q/2)^3 (1.5q + 1).
template <>
struct WendlandC2Shape<1> {
  static constexpr double radius_scale = 2.0;
  static constexpr double sigma = 5.0 / 8.0;
  SPHC_SHAPE_FUNCTIONS(sphc_wendland_c2_1d)
};

template <int Dim>
struct GaussianShape {
  static constexpr double radius_scale = 3.0;
  static constexpr double sigma = Dim == 1 ? kInvSqrtPi : Dim == 2 ? 1.0 / kPi : kInvPi32;
  SPHC_SHAPE_FUNCTIONS(sphc_gaussian)
};

// Wendland C4 for d = 2, 3: (1 - q/2)^6 (35/12 q^2 + 3q + 1).
template <int Dim>
struct WendlandC4Shape {
  static constexpr double radius_scale = 2.0;
  static constexpr double sigma = Dim == 2 ? 9.0 / (4.0 * kPi) : 495.0 / (256.0 * kPi);
  SPHC_SHAPE_FUNCTIONS(sphc_wendland_c4)
};

// Wendland C4 for d = 1: (1 - q/2)^5 (2q^2 + 2.5q + 1).
template <>
struct WendlandC4Shape<1> {
  static constexpr double radius_scale = 2.0;
  static constexpr double sigma = 0.75;
  SPHC_SHAPE_FUNCTIONS(sphc_wendland_c4_1d)
};

// Wendland C6 for d = 2, 3: (1 - q/2)^8 (4q^3 + 6.25q^2 + 4q + 1).
template <int Dim>
struct WendlandC6Shape {
  static constexpr double radius_scale = 2.0;
  static constexpr double sigma = Dim == 2 ? 78.0 / (28.0 * kPi) : 1365.0 / (512.0 * kPi);
  SPHC_SHAPE_FUNCTIONS(sphc_wendland_c6)
};

// Wendland C6 for d = 1: (1 - q/2)^7 (21/8 q^3 + 19/4 q^2 + 3.5q + 1).
template <>
struct WendlandC6Shape<1> {
  static constexpr double radius_scale = 2.0;
  static constexpr double sigma = 55.0 / 64.0;
  SPHC_SHAPE_FUNCTIONS(sphc_wendland_c6_1d)
};

// Super-Gaussian: exp(-q^2) (1 + d/2 - q^2), truncated at 3h.
template <int Dim>
struct SuperGaussianShape {
  static constexpr double radius_scale = 3.0;
  static constexpr double sigma = GaussianShape<Dim>::sigma;
  template <class T>
  static SPHC_KERNEL_INLINE T f(T q) {
    return shapes::sphc_super_gaussian_f(q, T(1 + 0.5 * Dim));
  }
  template <class T>
  static SPHC_KERNEL_INLINE T df(T q) {
    return shapes::sphc_super_gaussian_df(q, T(Dim + 4));
  }
};

#undef SPHC_SHAPE_FUNCTIONS

}  // namespace detail

// The cluster-pair tiles' reciprocals of a lane from one division (sphc --tile-math=batched,
// the tiles' default since stop 45; codegen/SimdPairs.cpp prints them where a lane needs 1 /
// RHOIJ (RHOIJ1) and 1 / r2 (a gradient's); the kernel's 1 / h stays a division of its own,
// once per pass where h is one value, analysis/UniformH.cpp). A 512-bit divide takes the
// divider ~16 cycles where a multiply takes a port half a cycle (docs/performance-log.md, "One
// division for the tiles' reciprocals (stop 45; `--tile-math=batched`)").
// inv = 1 / (a b), 1 / a = b inv, 1 / b = a inv: one division and 3 multiplications for two
// reciprocals. Error (u = 2^-53, relative, first order; every operand and product normal):
// each within 3 u (tests/unit/test_kernels.cpp, TileReciprocalsWithinBounds). The domain: the
// product a b must be a normal number; in the tiles a = r2 guarded by tile_r2_guard (at least
// 1e-25, or 1) and b = RHOIJ, so a lane within the support (r2 < (radius_scale hmax)^2) has a
// b below radius_scale^2 hmax^2 rho and above 1e-25 rho: normal for any h and rho a simulation
// in SI units (or scaled ones) has (double: rho >= 2.2e-283 and rho hmax^2 <= 4e307; float:
// rho >= 1.2e-13 and rho hmax^2 <= 8e37). Lanes outside the support may overflow or underflow
// (inf, 0, NaN): their values are masked out of every sum, as the exact forms' are.
template <class T>
SPHC_KERNEL_INLINE T tile_r2_guard(T r2) {
  // r2 <= 1e-25 means rij < 1e-12: the gradient is 0 there and 1 / r2 unused (gradient_factor)
  return r2 > T(1e-25) ? r2 : T(1);
}
template <class T>
SPHC_KERNEL_INLINE void tile_reciprocals(T a, T b, T& ia, T& ib) {
  const T inv = T(1) / (a * b);
  ia = b * inv;
  ib = a * inv;
}

template <int Dim>
struct CubicSpline : detail::RadialKernel<detail::CubicShape<Dim>, Dim> {
  static constexpr const char* name = "CubicSpline";
};

template <int Dim>
struct QuinticSpline : detail::RadialKernel<detail::QuinticShape<Dim>, Dim> {
  static constexpr const char* name = "QuinticSpline";
};

template <int Dim>
struct WendlandQuintic : detail::RadialKernel<detail::WendlandC2Shape<Dim>, Dim> {
  static constexpr const char* name = "WendlandQuintic";
};

template <int Dim>
struct Gaussian : detail::RadialKernel<detail::GaussianShape<Dim>, Dim> {
  static constexpr const char* name = "Gaussian";
};

template <int Dim>
struct WendlandQuinticC4 : detail::RadialKernel<detail::WendlandC4Shape<Dim>, Dim> {
  static constexpr const char* name = "WendlandQuinticC4";
};

template <int Dim>
struct WendlandQuinticC6 : detail::RadialKernel<detail::WendlandC6Shape<Dim>, Dim> {
  static constexpr const char* name = "WendlandQuinticC6";
};

template <int Dim>
struct SuperGaussian : detail::RadialKernel<detail::SuperGaussianShape<Dim>, Dim> {
  static constexpr const char* name = "SuperGaussian";
};

// ---- Run-time selection (tests and tools; generated code names the kernel type) ----------

enum class KernelKind {
  CubicSpline,
  QuinticSpline,
  WendlandQuintic,
  Gaussian,
  WendlandQuinticC4,
  WendlandQuinticC6,
  SuperGaussian,
};

// Every kind, in the order above.
inline constexpr KernelKind kAllKernelKinds[] = {
    KernelKind::CubicSpline,       KernelKind::QuinticSpline,     KernelKind::WendlandQuintic,
    KernelKind::Gaussian,          KernelKind::WendlandQuinticC4, KernelKind::WendlandQuinticC6,
    KernelKind::SuperGaussian};

inline const char* kernel_name(KernelKind k) {
  switch (k) {
    case KernelKind::CubicSpline: return "CubicSpline";
    case KernelKind::QuinticSpline: return "QuinticSpline";
    case KernelKind::WendlandQuintic: return "WendlandQuintic";
    case KernelKind::Gaussian: return "Gaussian";
    case KernelKind::WendlandQuinticC4: return "WendlandQuinticC4";
    case KernelKind::WendlandQuinticC6: return "WendlandQuinticC6";
    case KernelKind::SuperGaussian: return "SuperGaussian";
  }
  return "?";
}

// The kind named `name` (as in kernel_name); false if there is none.
inline bool parse_kernel_kind(const std::string& name, KernelKind& out) {
  for (KernelKind k : kAllKernelKinds) {
    if (name == kernel_name(k)) {
      out = k;
      return true;
    }
  }
  return false;
}

// A kernel chosen at run time: a switch per call, so not for the hot loop.
struct AnyKernel {
  KernelKind kind = KernelKind::CubicSpline;
  int dim = 2;

  double w(double rij, double h) const {
    return visit([&](auto k) { return decltype(k)::w(rij, h); });
  }
  double dwdq(double rij, double h) const {
    return visit([&](auto k) { return decltype(k)::dwdq(rij, h); });
  }
  void gradient(const double xij[3], double rij, double h, double grad[3]) const {
    visit([&](auto k) {
      decltype(k)::gradient(xij, rij, h, grad);
      return 0.0;
    });
  }
  double radius_scale() const {
    return visit([](auto k) { return decltype(k)::radius_scale; });
  }
  double sigma() const {
    return visit([](auto k) { return decltype(k)::sigma; });
  }
  const char* name() const { return kernel_name(kind); }

  // Calls fn(K<dim>{}) for the selected kernel type; throws std::invalid_argument for a
  // dimension other than 1, 2, 3.
  template <class Fn>
  double visit(Fn&& fn) const {
    switch (kind) {
      case KernelKind::CubicSpline: return visit_dim<CubicSpline>(fn);
      case KernelKind::QuinticSpline: return visit_dim<QuinticSpline>(fn);
      case KernelKind::WendlandQuintic: return visit_dim<WendlandQuintic>(fn);
      case KernelKind::Gaussian: return visit_dim<Gaussian>(fn);
      case KernelKind::WendlandQuinticC4: return visit_dim<WendlandQuinticC4>(fn);
      case KernelKind::WendlandQuinticC6: return visit_dim<WendlandQuinticC6>(fn);
      case KernelKind::SuperGaussian: return visit_dim<SuperGaussian>(fn);
    }
    throw std::invalid_argument("sphc::AnyKernel: unknown kernel kind");
  }

 private:
  template <template <int> class K, class Fn>
  double visit_dim(Fn& fn) const {
    switch (dim) {
      case 1: return fn(K<1>{});
      case 2: return fn(K<2>{});
      case 3: return fn(K<3>{});
    }
    throw std::invalid_argument(std::string("sphc::AnyKernel: dimension must be 1, 2 or 3 (got ") +
                                std::to_string(dim) + ")");
  }
};

}  // namespace sphc
