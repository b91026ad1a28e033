// fma_peak.cpp: the FP64 peak of one core, measured (used by bench/roofline.py; stop 44): the
// throughput of fused multiply-adds on 12 independent chains each of zmm (AVX-512, 8 doubles),
// ymm (AVX2, 4) and scalar registers, and the clock from a chain of dependent integer adds
// (1 cycle each). A VM's /proc/cpuinfo "cpu MHz" is its TSC rate, not the clock the cores run
// at; this measures what the cores do. CPU time of the thread (CLOCK_THREAD_CPUTIME_ID), the
// best of the repetitions. 12 chains cover an FMA latency of 4-6 cycles on two units.
// Prints "fma_GFLOPs_zmm=... fma_GFLOPs_ymm=... fma_GFLOPs_scalar=... clock_GHz=..." (a kind
// the CPU lacks is left out) and the flops per cycle of each at that clock.
//   c++ -O2 -march=native bench/fma_peak.cpp -o fma_peak && ./fma_peak
#include <time.h>

#include <cstdio>
#include <cstdlib>

#if defined(__AVX2__) || defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace {

double cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

volatile double g_sink;  // keeps the chains' results alive

constexpr int kChains = 12;

// Each returns the flops it did (2 per lane per FMA).
#if defined(__AVX512F__)
__attribute__((noinline)) double fma_zmm(long iters) {
  __m512d a0 = _mm512_set1_pd(1.000);
  __m512d a1 = _mm512_set1_pd(1.001);
  __m512d a2 = _mm512_set1_pd(1.002);
  __m512d a3 = _mm512_set1_pd(1.003);
  __m512d a4 = _mm512_set1_pd(1.004);
  __m512d a5 = _mm512_set1_pd(1.005);
  __m512d a6 = _mm512_set1_pd(1.006);
  __m512d a7 = _mm512_set1_pd(1.007);
  __m512d a8 = _mm512_set1_pd(1.008);
  __m512d a9 = _mm512_set1_pd(1.009);
  __m512d a10 = _mm512_set1_pd(1.010);
  __m512d a11 = _mm512_set1_pd(1.011);
  const __m512d a = _mm512_set1_pd(0.999999), b = _mm512_set1_pd(1e-6);
  for (long i = 0; i < iters; ++i) {
    a0 = _mm512_fmadd_pd(a0, a, b);
    a1 = _mm512_fmadd_pd(a1, a, b);
    a2 = _mm512_fmadd_pd(a2, a, b);
    a3 = _mm512_fmadd_pd(a3, a, b);
    a4 = _mm512_fmadd_pd(a4, a, b);
    a5 = _mm512_fmadd_pd(a5, a, b);
    a6 = _mm512_fmadd_pd(a6, a, b);
    a7 = _mm512_fmadd_pd(a7, a, b);
    a8 = _mm512_fmadd_pd(a8, a, b);
    a9 = _mm512_fmadd_pd(a9, a, b);
    a10 = _mm512_fmadd_pd(a10, a, b);
    a11 = _mm512_fmadd_pd(a11, a, b);
    __asm__ volatile("" : "+v"(a0), "+v"(a1), "+v"(a2), "+v"(a3), "+v"(a4), "+v"(a5), "+v"(a6), "+v"(a7), "+v"(a8), "+v"(a9), "+v"(a10), "+v"(a11));
  }
  const __m512d s = _mm512_add_pd(_mm512_add_pd(_mm512_add_pd(a0, a1), _mm512_add_pd(a2, a3)),
      _mm512_add_pd(_mm512_add_pd(_mm512_add_pd(a4, a5), _mm512_add_pd(a6, a7)),
                    _mm512_add_pd(_mm512_add_pd(a8, a9), _mm512_add_pd(a10, a11))));
  alignas(64) double t[8];
  _mm512_store_pd(t, s);
  g_sink = t[0] + t[1] + t[2] + t[3] + t[4] + t[5] + t[6] + t[7];
  return 2.0 * 8 * kChains * static_cast<double>(iters);
}
#endif

