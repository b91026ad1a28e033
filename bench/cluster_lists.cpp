// The runtime's cluster-pair lists (sphc/cluster_pairs.h) on the cube's lattice (bench/cube.sph:
// 47^3 = 103,823 particles, h = 1.5 dx, each coordinate moved by up to +-0.05 dx, in the
// solver's cell order), timed piece by piece: the layout (sort into columns and clusters) and
// the outer list at (1 + skin) 2 h, done at a kept-list rebuild; per evaluation the positions
// and the loop's other source fields into slot order, the boxes, the pruned list at 2 h and the
// sums added back. Thread CPU time, best of --reps rounds (interleaved). Prints the tile
// lanes within the support (pairs within 2 h over pruned cluster pairs x 64) and checks the
// lists against a cell-list count of the pairs within the support (exit 1 if one is missing).
// docs/performance-log.md, "Cluster-pair lists in the runtime (stop 37)".
//
// Built with the runtime (tests/CMakeLists.txt: cluster_lists_check, serial runtime; ctest
// bench.cluster_lists at nx = 16). Run: cluster_lists [--nx 47] [--hdx 1.5] [--pert 0.05]
//   [--skin 0.1] [--reps 7] [--column DX] [--fields 8] [--sums 7] [--move F] [--dim 3]
// --dim 2: the nx x nx square (2D columns: strips in x sorted by y). --cluster-order: the
// particles first permuted into the layout's slot order (what a solver that sorted its arrays
// into cluster order at each rebuild would have; the gathers then read contiguous runs).
// --move F: before the per-evaluation pieces every particle moves by up to F x skin x 2 h
// (a random direction; F <= 0.5 keeps the outer list complete).
// --width W: the layout's cluster width (sphc::ClusterLayout::width; default 8).
// --fill: also the tile shapes' fill (docs/performance-log.md, "SIMD tiles in 2D, measured by hand
// (stop 38)"): per shape (i-cluster x j-cluster: 8x8, 4x8 = the halves of an 8-cluster x an
// 8-cluster, 4x4, 2x4 and GROMACS' 2xMM = a 4x4 tile in two registers of 2 i's x 4 j's, 2x2,
// 1x8) the lanes within the support over the lanes computed, every tile's lanes or only the
// rows (registers) with a pair, and the registers of 8 lanes per particle; at the build's
// positions and after the move; and today's each-pair-once lanes over the kept lists (a
// particle's list entries above it, in chunks of 8). --ny NY: a rectangle of nx x ny in 2D
// (the dam break's water column at dx = 0.03: --nx 33 --ny 66). --positions FILE: the
// particles from a text file (x y [z] per line; --dx its spacing, h = hdx dx), e.g. a
// snapshot of a run; --dx also scales the lattice (default 1 / nx). --flush MB: a buffer of
// MB written before each per-evaluation piece (cold caches, as in a solver); the pieces of
// stop 39 in one call each (gather_positions_boxes, gather_slots and add_slots of several
// arrays) are timed after the others.
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

#include "bench_options.h"
#include "bench_tiles.h"
#include "sphc/cluster_pairs.h"

