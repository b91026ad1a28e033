// What the instructions of the SIMD pair loops (sphc --simd-pairs, codegen/SimdPairs.cpp)
// cost on this CPU, per lane against the scalar unit (docs/performance-log.md, "SIMD pair loops
// by the CPU", stop 35): not a test, it prints figures. CPU time of the thread, best of 9.
//   div:  a[i] / b[i] over 1,024 doubles (in L1), `#pragma omp simd` against a loop GCC may
//         not vectorise; sqrt: the same with std::sqrt.
//   gather13: 13 source arrays read at the neighbour indices of a 47^3 lattice (neighbours
//         within 3 spacings: ~87 each, the cube's ~100), as the pair loop reads a neighbour's
//         h, x, y, z, u, v, w, rho, cs, m, p, ...; in lanes (gathers) and scalar.
//   contig13: the same reads in index order (neighbours' values copied contiguous first).
// Build as the solvers are: c++ -std=c++17 -O3 -march=native -fno-math-errno
// -ffp-contract=off -fopenmp-simd bench/simd_lanes_micro.cpp; add -mtune=sapphirerapids
// (or another tuning that allows gathers) to see real gathers where GCC's -march=native tunes
// for `generic` (a CPU model it does not know): then GCC emulates them with scalar loads.
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <vector>
#include <algorithm>

#define NOVEC __attribute__((noinline, optimize("no-tree-vectorize")))
#define VEC __attribute__((noinline))

#include <time.h>
// CPU time of this thread (the machine is shared: wall time would be the load's).
static double now() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

constexpr int N = 1024;
alignas(64) double a[N], b[N];

NOVEC double div_scalar(int reps) {
  double s = 0;
  for (int r = 0; r < reps; ++r)
    for (int i = 0; i < N; ++i) s += a[i] / b[i];
  return s;
}
VEC double div_simd(int reps) {
  double s = 0;
  for (int r = 0; r < reps; ++r) {
#pragma omp simd reduction(+ : s)
    for (int i = 0; i < N; ++i) s += a[i] / b[i];
  }
  return s;
}
NOVEC double sqrt_scalar(int reps) {
  double s = 0;
  for (int r = 0; r < reps; ++r)
    for (int i = 0; i < N; ++i) s += std::sqrt(a[i]);
  return s;
}
VEC double sqrt_simd(int reps) {
  double s = 0;
  for (int r = 0; r < reps; ++r) {
#pragma omp simd reduction(+ : s)
    for (int i = 0; i < N; ++i) s += std::sqrt(a[i]);
  }
  return s;
}
// Several independent sums (no add latency chain in the scalar form).
NOVEC double fma_scalar(int reps) {
  double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
  for (int r = 0; r < reps; ++r)
    for (int i = 0; i < N; i += 4) {
      s0 += a[i] * b[i]; s1 += a[i + 1] * b[i + 1]; s2 += a[i + 2] * b[i + 2]; s3 += a[i + 3] * b[i + 3];
    }
  return s0 + s1 + s2 + s3;
}

constexpr int NA = 13;  // source arrays a lane loop gathers (the cube's loop: 13)
struct Scene {
  int n = 0;
  std::vector<double> arr[NA];
  std::vector<uint32_t> start, nbrs;
};

static const double* P[NA];
#define TREE(j) ((((A[0][j] + A[1][j]) + (A[2][j] + A[3][j])) + ((A[4][j] + A[5][j]) + (A[6][j] + A[7][j]))) + \
                 (((A[8][j] + A[9][j]) + (A[10][j] + A[11][j])) + A[12][j]))
