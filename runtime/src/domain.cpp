// sphc runtime: the domain manager. See domain.h.
#include "sphc/domain.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sphc {

namespace {

const char* const kAxis[3] = {"x", "y", "z"};
const char* const kVelocity[3] = {"u", "v", "w"};

std::string axis_name(int a) { return std::string("axis ") + kAxis[a]; }

// Where the floating values of a property live: the host doubles (HostReals) or the float
// copy (FloatReals, --precision=single). Integer properties always live in the host array.
struct HostReals {
  using Real = double;
  ParticleArray& a;
  std::vector<double>& of(std::size_t i) { return a.props[i].f64; }
};
struct FloatReals {
  using Real = float;
  FloatArray& f;
  std::vector<float>& of(std::size_t i) {
    if (i >= f.props.size())
      throw std::out_of_range("ghosts: the float copy has no property number " +
                              std::to_string(i) + " (upload() first)");
    return f.props[i];
  }
};

// Storage of every property resized to n particles (new values 0).
template <class Reals>
void resize_storage(Reals reals, ParticleArray& a, std::size_t n) {
  for (std::size_t i = 0; i < a.props.size(); ++i) {
    Property& p = a.props[i];
    const std::size_t len = n * static_cast<std::size_t>(p.stride);
    switch (p.type) {
      case PropType::F64: reals.of(i).resize(len, 0); break;
      case PropType::I32: p.i32.resize(len, 0); break;
      case PropType::U32: p.u32.resize(len, 0u); break;
    }
  }
}

template <class T>
void copy_values(std::vector<T>& v, std::size_t n, int stride, const Ghosts& g) {
  const std::size_t s = static_cast<std::size_t>(stride);
  for (std::size_t k = 0; k < g.size(); ++k)
    for (std::size_t c = 0; c < s; ++c) v[(n + k) * s + c] = v[g.source[k] * s + c];
}

int image_along(std::uint8_t image, int axis) { return (image >> (2 * axis)) & 3; }

// v through the transform, in the arithmetic of T (t rounded to T first).
template <class T>
T transformed(const GhostTransform& tr, T v) {
  const T t = static_cast<T>(tr.t);
  switch (tr.op) {
    case GhostOp::Shift: return v + t;
    case GhostOp::Reflect: return t - v;
    case GhostOp::Negate: return -v;
    case GhostOp::Copy: break;
  }
  return v;
}

template <class Reals>
void copy_property(const Domain& d, Reals reals, ParticleArray& a, const Ghosts& g, int idx) {
  using Real = typename Reals::Real;
  if (idx < 0 || static_cast<std::size_t>(idx) >= a.props.size())
    throw std::out_of_range("ghosts of array '" + a.name + "': no property number " +
                            std::to_string(idx));
  Property& p = a.props[idx];
  const std::size_t n = a.n;
  bool position = false;
  const int axis = ghost_axis(p, position);
  if (axis >= 0) {
    const GhostTransform side[3] = {GhostTransform{}, ghost_transform(d, axis, 0, position),
                                    ghost_transform(d, axis, 1, position)};
    Real* v = reals.of(static_cast<std::size_t>(idx)).data();
    for (std::size_t k = 0; k < g.size(); ++k)
      v[n + k] = transformed(side[image_along(g.image[k], axis)], v[g.source[k]]);
    return;
  }
  switch (p.type) {
    case PropType::F64: copy_values(reals.of(static_cast<std::size_t>(idx)), n, p.stride, g); break;
    case PropType::I32: copy_values(p.i32, n, p.stride, g); break;
    case PropType::U32: copy_values(p.u32, n, p.stride, g); break;
  }
}

// wrap_periodic of n coordinates x along axis ax, in the arithmetic of T. With h: only the
// particles further than margin * h[i] outside [lo, hi) (wrap_periodic_far).
template <class T>
void wrap_axis(const Domain& d, int ax, T* x, std::size_t n, const T* h = nullptr,
               double margin = 0.0) {
  const T lo = static_cast<T>(d.lo[ax]), hi = static_cast<T>(d.hi[ax]), period = hi - lo;
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < n; ++i) {
    T v = x[i];
    if (!std::isfinite(v) || (v >= lo && v < hi)) continue;
    if (h && v >= lo - margin * h[i] && v < hi + margin * h[i]) continue;
    // Whole periods; the checks after it catch rounding at the ends.
    v -= std::floor((v - lo) / period) * period;
    if (v >= hi) v -= period;
    if (v < lo) v = lo;
    x[i] = v;
  }
}