namespace {

using bench::tiles::cpu_now;

struct Cube {
  std::vector<double> x, y, z;
  std::size_t n() const { return x.size(); }
};

// The prototype's lattice (bench/cluster_pairs.cpp make_cube): the same draws for the positions.
// dim = 2: the nx x nx square (z = 0), the same draws per particle.
Cube make_cube(int nx, double hdx, double pert, unsigned seed, int dim = 3, int ny = 0, double dx = 0) {
  if (!(dx > 0)) dx = 1.0 / nx;
  if (ny <= 0 || dim == 3) ny = nx;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  Cube lat;
  for (int iz = 0; iz < (dim == 3 ? nx : 1); ++iz)
    for (int iy = 0; iy < ny; ++iy)
      for (int ix = 0; ix < nx; ++ix) {
        lat.x.push_back((ix + 0.5) * dx + pert * dx * uni(rng));
        lat.y.push_back((iy + 0.5) * dx + pert * dx * uni(rng));
        lat.z.push_back(dim == 3 ? (iz + 0.5) * dx + pert * dx * uni(rng) : 0.0);
        for (int k = 0; k < 4; ++k) uni(rng);  // u, v, w, rho (as the prototype draws them)
      }
  // The support's cells (side 2 h): the solver's order.
  const double cell = 2.0 * hdx * dx;
  const int nc = static_cast<int>(std::ceil(std::max(nx, ny) * dx / cell)) + 1;
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
  const std::size_t C = static_cast<std::size_t>(L.width);
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

// Particles from a text file: x y [z] per line ('#' lines skipped).
Cube read_positions(const std::string& path, int dim) {
  Cube c;
  FILE* f = std::fopen(path.c_str(), "r");
  if (!f) return c;
  char line[512];
  while (std::fgets(line, sizeof line, f)) {
    if (line[0] == '#') continue;
    double v[3] = {0, 0, 0};
    const int got = std::sscanf(line, "%lf %lf %lf", &v[0], &v[1], &v[2]);
    if (got < dim) continue;
    c.x.push_back(v[0]), c.y.push_back(v[1]), c.z.push_back(dim == 3 ? v[2] : 0.0);
  }
  std::fclose(f);
  return c;
}

// A tile shape over a layout of width W: i-parts of iw slots of an i-cluster (iw divides W; a
// part kept per cluster pair where its own box lies within the list's radius of the j box) x
// the j-cluster's W slots, computed in registers of ri i's x W j's.
struct TileCount {
  long tiles = 0, regs = 0, regs_with_pair = 0, pairs = 0;
};

// Positions in slot order: xs, ys, zs (now, for the pairs and the j boxes in L.box) and bx,
// by, bz (where the i-parts' boxes are taken: the build's for an outer list).
TileCount count_tiles(const sphc::ClusterLayout& L, const sphc::ClusterPairList& l, int iw, int ri,
                      const double* xs, const double* ys, const double* zs, const double* bx,
                      const double* by, const double* bz, const double* jbox, double part_radius,
                      double support) {
  TileCount t;
  const std::size_t W = static_cast<std::size_t>(L.width);
  const double s2 = support * support, p2 = part_radius * part_radius * (1 + 1e-12);
  for (std::size_t ci = 0; ci < L.n_clusters; ++ci)
    for (std::uint32_t e = l.begin[ci]; e < l.begin[ci + 1]; ++e) {
      const std::size_t cj = l.j[e];
      const double* jb = jbox + 6 * cj;
      for (std::size_t p0 = ci * W; p0 < ci * W + W; p0 += iw) {
        // The part's box (real slots only); none: no tile.
        double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
        bool any = false;
        for (std::size_t i = p0; i < p0 + iw; ++i) {
          if (L.slot[i] == sphc::kPadSlot) continue;
          any = true;
          const double q[3] = {bx[i], by[i], L.dim == 3 ? bz[i] : 0.0};
          for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], q[a]), hi[a] = std::max(hi[a], q[a]);
        }
        if (!any) continue;
        if (static_cast<std::size_t>(iw) < W) {
          double d2 = 0;
          for (int a = 0; a < 3; ++a) {
            const double g = std::max({0.0, jb[a] - hi[a], lo[a] - jb[3 + a]});
            d2 += g * g;
          }
          if (d2 > p2) continue;
        }
        ++t.tiles;
        for (std::size_t r0 = p0; r0 < p0 + iw; r0 += ri) {
          bool pair = false;
          for (std::size_t i = r0; i < r0 + ri; ++i)
            for (std::size_t j = cj * W; j < cj * W + W; ++j) {
              if (L.slot[i] == sphc::kPadSlot || L.slot[j] == sphc::kPadSlot || (cj == ci && j <= i)) continue;
              const double ex = xs[i] - xs[j], ey = ys[i] - ys[j], ez = L.dim == 3 ? zs[i] - zs[j] : 0.0;
              if (ex * ex + ey * ey + ez * ez < s2) ++t.pairs, pair = true;
            }
          ++t.regs;
          t.regs_with_pair += pair;
        }
      }
    }
  return t;
}

