// sphc runtime: particle position generators. See geometry.h.
#include "sphc/geometry.h"

#include "sphc/memory.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace sphc {

namespace {

constexpr double kMaxPoints = 1e9;  // refuse to build more (a typo in dx, not a scene)
const char* const kMin[3] = {"xmin", "ymin", "zmin"};
const char* const kMax[3] = {"xmax", "ymax", "zmax"};

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

[[noreturn]] void fail(const char* builder, const std::string& what) {
  throw std::invalid_argument(std::string(builder) + ": " + what);
}

void check_dim(const char* builder, int dim) {
  if (dim < 1 || dim > 3) fail(builder, "dim must be 1, 2 or 3 (got " + std::to_string(dim) + ")");
}

void check_finite(const char* builder, const char* arg, double v) {
  if (!std::isfinite(v)) fail(builder, std::string(arg) + " must be finite (got " + num(v) + ")");
}

void check_positive(const char* builder, const char* arg, double v) {
  if (!(v > 0.0) || !std::isfinite(v)) {
    fail(builder, std::string(arg) + " must be > 0 (got " + num(v) + ")");
  }
}

void check_range(const char* builder, const char* lo_name, double lo, const char* hi_name,
                 double hi) {
  check_finite(builder, lo_name, lo);
  check_finite(builder, hi_name, hi);
  if (hi < lo) {
    fail(builder, std::string(hi_name) + " (" + num(hi) + ") < " + lo_name + " (" + num(lo) + ")");
  }
}

void check_count(const char* builder, double count) {
  if (count > kMaxPoints) {
    fail(builder, "would create " + num(count) + " points (more than " + num(kMaxPoints) +
                      "); is dx too small?");
  }
}

// Lattice coordinates along one axis with, for the tank, the side of the box they lie on:
// -1 below lo, 0 inside, +1 above hi.
struct Axis {
  std::vector<double> v;
  std::vector<int> side;
  void add(double c, int s) {
    v.push_back(c);
    side.push_back(s);
  }
};

// Axis a of a block/tank: cell centres inside [lo, hi] and `layers` wall layers each side.
// The wall layers above hi continue the lattice of the cells inside: they start at
// lo + n dx, n the whole number of cells that fit, which is hi itself when hi - lo is a
// whole number of dx. Starting them at hi instead would leave a seam wider than dx between
// the last column of the floor and the wall when it is not (4 m at dx = 0.03: 0.04 m), and
// water leaks through it under pressure.
Axis make_axis(double lo, double hi, double dx, int layers) {
  Axis ax;
  for (int k = layers - 1; k >= 0; --k) ax.add(lo - (k + 0.5) * dx, -1);
  const std::size_t n = lattice_count(lo, hi, dx);
  for (std::size_t i = 0; i < n; ++i) ax.add(lo + (i + 0.5) * dx, 0);
  const double on_lattice = lo + static_cast<double>(n) * dx;
  const double face = std::fabs(on_lattice - hi) <= 1e-9 * dx ? hi : on_lattice;
  for (int k = 0; k < layers; ++k) ax.add(face + (k + 0.5) * dx, +1);
  return ax;
}

// The axes of a block or tank in `dim` dimensions (unused axes: the single coordinate 0).
void make_axes(const char* builder, int dim, const double lo[3], const double hi[3], double dx,
               int layers, Axis axes[3]) {
  check_dim(builder, dim);
  check_positive(builder, "dx", dx);
  for (int a = 0; a < 3; ++a) {
    if (a < dim) {
      check_range(builder, kMin[a], lo[a], kMax[a], hi[a]);
      check_count(builder, (hi[a] - lo[a]) / dx + 2.0 * layers + 1.0);  // one axis
      axes[a] = make_axis(lo[a], hi[a], dx, layers);
    } else {
      axes[a] = Axis();
      axes[a].add(0.0, 0);
    }
  }
}

// The lattice of a disk (nd = 2) or ball (nd = 3): points c + (i, j, k) dx with |i|, |j| <= m,
// |k| <= mz and i^2 + j^2 + k^2 <= R2 (arguments checked).
struct BallLattice {
  double R2 = 0;
  long m = 0, mz = 0;
  bool inside(long i, long j, long k) const {
    return static_cast<double>(i * i + j * j + k * k) <= R2;
  }
  std::size_t count() const {  // without building the points (sphc/memory.h)
    std::size_t n = 0;
    for (long k = -mz; k <= mz; ++k)
      for (long j = -m; j <= m; ++j)
        for (long i = -m; i <= m; ++i) n += inside(i, j, k);
    return n;
  }
};

BallLattice ball_lattice(const char* builder, int nd, const double c[3], double r, double dx) {
  check_positive(builder, "r", r);
  check_positive(builder, "dx", dx);
  const char* const names[3] = {"cx", "cy", "cz"};
  for (int a = 0; a < nd; ++a) check_finite(builder, names[a], c[a]);
  const double R = r / dx;
  check_count(builder, std::pow(2.0 * R + 1.0, nd));
  // Integer test i^2 + j^2 + k^2 <= R^2, with a relative slack so that points on the circle
  // (e.g. r a whole number of dx) are kept regardless of rounding.
  BallLattice b;
  b.R2 = R * R * (1.0 + 1e-12);
  b.m = static_cast<long>(std::floor(R * (1.0 + 1e-12)));
  b.mz = nd == 3 ? b.m : 0;
  return b;
}

// Points of a disk (nd = 2) or ball (nd = 3) of lattice points c + i dx.
Points ball(const char* builder, int nd, const double c[3], double r, double dx) {
  const BallLattice b = ball_lattice(builder, nd, c, r, dx);
  if (counting_particles()) {  // sphc/memory.h: count, build nothing
    count_points(b.count());
    return {};
  }
  Points p;
  for (long k = -b.mz; k <= b.mz; ++k) {
    for (long j = -b.m; j <= b.m; ++j) {
      for (long i = -b.m; i <= b.m; ++i) {
        if (!b.inside(i, j, k)) continue;
        p.push(c[0] + i * dx, c[1] + j * dx, nd == 3 ? c[2] + k * dx : 0.0);
      }
    }
  }
  return p;
}

}  // namespace