template <class Reals>
void wrap_all(const Domain& d, Reals reals, const ParticleArray& a) {
  for (int ax = 0; ax < d.dim && ax < 3; ++ax) {
    if (!d.periodic(ax)) continue;
    const int idx = a.find(kAxis[ax]);
    if (idx < 0 || a.props[idx].type != PropType::F64) continue;
    wrap_axis(d, ax, reals.of(static_cast<std::size_t>(idx)).data(), a.n);
  }
}

template <class Reals>
std::size_t add_all(const Domain& d, Reals reals, ParticleArray& a, double cutoff, Ghosts& g,
                    const std::vector<int>& carried) {
  using Real = typename Reals::Real;
  const Real* pos[3] = {nullptr, nullptr, nullptr};
  for (int ax = 0; ax < d.dim && ax < 3; ++ax) {
    const int idx = a.find(kAxis[ax]);
    if (idx >= 0 && a.props[idx].type == PropType::F64)
      pos[ax] = reals.of(static_cast<std::size_t>(idx)).data();
  }
  find_ghosts(d, pos, a.n, cutoff, g, a.name);
  resize_storage(reals, a, a.n + g.size());
  for (int idx : carried) copy_property(d, reals, a, g, idx);
  return g.size();
}

template <class T>
std::size_t find_ghosts_of(const Domain& d, const T* const pos[3], std::size_t n, double cutoff,
                           Ghosts& g, const std::string& array) {
  g.source.clear();
  g.image.clear();
  if (!(cutoff >= 0.0) || !std::isfinite(cutoff))
    throw std::invalid_argument("ghosts of array '" + array + "': the cutoff must be finite "
                                "and >= 0");
  // Which sides make images, and the coordinates read per axis.
  bool makes[3][2] = {{false, false}, {false, false}, {false, false}};
  const T* axis[3] = {nullptr, nullptr, nullptr};
  bool any = false;
  for (int ax = 0; ax < d.dim && ax < 3; ++ax) {
    makes[ax][0] = d.lo_kind[ax] != Boundary::Open;
    makes[ax][1] = d.hi_kind[ax] != Boundary::Open;
    if (!makes[ax][0] && !makes[ax][1]) continue;
    any = true;
    if (makes[ax][0] && makes[ax][1] && d.hi[ax] - d.lo[ax] < cutoff)
      throw std::invalid_argument(
          "ghosts of array '" + array + "': " + axis_name(ax) + " spans " +
          std::to_string(d.hi[ax] - d.lo[ax]) + ", less than the interaction radius " +
          std::to_string(cutoff) + " (radius_scale * max h); enlarge the domain or reduce h");
    if (!pos[ax])
      throw std::invalid_argument("ghosts of array '" + array + "': no position " + kAxis[ax]);
    axis[ax] = pos[ax];
  }
  if (!any) return 0;
  for (std::size_t i = 0; i < n; ++i) {
    // Per axis the images this particle has: 0 (itself) and 1 / 2 when near a side.
    int codes[3][3];
    int count[3] = {1, 1, 1};
    for (int ax = 0; ax < 3; ++ax) {
      codes[ax][0] = 0;
      if (!axis[ax]) continue;
      const double v = axis[ax][i];  // a float widened: compared in double
      if (!std::isfinite(v)) continue;
      if (makes[ax][0] && v < d.lo[ax] + cutoff) codes[ax][count[ax]++] = 1;
      if (makes[ax][1] && v > d.hi[ax] - cutoff) codes[ax][count[ax]++] = 2;
    }
    // Every combination but the particle itself (corners and edges included).
    for (int cz = 0; cz < count[2]; ++cz)
      for (int cy = 0; cy < count[1]; ++cy)
        for (int cx = 0; cx < count[0]; ++cx) {
          const int image = codes[0][cx] | (codes[1][cy] << 2) | (codes[2][cz] << 4);
          if (image == 0) continue;
          g.source.push_back(static_cast<std::uint32_t>(i));
          g.image.push_back(static_cast<std::uint8_t>(image));
        }
  }
  return g.size();
}

}  // namespace