NOVEC double gather_scalar(const Scene& sc) {
  for (int q = 0; q < NA; ++q) P[q] = sc.arr[q].data();
  double s = 0;
  for (int d = 0; d < sc.n; ++d) {
    double acc = 0;
    const uint32_t* L = sc.nbrs.data() + sc.start[d];
    const int m = sc.start[d + 1] - sc.start[d];
    for (int k = 0; k < m; ++k) {
      const uint32_t j = L[k];
      const double* const* A = P;
      acc += TREE(j);
    }
    s += acc;
  }
  return s;
}
VEC double gather_simd(const Scene& sc) {
  const double* A[NA];
  for (int q = 0; q < NA; ++q) A[q] = sc.arr[q].data();
  double s = 0;
  for (int d = 0; d < sc.n; ++d) {
    double acc = 0;
    const uint32_t* L = sc.nbrs.data() + sc.start[d];
    const int m = sc.start[d + 1] - sc.start[d];
#pragma omp simd reduction(+ : acc)
    for (int k = 0; k < m; ++k) {
      const int j = static_cast<int>(L[k]);
      acc += TREE(j);
    }
    s += acc;
  }
  return s;
}
// The same reads in index order (as if the neighbours' values were copied contiguous first).
VEC double contiguous_simd(const Scene& sc) {
  const double* A[NA];
  for (int q = 0; q < NA; ++q) A[q] = sc.arr[q].data();
  double s = 0;
  for (int d = 0; d < sc.n; ++d) {
    double acc = 0;
    const int b0 = std::min(d, sc.n - 200);
    const int m = sc.start[d + 1] - sc.start[d];
#pragma omp simd reduction(+ : acc)
    for (int k = b0; k < b0 + m; ++k)
      acc += TREE(k);
    s += acc;
  }
  return s;
}

int main() {
  for (int i = 0; i < N; ++i) { a[i] = 1.0 + i * 1e-3; b[i] = 2.0 + i * 7e-4; }
  const int reps = 4000;
  const double elems = double(N) * reps;
  auto time = [&](const char* name, auto f, double count, const char* unit) {
    double best = 1e30, v = 0;
    for (int t = 0; t < 9; ++t) {
      const double t0 = now();
      v += f();
      best = std::fmin(best, now() - t0);
    }
    std::printf("%-18s %8.3f ns per %s  (%.3g)\n", name, best / count * 1e9, unit, v);
  };
  time("div scalar", [&] { return div_scalar(reps); }, elems, "division");
  time("div simd", [&] { return div_simd(reps); }, elems, "division");
  time("sqrt scalar", [&] { return sqrt_scalar(reps); }, elems, "sqrt");
  time("sqrt simd", [&] { return sqrt_simd(reps); }, elems, "sqrt");
  time("mul+add scalar", [&] { return fma_scalar(reps); }, elems, "mul+add");
  // A 47^3 lattice (the cube), neighbours within 3 dx (support 2 h, h = 1.5 dx): ~113.
  Scene sc;
  const int nx = 47;
  sc.n = nx * nx * nx;
  for (int q = 0; q < NA; ++q) {
    sc.arr[q].resize(sc.n);
    for (int i = 0; i < sc.n; ++i) sc.arr[q][i] = 1.0 + 1e-6 * i * (q + 1);
  }
  sc.start.push_back(0);
  for (int x = 0; x < nx; ++x)
    for (int y = 0; y < nx; ++y)
      for (int z = 0; z < nx; ++z) {
        for (int X = std::max(0, x - 3); X <= std::min(nx - 1, x + 3); ++X)
          for (int Y = std::max(0, y - 3); Y <= std::min(nx - 1, y + 3); ++Y)
            for (int Z = std::max(0, z - 3); Z <= std::min(nx - 1, z + 3); ++Z) {
              const int dx = X - x, dy = Y - y, dz = Z - z;
              if (dx * dx + dy * dy + dz * dz < 9) sc.nbrs.push_back((X * nx + Y) * nx + Z);
            }
        sc.start.push_back(sc.nbrs.size());
      }
  const double pairs = sc.nbrs.size();
  std::printf("lattice %d particles, %.1f neighbours each\n", sc.n, pairs / sc.n);
  time("gather13 scalar", [&] { return gather_scalar(sc); }, pairs, "pair");
  time("gather13 simd", [&] { return gather_simd(sc); }, pairs, "pair");
  time("contig13 simd", [&] { return contiguous_simd(sc); }, pairs, "pair");
}
