// stream_triad.cpp: memory bandwidth of this machine, the STREAM triad a[i] = b[i] + s c[i]
// over arrays far larger than the caches; used by bench/roofline.py. Counts 24 bytes per
// element (two reads, one write; a write-allocate read of a[] would add 8 more, not counted,
// as STREAM does not). Prints "triad_GBps=<best of the repetitions>".
//   c++ -O3 -march=native -fopenmp bench/stream_triad.cpp -o triad && OMP_NUM_THREADS=2 ./triad
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

int main(int argc, char** argv) {
  const long n = argc > 1 ? std::atol(argv[1]) : 20000000L;  // 3 x 160 MB
  const int reps = argc > 2 ? std::atoi(argv[2]) : 10;
  std::vector<double> a(n), b(n), c(n);
#pragma omp parallel for schedule(static)
  for (long i = 0; i < n; ++i) {  // first touch by the threads that use them
    a[i] = 0.0;
    b[i] = 1.0;
    c[i] = 2.0;
  }
  double best = 0.0;
  const double s = 3.0;
  for (int r = 0; r < reps; ++r) {
    auto t0 = std::chrono::steady_clock::now();
#pragma omp parallel for schedule(static)
    for (long i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
    auto t1 = std::chrono::steady_clock::now();
    double sec = std::chrono::duration<double>(t1 - t0).count();
    double gbps = 24.0 * n / sec / 1e9;
    if (gbps > best) best = gbps;
  }
  double check = 0.0;
  for (long i = 0; i < n; i += n / 16) check += a[i];
  std::printf("triad_GBps=%.2f n=%ld check=%g\n", best, n, check);
  return 0;
}