#if defined(__AVX2__) && defined(__FMA__)
__attribute__((noinline)) double fma_ymm(long iters) {
  __m256d a0 = _mm256_set1_pd(1.000);
  __m256d a1 = _mm256_set1_pd(1.001);
  __m256d a2 = _mm256_set1_pd(1.002);
  __m256d a3 = _mm256_set1_pd(1.003);
  __m256d a4 = _mm256_set1_pd(1.004);
  __m256d a5 = _mm256_set1_pd(1.005);
  __m256d a6 = _mm256_set1_pd(1.006);
  __m256d a7 = _mm256_set1_pd(1.007);
  __m256d a8 = _mm256_set1_pd(1.008);
  __m256d a9 = _mm256_set1_pd(1.009);
  __m256d a10 = _mm256_set1_pd(1.010);
  __m256d a11 = _mm256_set1_pd(1.011);
  const __m256d a = _mm256_set1_pd(0.999999), b = _mm256_set1_pd(1e-6);
  for (long i = 0; i < iters; ++i) {
    a0 = _mm256_fmadd_pd(a0, a, b);
    a1 = _mm256_fmadd_pd(a1, a, b);
    a2 = _mm256_fmadd_pd(a2, a, b);
    a3 = _mm256_fmadd_pd(a3, a, b);
    a4 = _mm256_fmadd_pd(a4, a, b);
    a5 = _mm256_fmadd_pd(a5, a, b);
    a6 = _mm256_fmadd_pd(a6, a, b);
    a7 = _mm256_fmadd_pd(a7, a, b);
    a8 = _mm256_fmadd_pd(a8, a, b);
    a9 = _mm256_fmadd_pd(a9, a, b);
    a10 = _mm256_fmadd_pd(a10, a, b);
    a11 = _mm256_fmadd_pd(a11, a, b);
    __asm__ volatile("" : "+x"(a0), "+x"(a1), "+x"(a2), "+x"(a3), "+x"(a4), "+x"(a5), "+x"(a6), "+x"(a7), "+x"(a8), "+x"(a9), "+x"(a10), "+x"(a11));
  }
  const __m256d s = _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(a0, a1), _mm256_add_pd(a2, a3)),
      _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(a4, a5), _mm256_add_pd(a6, a7)),
                    _mm256_add_pd(_mm256_add_pd(a8, a9), _mm256_add_pd(a10, a11))));
  alignas(32) double t[4];
  _mm256_store_pd(t, s);
  g_sink = t[0] + t[1] + t[2] + t[3];
  return 2.0 * 4 * kChains * static_cast<double>(iters);
}

__attribute__((noinline)) double fma_scalar(long iters) {
  __m128d a0 = _mm_set_sd(1.000);
  __m128d a1 = _mm_set_sd(1.001);
  __m128d a2 = _mm_set_sd(1.002);
  __m128d a3 = _mm_set_sd(1.003);
  __m128d a4 = _mm_set_sd(1.004);
  __m128d a5 = _mm_set_sd(1.005);
  __m128d a6 = _mm_set_sd(1.006);
  __m128d a7 = _mm_set_sd(1.007);
  __m128d a8 = _mm_set_sd(1.008);
  __m128d a9 = _mm_set_sd(1.009);
  __m128d a10 = _mm_set_sd(1.010);
  __m128d a11 = _mm_set_sd(1.011);
  const __m128d a = _mm_set_sd(0.999999), b = _mm_set_sd(1e-6);
  for (long i = 0; i < iters; ++i) {
    a0 = _mm_fmadd_sd(a0, a, b);
    a1 = _mm_fmadd_sd(a1, a, b);
    a2 = _mm_fmadd_sd(a2, a, b);
    a3 = _mm_fmadd_sd(a3, a, b);
    a4 = _mm_fmadd_sd(a4, a, b);
    a5 = _mm_fmadd_sd(a5, a, b);
    a6 = _mm_fmadd_sd(a6, a, b);
    a7 = _mm_fmadd_sd(a7, a, b);
    a8 = _mm_fmadd_sd(a8, a, b);
    a9 = _mm_fmadd_sd(a9, a, b);
    a10 = _mm_fmadd_sd(a10, a, b);
    a11 = _mm_fmadd_sd(a11, a, b);
    __asm__ volatile("" : "+x"(a0), "+x"(a1), "+x"(a2), "+x"(a3), "+x"(a4), "+x"(a5), "+x"(a6), "+x"(a7), "+x"(a8), "+x"(a9), "+x"(a10), "+x"(a11));
  }
  const __m128d s = _mm_add_sd(_mm_add_sd(_mm_add_sd(a0, a1), _mm_add_sd(a2, a3)),
      _mm_add_sd(_mm_add_sd(_mm_add_sd(a4, a5), _mm_add_sd(a6, a7)),
                 _mm_add_sd(_mm_add_sd(a8, a9), _mm_add_sd(a10, a11))));
  g_sink = _mm_cvtsd_f64(s);
  return 2.0 * 1 * kChains * static_cast<double>(iters);
}
#endif