void Points::append(const Points& other) {
  x.insert(x.end(), other.x.begin(), other.x.end());
  y.insert(y.end(), other.y.begin(), other.y.end());
  z.insert(z.end(), other.z.begin(), other.z.end());
}

std::size_t lattice_count(double lo, double hi, double dx) {
  const double cells = (hi - lo) / dx;
  if (!(cells > 0.0)) return 0;
  return static_cast<std::size_t>(std::floor(cells * (1.0 + 1e-9) + 0.5));
}

Points block(int dim, const double lo[3], const double hi[3], double dx) {
  Axis axes[3];
  make_axes("block", dim, lo, hi, dx, 0, axes);
  check_count("block", static_cast<double>(axes[0].v.size()) *
                           static_cast<double>(axes[1].v.size()) *
                           static_cast<double>(axes[2].v.size()));
  if (counting_particles()) {  // sphc/memory.h: count, build nothing
    count_points(axes[0].v.size() * axes[1].v.size() * axes[2].v.size());
    return {};
  }
  Points p;
  for (double z : axes[2].v) {
    for (double y : axes[1].v) {
      for (double x : axes[0].v) p.push(x, y, z);
    }
  }
  return p;
}

Points tank(int dim, const double lo[3], const double hi[3], double dx, int layers, bool top) {
  if (layers < 1) fail("tank", "layers must be >= 1 (got " + std::to_string(layers) + ")");
  Axis axes[3];
  make_axes("tank", dim, lo, hi, dx, layers, axes);
  const int up = dim - 1;  // vertical axis
  // The walls' points: every lattice point less those inside the box and, without a lid,
  // those above it (the walls alone count against the limit, not the box they enclose).
  double all = 1, inside = 1, above = 1;
  for (int a = 0; a < 3; ++a) {
    all *= static_cast<double>(axes[a].v.size());
    inside *= static_cast<double>(std::count(axes[a].side.begin(), axes[a].side.end(), 0));
    above *= a == up ? static_cast<double>(layers) : static_cast<double>(axes[a].v.size());
  }
  const double count = all - inside - (top ? 0 : above);
  check_count("tank", count);
  if (counting_particles()) {  // sphc/memory.h: count, build nothing
    count_points(static_cast<std::size_t>(count));
    return {};
  }
  Points p;
  int side[3];
  for (std::size_t k = 0; k < axes[2].v.size(); ++k) {
    side[2] = axes[2].side[k];
    for (std::size_t j = 0; j < axes[1].v.size(); ++j) {
      side[1] = axes[1].side[j];
      for (std::size_t i = 0; i < axes[0].v.size(); ++i) {
        side[0] = axes[0].side[i];
        if (side[0] == 0 && side[1] == 0 && side[2] == 0) continue;  // inside the box
        if (!top && side[up] == +1) continue;                         // no lid
        p.push(axes[0].v[i], axes[1].v[j], axes[2].v[k]);
      }
    }
  }
  return p;
}

