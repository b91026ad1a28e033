// What the hand-written tile programs of bench/ share (cluster_pairs.cpp, cluster_pairs_2d.cpp;
// cluster_lists.cpp takes the timing): the thread's CPU time, the median of the rounds, and,
// built for AVX-512F, the vector operations the tiles are written in (8 doubles a register,
// masks of 8 lanes) and the core's clock while it runs 512-bit FMAs.
//
//   #include "bench_tiles.h"
//   namespace { using namespace bench::tiles; ... }
#pragma once

#include <immintrin.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include <time.h>

namespace bench {
namespace tiles {

// CPU time of this thread (the machine is shared: wall time would be the load's).
inline double cpu_now() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// The median of the rounds' times (the upper one of an even count; 0 for none).
inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

#ifdef __AVX512F__
using V = __m512d;
using M = __mmask8;
inline V bc(double a) { return _mm512_set1_pd(a); }
inline V add(V a, V b) { return _mm512_add_pd(a, b); }
inline V sub(V a, V b) { return _mm512_sub_pd(a, b); }
inline V mul(V a, V b) { return _mm512_mul_pd(a, b); }
inline V div(V a, V b) { return _mm512_div_pd(a, b); }
inline V fma(V a, V b, V c) { return _mm512_fmadd_pd(a, b, c); }
inline V sel(M m, V yes, V no) { return _mm512_mask_blend_pd(m, no, yes); }
// -x (the sign flipped, as the scalar code's unary minus; 0 - x would give +0 for +0)
inline V neg(V x) { return _mm512_castsi512_pd(_mm512_xor_si512(_mm512_castpd_si512(x), _mm512_set1_epi64(INT64_MIN))); }
// 1 / x from vrcp14pd (relative error < 2^-14) and two Newton steps (~2^-28, then ~1 ulp).
inline V rcp(V x) {
  V r = _mm512_rcp14_pd(x);
  r = fma(r, _mm512_fnmadd_pd(x, r, bc(1.0)), r);
  r = fma(r, _mm512_fnmadd_pd(x, r, bc(1.0)), r);
  return r;
}
// 1 / sqrt(x) from vrsqrt14pd and two Newton steps: y += y (1 - x y^2) / 2.
inline V rsqrt(V x) {
  V y = _mm512_rsqrt14_pd(x);
  for (int it = 0; it < 2; ++it) {
    const V e = _mm512_fnmadd_pd(mul(x, y), y, bc(1.0));
    y = fma(mul(y, bc(0.5)), e, y);
  }
  return y;
}

// The core's clock while it runs 512-bit FMAs: a chain of `n` dependent vfmadd (4 cycles each
// on this core), the best of 3 rounds of the thread's CPU time.
inline double clock_estimate(long n) {
  __m512d x = _mm512_set1_pd(1.0);
  const __m512d b = _mm512_set1_pd(0.999999), c = _mm512_set1_pd(1e-9);
  double best = 1e30;
  for (int r = 0; r < 3; ++r) {
    const double t0 = cpu_now();
    for (long i = 0; i < n; ++i) {
      x = _mm512_fmadd_pd(x, b, c);
      __asm__ volatile("" : "+v"(x));
    }
    best = std::min(best, cpu_now() - t0);
  }
  return _mm512_reduce_add_pd(x) > 0 ? 4.0 * n / best : 0.0;
}
#endif  // __AVX512F__

}  // namespace tiles
}  // namespace bench