// The fill of the tile shapes (--fill; see the file's comment). Returns 1 if a list misses a
// pair within the support.
int fill_report(const Cube& built, const Cube& moved, int dim, double side, double support, double rlist) {
  const std::size_t n = built.n();
  const long ref_built = pairs_within(built, support), ref_moved = pairs_within(moved, support);
  int bad = 0;
  std::printf("\nTILE FILL (lanes within the support / lanes computed; 'rows': only the registers with a pair"
              " computed; regs/particle: registers of 8 lanes (4 for AVX2 rows) per particle and sweep)\n");
  std::printf("%-10s %-34s %-9s %9s %9s %9s %9s %11s %11s\n", "state", "shape", "list", "tiles", "fill all",
              "fill rows", "rows full", "regs/part", "rows/part");
  struct Shape {
    const char* name;
    int width, iw, ri, lanes;  // layout width, i-part, i's per register, lanes per register
  };
  const Shape shapes[] = {
      {"8x8 (rows 1 i x 8 j)", 8, 8, 1, 8},
      {"4x8 (halves of 8-clusters; rows 1x8)", 8, 4, 1, 8},
      {"2x8 (rows 1x8)", 8, 2, 1, 8},
      {"1x8 (rows 1x8)", 8, 1, 1, 8},
      {"4x4 2xMM (zmm = 2 i x 4 j)", 4, 4, 2, 8},
      {"4x4 AVX2 (ymm rows 1 i x 4 j)", 4, 4, 1, 4},
      {"2x4 (zmm = 2 i x 4 j)", 4, 2, 2, 8},
  };
  for (int state = 0; state < 2; ++state) {
    const Cube& now = state ? moved : built;
    const long ref = state ? ref_moved : ref_built;
    const char* sname = state ? "moved" : "at build";
    for (int w : {8, 4}) {
      sphc::ClusterLayout L;
      sphc::build_cluster_layout(L, built.x.data(), built.y.data(), built.z.data(), n, dim,
                                 side > 0 ? side * std::pow(w / 8.0, 1.0 / dim) : 0.0, w);
      sphc::ClusterPairList outer, pruned;
      sphc::build_cluster_pairs(L, L, rlist, true, outer);
      const std::vector<double> build_box = L.box;
      const std::size_t S = L.slots();
      std::vector<double> bx(S), by(S), bz(S), xs(S), ys(S), zs(S);
      sphc::gather_positions(L, built.x.data(), built.y.data(), built.z.data(), bx.data(), by.data(), bz.data(),
                             4 * rlist);
      sphc::gather_positions(L, now.x.data(), now.y.data(), now.z.data(), xs.data(), ys.data(), zs.data(),
                             4 * rlist);
      sphc::update_boxes(L, xs.data(), ys.data(), zs.data());
      sphc::prune_cluster_pairs(L, L, outer, support, pruned);
      for (const Shape& sh : shapes) {
        if (sh.width != w) continue;
        for (int which = 0; which < 2; ++which) {
          // pruned: the i-parts against the j boxes now at the support; outer: at the list
          // radius with the build's boxes.
          const TileCount t =
              which == 0 ? count_tiles(L, pruned, sh.iw, sh.ri, xs.data(), ys.data(), zs.data(), xs.data(), ys.data(),
                                       zs.data(), L.box.data(), support, support)
                         : count_tiles(L, outer, sh.iw, sh.ri, xs.data(), ys.data(), zs.data(), bx.data(), by.data(),
                                       bz.data(), build_box.data(), rlist, support);
          if (t.pairs != ref) {
            std::printf("FAILED: %s %s list holds %ld of %ld pairs\n", sh.name, which ? "outer" : "pruned", t.pairs, ref);
            bad = 1;
          }
          const double lanes = double(t.tiles) * sh.iw * w;
          std::printf("%-10s %-34s %-9s %9ld %8.1f%% %8.1f%% %8.1f%% %11.2f %11.2f\n", sname, sh.name,
                      which ? "outer" : "pruned", t.tiles, 100.0 * t.pairs / lanes,
                      100.0 * t.pairs / (double(t.regs_with_pair) * sh.lanes),
                      100.0 * t.regs_with_pair / double(t.regs), double(t.regs) / n, double(t.regs_with_pair) / n);
        }
      }
    }
    // Today's each-pair-once lanes: particle i's kept list (within rlist at the build) above
    // i in chunks of 8; the scalar loop tests each entry.
    {
      std::vector<long> above(n, 0);
      const double r2 = rlist * rlist, s2 = support * support;
      long pairs = 0, entries = 0, vectors = 0;
      // O(n^2)-free: cells of side rlist.
      double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
      const std::vector<double>* ax[3] = {&built.x, &built.y, &built.z};
      for (int a = 0; a < 3; ++a)
        for (double v : *ax[a]) lo[a] = std::min(lo[a], v), hi[a] = std::max(hi[a], v);
      int nc[3];
      for (int a = 0; a < 3; ++a) nc[a] = static_cast<int>((hi[a] - lo[a]) / rlist) + 1;
      auto cell = [&](std::size_t i, int a) {
        return std::min(nc[a] - 1, static_cast<int>(((*ax[a])[i] - lo[a]) / rlist));
      };
      std::vector<std::vector<std::size_t>> cells(static_cast<std::size_t>(nc[0]) * nc[1] * nc[2]);
      for (std::size_t i = 0; i < n; ++i) cells[(cell(i, 2) * nc[1] + cell(i, 1)) * nc[0] + cell(i, 0)].push_back(i);
      for (std::size_t i = 0; i < n; ++i) {
        const int c[3] = {cell(i, 0), cell(i, 1), cell(i, 2)};
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dxx = -1; dxx <= 1; ++dxx) {
              const int q[3] = {c[0] + dxx, c[1] + dy, c[2] + dz};
              if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= nc[0] || q[1] >= nc[1] || q[2] >= nc[2]) continue;
              for (std::size_t j : cells[(q[2] * nc[1] + q[1]) * nc[0] + q[0]]) {
                if (j <= i) continue;
                const double ex = built.x[i] - built.x[j], ey = built.y[i] - built.y[j], ez = built.z[i] - built.z[j];
                if (!(ex * ex + ey * ey + ez * ez < r2)) continue;
                ++above[i];
                const double fx = now.x[i] - now.x[j], fy = now.y[i] - now.y[j], fz = now.z[i] - now.z[j];
                pairs += fx * fx + fy * fy + fz * fz < s2;
              }
            }
      }
      for (std::size_t i = 0; i < n; ++i) entries += above[i], vectors += (above[i] + 7) / 8;
      std::printf("%-10s %-34s %-9s %9s %8.1f%% %9s %9s %11.2f %11s   (%.1f entries above i per particle)\n", sname,
                  "kept lists j > i, 8 lanes", "kept", "-", 100.0 * pairs / (8.0 * vectors), "-", "-",
                  double(vectors) / n, "-", double(entries) / n);
      if (pairs != ref) {
        std::printf("FAILED: the kept lists hold %ld of %ld pairs\n", pairs, ref);
        bad = 1;
      }
    }
  }
  std::printf("pairs within the support: %ld at the build, %ld moved (%.1f, %.1f ordered neighbours per particle)\n",
              ref_built, ref_moved, 2.0 * ref_built / n, 2.0 * ref_moved / n);
  return bad;
}

}  // namespace