Points disk(double cx, double cy, double r, double dx) {
  const double c[3] = {cx, cy, 0.0};
  return ball("disk", 2, c, r, dx);
}

Points sphere(double cx, double cy, double cz, double r, double dx) {
  const double c[3] = {cx, cy, cz};
  return ball("sphere", 3, c, r, dx);
}

Points cylinder(double cx, double cy, double r, double zmin, double zmax, double dx) {
  const double c[3] = {cx, cy, 0.0};
  check_range("cylinder", "zmin", zmin, "zmax", zmax);
  const std::size_t layers = lattice_count(zmin, zmax, dx);
  if (counting_particles()) {  // sphc/memory.h: count, build nothing
    const std::size_t section = ball_lattice("cylinder", 2, c, r, dx).count();
    check_count("cylinder", static_cast<double>(layers) * static_cast<double>(section));
    count_points(layers * section);
    return {};
  }
  const Points section = ball("cylinder", 2, c, r, dx);
  check_count("cylinder", static_cast<double>(layers) * static_cast<double>(section.size()));
  Points p;
  for (std::size_t k = 0; k < layers; ++k) {
    const double z = zmin + (k + 0.5) * dx;
    for (std::size_t i = 0; i < section.size(); ++i) p.push(section.x[i], section.y[i], z);
  }
  return p;
}

Points line(const double p0[3], const double p1[3], double dx) {
  check_positive("line", "dx", dx);
  const char* const names[6] = {"x0", "y0", "z0", "x1", "y1", "z1"};
  double d[3], len2 = 0.0;
  for (int a = 0; a < 3; ++a) {
    check_finite("line", names[a], p0[a]);
    check_finite("line", names[3 + a], p1[a]);
    d[a] = p1[a] - p0[a];
    len2 += d[a] * d[a];
  }
  Points p;
  if (len2 == 0.0) {
    if (counting_particles()) {
      count_points(1);
      return p;
    }
    p.push(p0[0], p0[1], p0[2]);
    return p;
  }
  const double len = std::sqrt(len2);
  check_count("line", len / dx);
  const std::size_t intervals = std::max<std::size_t>(1, lattice_count(0.0, len, dx));
  if (counting_particles()) {  // sphc/memory.h: count, build nothing
    count_points(intervals + 1);
    return {};
  }
  for (std::size_t k = 0; k < intervals; ++k) {
    const double t = static_cast<double>(k) / static_cast<double>(intervals);
    p.push(p0[0] + t * d[0], p0[1] + t * d[1], p0[2] + t * d[2]);
  }
  p.push(p1[0], p1[1], p1[2]);  // the end point exactly
  return p;
}

}  // namespace sphc