bool Domain::any() const {
  for (int a = 0; a < 3; ++a)
    if (lo_kind[a] != Boundary::Open || hi_kind[a] != Boundary::Open) return true;
  return false;
}

void check_domain(const Domain& d) {
  if (d.dim < 1 || d.dim > 3)
    throw std::invalid_argument("domain: dim must be 1, 2 or 3 (got " + std::to_string(d.dim) +
                                ")");
  for (int a = 0; a < 3; ++a) {
    const bool lo = d.lo_kind[a] != Boundary::Open, hi = d.hi_kind[a] != Boundary::Open;
    if (!lo && !hi) continue;
    if (a >= d.dim)
      throw std::invalid_argument("domain: " + axis_name(a) + " is beyond dim = " +
                                  std::to_string(d.dim));
    if ((d.lo_kind[a] == Boundary::Periodic) != (d.hi_kind[a] == Boundary::Periodic))
      throw std::invalid_argument("domain: " + axis_name(a) +
                                  " is periodic on one side only");
    if ((lo && !std::isfinite(d.lo[a])) || (hi && !std::isfinite(d.hi[a])))
      throw std::invalid_argument("domain: a plane of " + axis_name(a) + " is not finite");
    if (lo && hi && !(d.lo[a] < d.hi[a]))
      throw std::invalid_argument("domain: " + axis_name(a) + " has the empty interval [" +
                                  std::to_string(d.lo[a]) + ", " + std::to_string(d.hi[a]) +
                                  "]");
  }
}

void check_ghost_span(const Domain& d, double cutoff, const std::string& why) {
  for (int a = 0; a < d.dim && a < 3; ++a)
    if (d.lo_kind[a] != Boundary::Open && d.hi_kind[a] != Boundary::Open &&
        d.hi[a] - d.lo[a] < cutoff)
      throw std::invalid_argument("domain: " + axis_name(a) + " spans " +
                                  std::to_string(d.hi[a] - d.lo[a]) + ", less than " +
                                  std::to_string(cutoff) + ": " + why);
}

GhostTransform ghost_transform(const Domain& d, int axis, int side, bool position) {
  GhostTransform t;
  if (axis < 0 || axis >= 3 || side < 0 || side > 1) return t;
  const Boundary kind = side == 0 ? d.lo_kind[axis] : d.hi_kind[axis];
  if (kind == Boundary::Open) return t;
  const double period = d.hi[axis] - d.lo[axis];
  if (position && kind == Boundary::Periodic) {
    t.op = GhostOp::Shift;  // x + L through the low side, x - L through the high side
    t.t = side == 0 ? period : -period;
  } else if (position) {
    t.op = GhostOp::Reflect;  // 2 lo - x, 2 hi - x
    t.t = 2.0 * (side == 0 ? d.lo[axis] : d.hi[axis]);
  } else if (kind == Boundary::Mirror) {
    t.op = GhostOp::Negate;  // the velocity component normal to a mirror
  }
  return t;
}

int ghost_axis(const Property& p, bool& position) {
  position = false;
  if (p.type != PropType::F64 || p.stride != 1) return -1;
  for (int ax = 0; ax < 3; ++ax) {
    if (p.name == kAxis[ax]) {
      position = true;
      return ax;
    }
    if (p.name == kVelocity[ax]) return ax;
  }
  return -1;
}

void wrap_periodic(const Domain& d, ParticleArray& a) { wrap_all(d, HostReals{a}, a); }

void wrap_periodic(const Domain& d, FloatArray& f, const ParticleArray& a) {
  wrap_all(d, FloatReals{f}, a);
}

