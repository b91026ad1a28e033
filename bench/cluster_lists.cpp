// The runtime's cluster-pair lists (sphc/cluster_pairs.h) on the cube's lattice (bench/cube.sph:
// 47^3 = 103,823 particles, h = 1.5 dx, each coordinate moved by up to +-0.05 dx, in the
// solver's cell order), timed piece by piece: the layout (sort into columns and clusters) and
// the outer list at (1 + skin) 2 h, done at a kept-list rebuild; per evaluation the positions
// and the loop's other source fields into slot order, the boxes, the pruned list at 2 h and the
// sums added back. Thread CPU time, best of --reps rounds (interleaved). Prints the tile
// lanes within the support (pairs within 2 h over pruned cluster pairs x 64) and checks the
// lists against a cell-list count of the pairs within the support (exit 1 if one is missing).
// docs/performance.md, "Cluster-pair lists in the runtime (stop 37)".
//
// Built with the runtime (tests/CMakeLists.txt: cluster_lists_check, serial runtime; ctest
// bench.cluster_lists at nx = 16). Run: cluster_lists [--nx 47] [--hdx 1.5] [--pert 0.05]
//   [--skin 0.1] [--reps 7] [--column DX] [--fields 8] [--sums 7] [--move F] [--dim 3]
// --dim 2: the nx x nx square (2D columns: strips in x sorted by y). --cluster-order: the
// particles first permuted into the layout's slot order (what a solver that sorted its arrays
// into cluster order at each rebuild would have; the gathers then read contiguous runs).
// --move F: before the per-evaluation pieces every particle moves by up to F x skin x 2 h
// (a random direction; F <= 0.5 keeps the outer list complete).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <time.h>

#include "sphc/cluster_pairs.h"

namespace {

double cpu_now() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

struct Cube {
  std::vector<double> x, y, z;
  std::size_t n() const { return x.size(); }
};

// The prototype's lattice (bench/cluster_pairs.cpp make_cube): the same draws for the positions.
// dim = 2: the nx x nx square (z = 0), the same draws per particle.
Cube make_cube(int nx, double hdx, double pert, unsigned seed, int dim = 3) {
  const double dx = 1.0 / nx;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  Cube lat;
  for (int iz = 0; iz < (dim == 3 ? nx : 1); ++iz)
    for (int iy = 0; iy < nx; ++iy)
      for (int ix = 0; ix < nx; ++ix) {
        lat.x.push_back((ix + 0.5) * dx + pert * dx * uni(rng));
        lat.y.push_back((iy + 0.5) * dx + pert * dx * uni(rng));
        lat.z.push_back(dim == 3 ? (iz + 0.5) * dx + pert * dx * uni(rng) : 0.0);
        for (int k = 0; k < 4; ++k) uni(rng);  // u, v, w, rho (as the prototype draws them)
      }
  // The support's cells (side 2 h): the solver's order.
  const double cell = 2.0 * hdx * dx;
  const int nc = static_cast<int>(std::ceil(1.0 / cell)) + 1;
  auto cell_of = [&](std::size_t i) {
    auto c = [&](double q) { return std::clamp(static_cast<int>(std::floor(q / cell)), 0, nc - 1); };
    return (c(lat.z[i]) * nc + c(lat.y[i])) * nc + c(lat.x[i]);
  };
  std::vector<std::size_t> order(lat.n());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return cell_of(a) < cell_of(b); });
  Cube f;
  for (std::size_t o : order) f.x.push_back(lat.x[o]), f.y.push_back(lat.y[o]), f.z.push_back(lat.z[o]);
  return f;
}

// Pairs i < j within `radius` from a grid of cells of side radius (the reference count).
long pairs_within(const Cube& c, double radius) {
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  const std::vector<double>* ax[3] = {&c.x, &c.y, &c.z};
  for (int a = 0; a < 3; ++a)
    for (double v : *ax[a]) lo[a] = std::min(lo[a], v), hi[a] = std::max(hi[a], v);
  int nc[3];
  for (int a = 0; a < 3; ++a) nc[a] = static_cast<int>((hi[a] - lo[a]) / radius) + 1;
  auto cell = [&](std::size_t i, int a) { return std::min(nc[a] - 1, static_cast<int>(((*ax[a])[i] - lo[a]) / radius)); };
  std::vector<std::vector<std::size_t>> cells(static_cast<std::size_t>(nc[0]) * nc[1] * nc[2]);
  for (std::size_t i = 0; i < c.n(); ++i) cells[(cell(i, 2) * nc[1] + cell(i, 1)) * nc[0] + cell(i, 0)].push_back(i);
  long count = 0;
  const double r2 = radius * radius;
  for (std::size_t i = 0; i < c.n(); ++i) {
    const int ci[3] = {cell(i, 0), cell(i, 1), cell(i, 2)};
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int q[3] = {ci[0] + dx, ci[1] + dy, ci[2] + dz};
          if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= nc[0] || q[1] >= nc[1] || q[2] >= nc[2]) continue;
          for (std::size_t j : cells[(q[2] * nc[1] + q[1]) * nc[0] + q[0]]) {
            if (j <= i) continue;
            const double ex = c.x[i] - c.x[j], ey = c.y[i] - c.y[j], ez = c.z[i] - c.z[j];
            count += ex * ex + ey * ey + ez * ez < r2;
          }
        }
  }
  return count;
}