// Dependent integer adds of a register, 1 cycle each: returns the cycles (the adds) it took.
// (Not adds of an immediate: Golden Cove-class cores fold a chain of those at rename, several
// per cycle; measured 20 "GHz" here.)
__attribute__((noinline)) double add_chain(long iters) {
  long x = 0, y = 1;
  for (long i = 0; i < iters; ++i) {
#if defined(__x86_64__)
    __asm__ volatile(".rept 100\n\taddq %1, %0\n\t.endr" : "+r"(x) : "r"(y));
#else
#error "fma_peak.cpp: x86-64 only"
#endif
  }
  g_sink = static_cast<double>(x);
  return 100.0 * static_cast<double>(iters);
}

// Dependent integer multiplies, 3 cycles each on Intel and AMD cores since Sandy Bridge:
// returns the cycles they took (a second estimate of the clock).
__attribute__((noinline)) double imul_chain(long iters) {
  long x = 1, y = 1;
  for (long i = 0; i < iters; ++i) __asm__ volatile(".rept 100\n\timulq %1, %0\n\t.endr" : "+r"(x) : "r"(y));
  g_sink = static_cast<double>(x);
  return 300.0 * static_cast<double>(iters);
}

// The best rate (units per second) of `reps` runs of f(iters), by CPU time.
template <class F>
double best_rate(F f, long iters, int reps) {
  double best = 0;
  for (int r = 0; r < reps; ++r) {
    const double t0 = cpu_seconds();
    const double units = f(iters);
    const double t = cpu_seconds() - t0;
    if (t > 0 && units / t > best) best = units / t;
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  const int reps = argc > 1 ? std::atoi(argv[1]) : 7;
  // FMA runs of 240 M FMAs (~0.04 s at ~3.3 GHz), clock runs of 0.4 G and 0.6 G cycles
  const long iters = argc > 2 ? std::atol(argv[2]) : 20000000L;
  best_rate(add_chain, iters / 5, 2);  // warm-up: the clock up from idle
  const double hz = best_rate(add_chain, iters / 5, reps);
  const double hz3 = best_rate(imul_chain, iters / 10, reps);
  std::printf("clock_GHz=%.3f clock_imul_GHz=%.3f", hz / 1e9, hz3 / 1e9);
  double zmm = 0, ymm = 0, sc = 0;
#if defined(__AVX512F__)
  zmm = best_rate(fma_zmm, iters, reps);
  std::printf(" fma_GFLOPs_zmm=%.2f", zmm / 1e9);
#endif
#if defined(__AVX2__) && defined(__FMA__)
  ymm = best_rate(fma_ymm, iters, reps);
  sc = best_rate(fma_scalar, iters, reps);
  std::printf(" fma_GFLOPs_ymm=%.2f fma_GFLOPs_scalar=%.2f", ymm / 1e9, sc / 1e9);
#endif
  std::printf("\n");
  std::printf("flops per cycle at that clock: zmm %.1f, ymm %.1f, scalar %.1f\n", zmm / hz,
              ymm / hz, sc / hz);
  return 0;
}
