// sphc runtime: the shape functions f(q) and f'(q) of every smoothing kernel (kernels.h),
// written once for both the CPU backends and the OpenCL device program. Not a header to
// include on its own: the includer defines
//   SPHC_KERNEL_SHAPES(...)  what to make of the text: kernels.h expands it as C++ (the
//                            functions are templates on the floating point type), opencl.cpp
//                            turns it into a string for the device program (#__VA_ARGS__);
//   SPHC_SHAPE_FN            the start of a definition returning `real` (C++: a template on
//                            `real`; OpenCL: `inline real`, with the program's typedef);
//   SPHC_R(x)                the literal x in type real;
//   SPHC_EXP(x)              exp in type real.
// So the text is in the common subset of C++17 and OpenCL C 1.2: no preprocessor lines, no
// string literals, no casts other than through SPHC_R. Each function does the operations of
// the kernel's formula in one fixed order (the CPU and device results then differ only where
// the device compiler contracts a * b + c into an FMA). The formulas and their derivations
// are in kernels.h. No include guard: each includer includes it once with its own macros.
#ifndef SPHC_KERNEL_SHAPES
#error "sphc/kernel_shapes.h is included by sphc/kernels.h and the OpenCL runtime only"
#endif
SPHC_KERNEL_SHAPES(

// CubicSpline: 1 - 3/2 q^2 + 3/4 q^3 (q < 1), 1/4 (2 - q)^3 (1 <= q < 2).
SPHC_SHAPE_FN sphc_cubic_f(real q) {
  if (q < SPHC_R(1)) return SPHC_R(1) - SPHC_R(1.5) * q * q * (SPHC_R(1) - SPHC_R(0.5) * q);
  if (q < SPHC_R(2)) {
    const real t = SPHC_R(2) - q;
    return SPHC_R(0.25) * t * t * t;
  }
  return SPHC_R(0);
}
SPHC_SHAPE_FN sphc_cubic_df(real q) {
  if (q < SPHC_R(1)) return q * (SPHC_R(2.25) * q - SPHC_R(3));
  if (q < SPHC_R(2)) {
    const real t = SPHC_R(2) - q;
    return SPHC_R(-0.75) * t * t;
  }
  return SPHC_R(0);
}

// QuinticSpline: (3-q)^5 - 6 (2-q)^5 + 15 (1-q)^5, each term only where its base > 0.
SPHC_SHAPE_FN sphc_quintic_f(real q) {
  if (q >= SPHC_R(3)) return SPHC_R(0);
  const real t3 = SPHC_R(3) - q, t2 = SPHC_R(2) - q, t1 = SPHC_R(1) - q;
  real v = t3 * t3 * t3 * t3 * t3;
  if (q < SPHC_R(2)) v -= SPHC_R(6) * t2 * t2 * t2 * t2 * t2;
  if (q < SPHC_R(1)) v += SPHC_R(15) * t1 * t1 * t1 * t1 * t1;
  return v;
}
SPHC_SHAPE_FN sphc_quintic_df(real q) {
  if (q >= SPHC_R(3)) return SPHC_R(0);
  const real t3 = SPHC_R(3) - q, t2 = SPHC_R(2) - q, t1 = SPHC_R(1) - q;
  real v = SPHC_R(-5) * t3 * t3 * t3 * t3;
  if (q < SPHC_R(2)) v += SPHC_R(30) * t2 * t2 * t2 * t2;
  if (q < SPHC_R(1)) v -= SPHC_R(75) * t1 * t1 * t1 * t1;
  return v;
}

// Wendland C2, d = 2, 3: (1 - q/2)^4 (2q + 1); its derivative -5 q t^3.
SPHC_SHAPE_FN sphc_wendland_c2_f(real q) {
  if (q >= SPHC_R(2)) return SPHC_R(0);
  const real t = SPHC_R(1) - SPHC_R(0.5) * q, t2 = t * t;
  return t2 * t2 * (SPHC_R(2) * q + SPHC_R(1));
}
SPHC_SHAPE_FN sphc_wendland_c2_df(real q) {
  if (q >= SPHC_R(2)) return SPHC_R(0);
  const real t = SPHC_R(1) - SPHC_R(0.5) * q;
  return SPHC_R(-5) * q * t * t * t;
}

// Wendland C2, d = 1: (1 - q/2)^3 (1.5q + 1); its derivative -3 q t^2.
SPHC_SHAPE_FN sphc_wendland_c2_1d_f(real q) {
  if (q >= SPHC_R(2)) return SPHC_R(0);
  const real t = SPHC_R(1) - SPHC_R(0.5) * q;
  return t * t * t * (SPHC_R(1.5) * q + SPHC_R(1));
}
SPHC_SHAPE_FN sphc_wendland_c2_1d_df(real q) {
  if (q >= SPHC_R(2)) return SPHC_R(0);
  const real t = SPHC_R(1) - SPHC_R(0.5) * q;
  return SPHC_R(-3) * q * t * t;
}

// Gaussian, truncated at q = 3: exp(-q^2).
SPHC_SHAPE_FN sphc_gaussian_f(real q) {
  return q < SPHC_R(3) ? SPHC_EXP(-q * q) : SPHC_R(0);
}
SPHC_SHAPE_FN sphc_gaussian_df(real q) {
  return q < SPHC_R(3) ? SPHC_R(-2) * q * SPHC_EXP(-q * q) : SPHC_R(0);
}

// Wendland C4, d = 2, 3: (1 - q/2)^6 (35/12 q^2 + 3q + 1); its derivative
// -14/3 q (1 + 5/2 q) t^5.
SPHC_SHAPE_FN sphc_wendland_c4_f(real q) {
  if (q >= SPHC_R(2)) return SPHC_R(0);
  const real t = SPHC_R(1) - SPHC_R(0.5) * q, t2 = t * t;
  return t2 * t2 * t2 * ((SPHC_R(35) / SPHC_R(12)) * q * q + SPHC_R(3) * q + SPHC_R(1));
}
SPHC_SHAPE_FN sphc_wendland_c4_df(real q) {
  if (q >= SPHC_R(2)) return SPHC_R(0);
  const real t = SPHC_R(1) - SPHC_R(0.5) * q, t2 = t * t;
  return (SPHC_R(-14) / SPHC_R(3)) * q * (SPHC_R(1) + SPHC_R(2.5) * q) * t2 * t2 * t;
}

// Wendland C4, d = 1: (1 - q/2)^5 (2q^2 + 2.5q + 1); its derivative -7/2 q (2q + 1) t^4.
SPHC_SHAPE_FN sphc_wendland_c4_1d_f(real q) {
  if (q >= SPHC_R(2)) return SPHC_R(0);
  const real t = SPHC_R(1) - SPHC_R(0.5) * q, t2 = t * t;
  return t2 * t2 * t * (SPHC_R(2) * q * q + SPHC_R(2.5) * q + SPHC_R(1));
}
SPHC_SHAPE_FN sphc_wendland_c4_1d_df(real q) {
  if (q >= SPHC_R(2)) return SPHC_R(0);
  const real t = SPHC_R(1) - SPHC_R(0.5) * q, t2 = t * t;
  return SPHC_R(-3.5) * q * (SPHC_R(2) * q + SPHC_R(1)) * t2 * t2;
}

// Wendland C6, d = 2, 3: (1 - q/2)^8 (4q^3 + 6.25q^2 + 4q + 1); its derivative
// -11/2 q (4q^2 + 3.5q + 1) t^7.
SPHC_SHAPE_FN sphc_wendland_c6_f(real q) {
  if (q >= SPHC_R(2)) return SPHC_R(0);
  const real t = SPHC_R(1) - SPHC_R(0.5) * q, t2 = t * t, t4 = t2 * t2;
  return t4 * t4 * (((SPHC_R(4) * q + SPHC_R(6.25)) * q + SPHC_R(4)) * q + SPHC_R(1));
}
SPHC_SHAPE_FN sphc_wendland_c6_df(real q) {
  if (q >= SPHC_R(2)) return SPHC_R(0);
  const real t = SPHC_R(1) - SPHC_R(0.5) * q, t2 = t * t, t4 = t2 * t2;
  return SPHC_R(-5.5) * q * ((SPHC_R(4) * q + SPHC_R(3.5)) * q + SPHC_R(1)) * t4 * t2 * t;
}

// Wendland C6, d = 1: (1 - q/2)^7 (21/8 q^3 + 19/4 q^2 + 3.5q + 1); its derivative
// -1/2 q (105/4 q^2 + 27q + 9) t^6.
SPHC_SHAPE_FN sphc_wendland_c6_1d_f(real q) {
  if (q >= SPHC_R(2)) return SPHC_R(0);
  const real t = SPHC_R(1) - SPHC_R(0.5) * q, t2 = t * t, t4 = t2 * t2;
  return t4 * t2 * t * (((SPHC_R(2.625) * q + SPHC_R(4.75)) * q + SPHC_R(3.5)) * q + SPHC_R(1));
}
SPHC_SHAPE_FN sphc_wendland_c6_1d_df(real q) {
  if (q >= SPHC_R(2)) return SPHC_R(0);
  const real t = SPHC_R(1) - SPHC_R(0.5) * q, t2 = t * t;
  return SPHC_R(-0.5) * q * ((SPHC_R(26.25) * q + SPHC_R(27)) * q + SPHC_R(9)) * t2 * t2 * t2;
}

// Super-Gaussian, truncated at q = 3: exp(-q^2) (a - q^2) with a = 1 + d/2; its derivative
// q (2q^2 - b) exp(-q^2) with b = 2a + 2 = d + 4.
SPHC_SHAPE_FN sphc_super_gaussian_f(real q, real a) {
  if (q >= SPHC_R(3)) return SPHC_R(0);
  const real q2 = q * q;
  return SPHC_EXP(-q2) * (a - q2);
}
SPHC_SHAPE_FN sphc_super_gaussian_df(real q, real b) {
  if (q >= SPHC_R(3)) return SPHC_R(0);
  const real q2 = q * q;
  return q * (SPHC_R(2) * q2 - b) * SPHC_EXP(-q2);
}

)