// Pairs within `radius` in the tiles of list l (each pair once: the diagonal tile's j > i),
// from the slot-order positions.
long pairs_in_tiles(const sphc::ClusterLayout& L, const sphc::ClusterPairList& l, const double* xs,
                    const double* ys, const double* zs, double radius) {
  long count = 0;
  const double r2 = radius * radius;
  constexpr int C = sphc::kClusterSize;
  for (std::size_t ci = 0; ci < L.n_clusters; ++ci)
    for (std::uint32_t e = l.begin[ci]; e < l.begin[ci + 1]; ++e) {
      const std::size_t cj = l.j[e];
      for (std::size_t i = ci * C; i < ci * C + C; ++i) {
        if (L.slot[i] == sphc::kPadSlot) continue;
        for (std::size_t j = cj * C; j < cj * C + C; ++j) {
          if (L.slot[j] == sphc::kPadSlot || (cj == ci && j <= i)) continue;
          const double ex = xs[i] - xs[j], ey = ys[i] - ys[j], ez = zs[i] - zs[j];
          count += ex * ex + ey * ey + ez * ez < r2;
        }
      }
    }
  return count;
}

}  // namespace

int main(int argc, char** argv) {
  int nx = 47, reps = 7, fields = 8, sums = 7, dim = 3;
  bool cluster_order = false;
  double hdx = 1.5, pert = 0.05, skin = 0.1, column = 0, move = 0.5;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    auto next = [&]() -> const char* {
      if (k + 1 >= argc) std::exit(2);
      return argv[++k];
    };
    if (a == "--nx") nx = std::atoi(next());
    else if (a == "--reps") reps = std::atoi(next());
    else if (a == "--hdx") hdx = std::atof(next());
    else if (a == "--pert") pert = std::atof(next());
    else if (a == "--skin") skin = std::atof(next());
    else if (a == "--column") column = std::atof(next());
    else if (a == "--fields") fields = std::atoi(next());
    else if (a == "--sums") sums = std::atoi(next());
    else if (a == "--move") move = std::atof(next());
    else if (a == "--dim") dim = std::atoi(next());
    else if (a == "--cluster-order") cluster_order = true;
    else {
      std::fprintf(stderr, "usage: %s [--nx 47] [--hdx 1.5] [--pert 0.05] [--skin 0.1] [--reps 7] [--column DX]"
                           " [--fields 8] [--sums 7] [--move 0.5] [--dim 3] [--cluster-order]\n", argv[0]);
      return 2;
    }
  }
  const double dx = 1.0 / nx, h = hdx * dx, support = 2.0 * h, rlist = (1.0 + skin) * support;
  if (dim != 2 && dim != 3) return 2;
  const double side = column > 0 ? column * dx : 0.0;
  Cube cube = make_cube(nx, hdx, pert, 12345, dim);
  const std::size_t n = cube.n();
  if (cluster_order) {  // the particles permuted into the layout's slot order (padding left out)
    sphc::ClusterLayout first;
    sphc::build_cluster_layout(first, cube.x.data(), cube.y.data(), cube.z.data(), n, dim, side);
    Cube sorted;
    for (std::uint32_t p : first.slot)
      if (p != sphc::kPadSlot) sorted.x.push_back(cube.x[p]), sorted.y.push_back(cube.y[p]), sorted.z.push_back(cube.z[p]);
    cube = sorted;
  }
  Cube moved = cube;
  {
    std::mt19937_64 rng(777);
    std::normal_distribution<double> g;
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (std::size_t i = 0; i < n; ++i) {
      const double d[3] = {g(rng), g(rng), dim == 3 ? g(rng) : 0.0};
      const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      const double s = move * skin * support * u(rng) / len;
      moved.x[i] += s * d[0], moved.y[i] += s * d[1], moved.z[i] += s * d[2];
    }
  }
  std::printf("%s nx = %d: %zu particles, h = %.3g dx, positions +-%.3g dx; list radius %.2f h, support 2 h;"
              " per evaluation %d source fields besides x, y, z and %d sums; particles moved by up to %.2f x skin x 2h\n",
              dim == 3 ? "cube" : "square (2D)", nx, n, hdx, pert, rlist / h, fields, sums, move);

  sphc::ClusterLayout L;
  sphc::ClusterPairList outer, pruned;
  std::vector<double> xs, ys, zs;
  std::vector<std::vector<double>> src(fields, std::vector<double>(n, 1.0)), dst(fields);
  std::vector<std::vector<double>> acc(sums), back(sums, std::vector<double>(n, 0.0));
  enum { LAYOUT, PAIRS, POSITIONS, FIELDS, BOXES, PRUNE, ADD, NPIECES };
  const char* names[NPIECES] = {"layout (sort into columns, clusters)", "outer list at (1 + skin) 2 h",
                                "gather positions (x, y, z in 3D)", "gather other fields", "update boxes", "prune to 2 h",
                                "add sums back"};
  std::vector<double> best(NPIECES, 1e30);
  for (int r = 0; r < reps; ++r) {
    double t = cpu_now(), t1;
    auto lap = [&](int piece) {
      t1 = cpu_now();
      best[piece] = std::min(best[piece], t1 - t);
      t = t1;
    };
    sphc::build_cluster_layout(L, cube.x.data(), cube.y.data(), cube.z.data(), n, dim, side);
    lap(LAYOUT);
    sphc::build_cluster_pairs(L, L, rlist, true, outer);
    lap(PAIRS);
    xs.resize(L.slots()), ys.resize(L.slots()), zs.resize(L.slots());
    for (auto& d : dst) d.resize(L.slots());
    for (auto& s : acc) s.assign(L.slots(), 1.0);
    t = cpu_now();
    sphc::gather_positions(L, moved.x.data(), moved.y.data(), moved.z.data(), xs.data(), ys.data(), zs.data(),
                           4 * support);
    lap(POSITIONS);
    for (int f = 0; f < fields; ++f) sphc::gather_slots(L, src[f].data(), dst[f].data());
    lap(FIELDS);
    sphc::update_boxes(L, xs.data(), ys.data(), zs.data());
    lap(BOXES);
    sphc::prune_cluster_pairs(L, L, outer, support, pruned);
    lap(PRUNE);
    for (int s = 0; s < sums; ++s) sphc::add_slots(L, acc[s].data(), back[s].data());
    lap(ADD);
  }
  double per_eval = 0, rebuild = best[LAYOUT] + best[PAIRS];
  for (int p = POSITIONS; p < NPIECES; ++p) per_eval += best[p];
  std::printf("clusters: %zu (%zu slots, %.1f%% padding), columns %zu x %zu of side %.2f dx\n", L.n_clusters,
              L.slots(), 100.0 * (L.slots() - n) / n, L.columns[0], L.columns[1], L.column_side / dx);
  std::printf("\n%-40s %10s\n", "piece (thread CPU time, best of reps)", "ms");
  for (int p = 0; p < NPIECES; ++p) std::printf("%-40s %10.3f\n", names[p], 1e3 * best[p]);
  std::printf("%-40s %10.3f\n%-40s %10.3f\n", "at a rebuild (layout + outer list)", 1e3 * rebuild,
              "per evaluation (gathers, boxes, prune, add)", 1e3 * per_eval);

  // Lanes within the support; completeness.
  const long ref = pairs_within(moved, support);
  const long in_pruned = pairs_in_tiles(L, pruned, xs.data(), ys.data(), zs.data(), support);
  const long in_outer = pairs_in_tiles(L, outer, xs.data(), ys.data(), zs.data(), support);
  std::printf("\npairs within 2 h (cell-list count): %ld (%.1f ordered neighbours per particle)\n", ref,
              2.0 * ref / n);
  std::printf("outer list: %zu cluster pairs (%.1f per i-cluster), %.1f%% of the tile lanes within the support\n",
              outer.pairs(), double(outer.pairs()) / L.n_clusters, 100.0 * in_outer / (64.0 * outer.pairs()));
  std::printf("pruned list: %zu cluster pairs (%.1f per i-cluster), %.1f%% of the tile lanes within the support\n",
              pruned.pairs(), double(pruned.pairs()) / L.n_clusters, 100.0 * in_pruned / (64.0 * pruned.pairs()));
  if (in_pruned != ref || in_outer != ref) {
    std::printf("FAILED: the lists hold %ld (pruned) and %ld (outer) of the %ld pairs within the support\n",
                in_pruned, in_outer, ref);
    return 1;
  }
  std::printf("OK: every pair within the support in both lists\n");
  return 0;
}
