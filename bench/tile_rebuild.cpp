// The OpenMP tiles' rebuild path (issue 16, stop 41; docs/performance-log.md, "The OpenMP
// speed-up on 2 cores: the tiles' blocks and their rebuild (stop 41)"): on the cube's lattice
// (bench/cube.sph: nx^3 particles, h = 1.5 dx, each coordinate moved by up to +-0.05 dx) the
// pieces a solver with cluster-pair tiles runs when the particles are put in the tiles' slot
// order and the lists rebuilt (sphc/cluster_pairs.h: cluster_order, ParticleArray::permute of
// 25 properties, the printed largest-h loop, build_cluster_layout_in_order, the outer list at
// 1.1 x 2 h, the pruning at 2 h, the blocks' cuts), and the search domain and cell list that
// the printed code built for the tiles before stop 41 (unused by them). Per piece the CPU of
// one thread, and at 2 threads the calling thread's CPU and the process's (OMP_WAIT_POLICY=
// passive: an idle thread sleeps); "model": one thread's CPU over the larger of the calling
// thread's and half the process's, the speed-up the piece allows on 2 cores. Minima of --reps
// rounds, 1 and 2 threads interleaved. CPU time: repeatable under the other jobs' load.
//
// Build (from the repository root, after the CMake build):
//   c++ -std=c++17 -O3 -fopenmp -I build/include bench/tile_rebuild.cpp \
//     build/lib/libsphc_runtime_omp.a -lfmt -o tile_rebuild
// Run: OMP_WAIT_POLICY=passive ./tile_rebuild [nx = 47] [reps = 5]
#include <omp.h>
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "sphc/cluster_pairs.h"
#include "sphc/nnps.h"
#include "sphc/particle_array.h"

namespace {

double cpu(clockid_t clock) {
  timespec ts;
  clock_gettime(clock, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
  const int nx = argc > 1 ? std::atoi(argv[1]) : 47;
  const int reps = argc > 2 ? std::atoi(argv[2]) : 5;
  const double dx = 1.0 / nx, h = 1.5 * dx;
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  sphc::ParticleArray a;
  a.name = "fluid";
  for (int k = 0; k < 25; ++k)
    a.add_property(k == 0 ? "x" : k == 1 ? "y" : k == 2 ? "z" : k == 5 ? "h" : "p" + std::to_string(k));
  const std::size_t n = static_cast<std::size_t>(nx) * nx * nx;
  a.resize(n);
  std::size_t i = 0;
  for (int z = 0; z < nx; ++z)
    for (int y = 0; y < nx; ++y)
      for (int x = 0; x < nx; ++x, ++i) {
        a.f64(0)[i] = (x + 0.5 + u(rng)) * dx;
        a.f64(1)[i] = (y + 0.5 + u(rng)) * dx;
        a.f64(2)[i] = (z + 0.5 + u(rng)) * dx;
        for (int k = 3; k < 25; ++k) a.f64(k)[i] = k == 5 ? h : static_cast<double>(i);
      }
  std::vector<std::uint32_t> order;
  sphc::ClusterLayout L;
  sphc::ClusterPairList outer, pruned;
  std::vector<int> cut;
  sphc::CellList cells;
  double hmax = 0;
  struct Piece {
    const char* name;
    std::function<void()> run;
  };
  const std::vector<Piece> pieces = {
      {"cluster_order", [&] { sphc::cluster_order(order, a.f64(0), a.f64(1), a.f64(2), n, 3, 0.0, 8); }},
      {"permute (25 properties)", [&] { a.permute(order); }},
      {"largest h (printed loop)", [&] {
         double m = 0;
         const double* hh = a.f64(5);
#pragma omp parallel for schedule(static) reduction(max : m)
         for (long p = 0; p < static_cast<long>(n); ++p) m = std::max(m, hh[p]);
         hmax = m;
       }},
      {"build_cluster_layout_in_order", [&] { sphc::build_cluster_layout_in_order(L, a.f64(0), a.f64(1), a.f64(2), n, 3, 0.0, 8); }},
      {"update_boxes", [&] { sphc::update_boxes(L, a.f64(0), a.f64(1), a.f64(2)); }},
      {"build_cluster_pairs (outer)", [&] { sphc::build_cluster_pairs(L, L, 2.0 * 1.1 * hmax, true, outer); }},
      {"prune_cluster_pairs", [&] { sphc::prune_cluster_pairs(L, L, outer, 2.0 * hmax, pruned); }},
      {"tile_block_cuts", [&] { sphc::tile_block_cuts(pruned, omp_get_max_threads(), cut); }},
      {"(domain + cells: before stop 41)", [&] {
         const std::vector<const sphc::ParticleArray*> all = {&a};
         const sphc::SearchDomain d = sphc::make_search_domain(all, 3, 2.0 * 1.1);
         cells.build(d, a.f64(0), a.f64(1), a.f64(2), n);
       }},
  };
  std::vector<double> one(pieces.size(), 1e30), t0(pieces.size(), 1e30), all(pieces.size(), 1e30);
  for (int r = 0; r < reps; ++r)
    for (int threads : {1, 2}) {
      omp_set_num_threads(threads);
      for (std::size_t p = 0; p < pieces.size(); ++p) {
        const double a0 = cpu(CLOCK_THREAD_CPUTIME_ID), b0 = cpu(CLOCK_PROCESS_CPUTIME_ID);
        pieces[p].run();
        const double a1 = cpu(CLOCK_THREAD_CPUTIME_ID) - a0, b1 = cpu(CLOCK_PROCESS_CPUTIME_ID) - b0;
        if (threads == 1) {
          one[p] = std::min(one[p], b1);
        } else {
          t0[p] = std::min(t0[p], a1);
          all[p] = std::min(all[p], b1);
        }
      }
    }
  std::printf("n = %zu, clusters %zu, outer list %zu, pruned %zu cluster pairs; minima of %d rounds, ms CPU\n",
              n, L.n_clusters, outer.pairs(), pruned.pairs(), reps);
  std::printf("%-34s %9s %12s %12s %8s\n", "piece", "1 thread", "2: calling", "2: process", "model");
  double s1 = 0, s2 = 0;
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    const double two = std::max(t0[p], all[p] / 2);
    std::printf("%-34s %9.3f %12.3f %12.3f %7.2fx\n", pieces[p].name, 1e3 * one[p], 1e3 * t0[p],
                1e3 * all[p], one[p] / two);
    if (p + 1 < pieces.size()) s1 += one[p], s2 += two;
  }
  std::printf("%-34s %9.3f %12.3f %12s %7.2fx\n", "the path (without the cells)", 1e3 * s1, 1e3 * s2, "",
              s1 / s2);
  return 0;
}