template <class Reals>
void wrap_far(const Domain& d, Reals reals, const ParticleArray& a, double margin) {
  const int h = a.find("h");
  if (h < 0 || a.props[h].type != PropType::F64) return wrap_all(d, reals, a);
  for (int ax = 0; ax < d.dim && ax < 3; ++ax) {
    if (!d.periodic(ax)) continue;
    const int idx = a.find(kAxis[ax]);
    if (idx < 0 || a.props[idx].type != PropType::F64) continue;
    wrap_axis(d, ax, reals.of(static_cast<std::size_t>(idx)).data(), a.n,
              reals.of(static_cast<std::size_t>(h)).data(), margin);
  }
}

template <class Reals>
std::size_t restore_all(const Domain& d, Reals reals, ParticleArray& a, const Ghosts& g,
                        const std::vector<int>& carried) {
  resize_storage(reals, a, a.n + g.size());
  for (int idx : carried) copy_property(d, reals, a, g, idx);
  return g.size();
}

void wrap_periodic_far(const Domain& d, ParticleArray& a, double margin) {
  wrap_far(d, HostReals{a}, a, margin);
}

void wrap_periodic_far(const Domain& d, FloatArray& f, const ParticleArray& a, double margin) {
  wrap_far(d, FloatReals{f}, a, margin);
}

std::size_t restore_ghosts(const Domain& d, ParticleArray& a, const Ghosts& g,
                           const std::vector<int>& carried) {
  return restore_all(d, HostReals{a}, a, g, carried);
}

std::size_t restore_ghosts(const Domain& d, FloatArray& f, ParticleArray& a, const Ghosts& g,
                           const std::vector<int>& carried) {
  return restore_all(d, FloatReals{f}, a, g, carried);
}

void hide_ghosts(ParticleArray& a) { resize_storage(HostReals{a}, a, a.n); }

void hide_ghosts(FloatArray& f, ParticleArray& a) { resize_storage(FloatReals{f}, a, a.n); }

std::size_t find_ghosts(const Domain& d, const double* const pos[3], std::size_t n,
                        double cutoff, Ghosts& g, const std::string& array) {
  return find_ghosts_of(d, pos, n, cutoff, g, array);
}

std::size_t find_ghosts(const Domain& d, const float* const pos[3], std::size_t n,
                        double cutoff, Ghosts& g, const std::string& array) {
  return find_ghosts_of(d, pos, n, cutoff, g, array);
}

std::size_t add_ghosts(const Domain& d, ParticleArray& a, double cutoff, Ghosts& g,
                       const std::vector<int>& carried) {
  return add_all(d, HostReals{a}, a, cutoff, g, carried);
}

std::size_t add_ghosts(const Domain& d, FloatArray& f, ParticleArray& a, double cutoff, Ghosts& g,
                       const std::vector<int>& carried) {
  return add_all(d, FloatReals{f}, a, cutoff, g, carried);
}

void refresh_ghosts(const Domain& d, ParticleArray& a, const Ghosts& g,
                    const std::vector<int>& props) {
  for (int idx : props) copy_property(d, HostReals{a}, a, g, idx);
}

void refresh_ghosts(const Domain& d, FloatArray& f, ParticleArray& a, const Ghosts& g,
                    const std::vector<int>& props) {
  for (int idx : props) copy_property(d, FloatReals{f}, a, g, idx);
}

void remove_ghosts(ParticleArray& a, Ghosts& g) {
  resize_storage(HostReals{a}, a, a.n);
  g.source.clear();
  g.image.clear();
}

void remove_ghosts(FloatArray& f, ParticleArray& a, Ghosts& g) {
  resize_storage(FloatReals{f}, a, a.n);
  g.source.clear();
  g.image.clear();
}

void extend_for_ghosts(SearchDomain& s, const Domain& d, double cutoff) {
  for (int ax = 0; ax < s.dim && ax < 3; ++ax) {
    if (d.lo_kind[ax] != Boundary::Open) s.lo[ax] = std::min(s.lo[ax], d.lo[ax] - cutoff);
    if (d.hi_kind[ax] != Boundary::Open) s.hi[ax] = std::max(s.hi[ax], d.hi[ax] + cutoff);
  }
}

}  // namespace sphc
