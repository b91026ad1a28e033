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

// One register kind: its vector type, lanes, and the operations the chains need.
#if defined(__AVX512F__)
struct Zmm {
  using V = __m512d;
  static constexpr int kLanes = 8;
  static V set1(double x) { return _mm512_set1_pd(x); }
  static V fma(V x, V a, V b) { return _mm512_fmadd_pd(x, a, b); }
  static V add(V x, V y) { return _mm512_add_pd(x, y); }
  static double sum(V x) { return _mm512_reduce_add_pd(x); }
};
#endif
#if defined(__AVX2__) && defined(__FMA__)
struct Ymm {
  using V = __m256d;
  static constexpr int kLanes = 4;
  static V set1(double x) { return _mm256_set1_pd(x); }
  static V fma(V x, V a, V b) { return _mm256_fmadd_pd(x, a, b); }
  static V add(V x, V y) { return _mm256_add_pd(x, y); }
  static double sum(V x) {
    alignas(32) double t[4];
    _mm256_store_pd(t, x);
    return t[0] + t[1] + t[2] + t[3];
  }
};
struct Scalar {  // one double in an xmm register (vfmadd...sd)
  using V = __m128d;
  static constexpr int kLanes = 1;
  static V set1(double x) { return _mm_set_sd(x); }
  static V fma(V x, V a, V b) { return _mm_fmadd_sd(x, a, b); }
  static V add(V x, V y) { return _mm_add_sd(x, y); }
  static double sum(V x) { return _mm_cvtsd_f64(x); }
};
#endif

// kChains independent chains of FMAs in registers of kind K, `iters` FMAs each: returns the
// flops it did (2 per lane per FMA). The empty asm after each FMA keeps every chain a
// register that the compiler may not fold or merge ("v": any vector register, zmm16-31
// included).
template <class K>
__attribute__((noinline)) double fma_chains(long iters) {
  typename K::V c[kChains];
#pragma GCC unroll 12
  for (int k = 0; k < kChains; ++k) c[k] = K::set1(1.0 + 0.001 * k);
  const typename K::V a = K::set1(0.999999), b = K::set1(1e-6);
  for (long i = 0; i < iters; ++i) {
#pragma GCC unroll 12
    for (int k = 0; k < kChains; ++k) {
      c[k] = K::fma(c[k], a, b);
      __asm__ volatile("" : "+v"(c[k]));
    }
  }
  typename K::V s = c[0];
#pragma GCC unroll 12
  for (int k = 1; k < kChains; ++k) s = K::add(s, c[k]);
  g_sink = K::sum(s);
  return 2.0 * K::kLanes * kChains * static_cast<double>(iters);
}

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
  zmm = best_rate(fma_chains<Zmm>, iters, reps);
  std::printf(" fma_GFLOPs_zmm=%.2f", zmm / 1e9);
#endif
#if defined(__AVX2__) && defined(__FMA__)
  ymm = best_rate(fma_chains<Ymm>, iters, reps);
  sc = best_rate(fma_chains<Scalar>, iters, reps);
  std::printf(" fma_GFLOPs_ymm=%.2f fma_GFLOPs_scalar=%.2f", ymm / 1e9, sc / 1e9);
#endif
  std::printf("\n");
  std::printf("flops per cycle at that clock: zmm %.1f, ymm %.1f, scalar %.1f\n", zmm / hz,
              ymm / hz, sc / hz);
  return 0;
}