int main(int argc, char** argv) {
  int nx = 47, ny = 0, reps = 7, fields = 8, sums = 7, dim = 3, width = sphc::kClusterSize;
  bool cluster_order = false, fill = false;
  double hdx = 1.5, pert = 0.05, skin = 0.1, column = 0, move = 0.5, dx_arg = 0, flush_mb = 0;
  std::string positions;
  bench::Options opts;
  opts.value("--nx", nx).value("--reps", reps).value("--hdx", hdx).value("--pert", pert);
  opts.value("--skin", skin).value("--column", column).value("--fields", fields);
  opts.value("--sums", sums).value("--move", move).value("--dim", dim);
  opts.flag("--cluster-order", cluster_order).value("--width", width).flag("--fill", fill);
  opts.value("--ny", ny).value("--dx", dx_arg).value("--positions", positions);
  opts.value("--flush", flush_mb);
  if (!opts.parse(argc, argv,
                  "[--nx 47] [--hdx 1.5] [--pert 0.05] [--skin 0.1] [--reps 7] [--column DX]"
                  " [--fields 8] [--sums 7] [--move 0.5] [--dim 3] [--cluster-order]"
                  " [--width 8] [--fill] [--ny NY] [--dx DX] [--positions FILE] [--flush MB]"))
    return 2;
  const double dx = dx_arg > 0 ? dx_arg : 1.0 / nx, h = hdx * dx, support = 2.0 * h,
               rlist = (1.0 + skin) * support;
  if (dim != 2 && dim != 3) return 2;
  if (width < 1 || width > sphc::kMaxClusterSize) return 2;
  const double side = column > 0 ? column * dx : 0.0;
  Cube cube;
  if (!positions.empty()) {
    cube = read_positions(positions, dim);
    if (cube.n() == 0) {
      std::fprintf(stderr, "no particles in %s\n", positions.c_str());
      return 2;
    }
  } else {
    cube = make_cube(nx, hdx, pert, 12345, dim, ny, dx);
  }
  const std::size_t n = cube.n();
  if (cluster_order) {  // the particles permuted into the layout's slot order (padding left out)
    sphc::ClusterLayout first;
    sphc::build_cluster_layout(first, cube.x.data(), cube.y.data(), cube.z.data(), n, dim, side, width);
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
  if (!positions.empty())
    std::printf("%s (%dD, dx = %g): %zu particles, h = %.3g dx;", positions.c_str(), dim, dx, n, hdx);
  else
    std::printf("%s nx = %d%s: %zu particles, h = %.3g dx, positions +-%.3g dx;",
                dim == 3 ? "cube" : ny > 0 ? "rectangle (2D)" : "square (2D)", nx,
                ny > 0 ? (" x " + std::to_string(ny)).c_str() : "", n, hdx, pert);
  std::printf(" list radius %.2f h, support 2 h; cluster width %d;"
              " per evaluation %d source fields besides x, y, z and %d sums; particles moved by up to %.2f x skin x 2h\n",
              rlist / h, width, fields, sums, move);

  sphc::ClusterLayout L;
  sphc::ClusterPairList outer, pruned;
  std::vector<double> xs, ys, zs;
  std::vector<std::vector<double>> src(fields, std::vector<double>(n, 1.0)), dst(fields);
  std::vector<std::vector<double>> acc(sums), back(sums, std::vector<double>(n, 0.0));
  enum { LAYOUT, PAIRS, POSITIONS, FIELDS, BOXES, PRUNE, ADD, POS_BOXES, FIELDS_1, ADD_1, NPIECES };
  const char* names[NPIECES] = {"layout (sort into columns, clusters)", "outer list at (1 + skin) 2 h",
                                "gather positions (x, y, z in 3D)", "gather other fields", "update boxes", "prune to 2 h",
                                "add sums back", "(stop 39) positions + boxes, one pass", "(stop 39) other fields, one call",
                                "(stop 39) sums back, one call"};
  // --flush MB: a buffer written before each piece, so that each starts with cold caches (as
  // in a solver, whose tiles evict the copies between the pieces).
  std::vector<double> flush_buf(static_cast<std::size_t>(flush_mb * (1 << 20) / 8), 0.0);
  auto flush = [&]() {
    for (std::size_t k = 0; k < flush_buf.size(); k += 8) flush_buf[k] += 1.0;
  };
  std::vector<double> best(NPIECES, 1e30);
  for (int r = 0; r < reps; ++r) {
    double t = cpu_now(), t1;
    auto lap = [&](int piece) {
      t1 = cpu_now();
      best[piece] = std::min(best[piece], t1 - t);
      t = t1;
    };
    sphc::build_cluster_layout(L, cube.x.data(), cube.y.data(), cube.z.data(), n, dim, side, width);
    lap(LAYOUT);
    sphc::build_cluster_pairs(L, L, rlist, true, outer);
    lap(PAIRS);
    xs.resize(L.slots()), ys.resize(L.slots()), zs.resize(L.slots());
    for (auto& d : dst) d.resize(L.slots());
    for (auto& s : acc) s.assign(L.slots(), 1.0);
    std::vector<const double*> from(fields), sums_from(sums);
    std::vector<double*> to(fields), into(sums);
    for (int f = 0; f < fields; ++f) from[f] = src[f].data(), to[f] = dst[f].data();
    for (int s = 0; s < sums; ++s) sums_from[s] = acc[s].data(), into[s] = back[s].data();
    flush();
    t = cpu_now();
    sphc::gather_positions(L, moved.x.data(), moved.y.data(), moved.z.data(), xs.data(), ys.data(), zs.data(),
                           4 * support);
    lap(POSITIONS);
    flush();
    t = cpu_now();
    for (int f = 0; f < fields; ++f) sphc::gather_slots(L, src[f].data(), dst[f].data());
    lap(FIELDS);
    flush();
    t = cpu_now();
    sphc::update_boxes(L, xs.data(), ys.data(), zs.data());
    lap(BOXES);
    flush();
    t = cpu_now();
    sphc::prune_cluster_pairs(L, L, outer, support, pruned);
    lap(PRUNE);
    flush();
    t = cpu_now();
    for (int s = 0; s < sums; ++s) sphc::add_slots(L, acc[s].data(), back[s].data());
    lap(ADD);
    flush();
    t = cpu_now();
    sphc::gather_positions_boxes(L, moved.x.data(), moved.y.data(), moved.z.data(), xs.data(), ys.data(),
                                 zs.data(), 4 * support);
    lap(POS_BOXES);
    flush();
    t = cpu_now();
    sphc::gather_slots(L, from.data(), to.data(), fields);
    lap(FIELDS_1);
    flush();
    t = cpu_now();
    sphc::add_slots(L, sums_from.data(), into.data(), sums);
    lap(ADD_1);
  }
  double per_eval = 0, rebuild = best[LAYOUT] + best[PAIRS];
  for (int p = POSITIONS; p <= ADD; ++p) per_eval += best[p];
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
  const double lanes_per_pair = double(width) * width;
  std::printf("outer list: %zu cluster pairs (%.1f per i-cluster), %.1f%% of the tile lanes within the support\n",
              outer.pairs(), double(outer.pairs()) / L.n_clusters, 100.0 * in_outer / (lanes_per_pair * outer.pairs()));
  std::printf("pruned list: %zu cluster pairs (%.1f per i-cluster), %.1f%% of the tile lanes within the support\n",
              pruned.pairs(), double(pruned.pairs()) / L.n_clusters, 100.0 * in_pruned / (lanes_per_pair * pruned.pairs()));
  if (in_pruned != ref || in_outer != ref) {
    std::printf("FAILED: the lists hold %ld (pruned) and %ld (outer) of the %ld pairs within the support\n",
                in_pruned, in_outer, ref);
    return 1;
  }
  std::printf("OK: every pair within the support in both lists\n");
  if (fill) {
    const int bad = fill_report(cube, moved, dim, side, support, rlist);
    if (bad) return 1;
  }
  return 0;
}
