// sphc runtime: the inlet/outlet manager (sphc/inlet_outlet.h).
#include "sphc/inlet_outlet.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>


namespace sphc {

namespace {

std::string num(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

// The coordinates of particle i (0 for an axis the array lacks).
struct Positions {
  const double* c[3] = {nullptr, nullptr, nullptr};
  explicit Positions(const ParticleArray& a) {
    const char* names[3] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) {
      int idx = a.find(names[k]);
      if (idx >= 0 && a.props[idx].type == PropType::F64) c[k] = a.f64(idx);
    }
  }
  void at(std::size_t i, double p[3]) const {
    for (int k = 0; k < 3; ++k) p[k] = c[k] ? c[k][i] : 0.0;
  }
};

// Moves position k of particle i by d along the normal.
void shift(ParticleArray& a, std::size_t i, const double n[3], double d) {
  const char* names[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    if (n[k] == 0.0) continue;
    int idx = a.find(names[k]);
    if (idx >= 0) a.f64(idx)[i] += d * n[k];
  }
}

}  // namespace

double Zone::depth(const double p[3]) const {
  double s = 0.0;
  for (int k = 0; k < dim; ++k) s += (p[k] - point[k]) * normal[k];
  return s;
}

bool Zone::across(const double p[3]) const {
  // Tangential offset: the part of p - point orthogonal to the normal, per axis.
  const double s = depth(p);
  double t2max = 0.0;
  if (dim == 2) {
    const double t = -(p[0] - point[0]) * normal[1] + (p[1] - point[1]) * normal[0];
    t2max = std::fabs(t);
  } else {
    for (int k = 0; k < dim; ++k) {
      const double t = p[k] - point[k] - s * normal[k];
      t2max = std::fmax(t2max, std::fabs(t));
    }
  }
  return dim == 1 || t2max <= 0.5 * width;
}

void check_zone(Zone& z, double support) {
  double len2 = 0.0;
  for (int k = 0; k < z.dim; ++k) len2 += z.normal[k] * z.normal[k];
  const std::string head = z.name + ": ";
  if (!(len2 > 0.0) || !std::isfinite(len2))
    throw std::invalid_argument(head + "the outward normal has zero length");
  for (int k = 0; k < 3; ++k) z.normal[k] = k < z.dim ? z.normal[k] / std::sqrt(len2) : 0.0;
  if (!(z.length > 0.0))
    throw std::invalid_argument(head + "length must be > 0 (got " + num(z.length) + ")");
  if (!(z.width > 0.0) && z.dim > 1)
    throw std::invalid_argument(head + "width must be > 0 (got " + num(z.width) + ")");
  if (z.length < support)
    throw std::invalid_argument(head + "length " + num(z.length) +
                                " is narrower than the kernel support " + num(support) +
                                ": particles near the face would miss neighbours");
}

CopyMap make_copy_map(const ParticleArray& to, const ParticleArray& from,
                      const std::vector<std::string>& names) {
  CopyMap m;
  auto add = [&](const std::string& p, bool required) {
    const int t = to.find(p), f = from.find(p);
    if (t < 0 || f < 0) {
      if (!required) return;
      throw std::invalid_argument("property '" + p + "' to copy from array '" + from.name +
                                  "' to '" + to.name + "' is missing in '" +
                                  (t < 0 ? to.name : from.name) + "'");
    }
    const Property &a = to.props[t], &b = from.props[f];
    if (a.type != b.type || a.stride != b.stride)
      throw std::invalid_argument("property '" + p + "' has another type in array '" +
                                  from.name + "' than in '" + to.name + "'");
    for (int k : m.to)
      if (k == t) return;
    m.to.push_back(t);
    m.from.push_back(f);
  };
  if (names.empty()) {
    for (const Property& p : to.props) add(p.name, false);
  } else {
    for (const std::string& p : names) add(p, true);
    add("gid", false);
  }
  return m;
}

void append_particle(ParticleArray& to, const ParticleArray& from, std::size_t i,
                     const CopyMap& map) {
  const std::size_t j = to.n;
  to.resize(j + 1);  // every property grows; new values 0 (std::vector: amortised growth)
  for (std::size_t k = 0; k < map.to.size(); ++k)
    copy_particle_values(to.props[map.to[k]], j, from.props[map.from[k]], i);
}

void set_inlet_velocity(InletZone& in, double t) {
  if (!in.velocity) return;
  ParticleArray& a = *in.inlet;
  const Positions pos(a);
  double* vel[3] = {nullptr, nullptr, nullptr};
  const char* names[3] = {"u", "v", "w"};
  for (int k = 0; k < 3; ++k)
    if (int idx = a.find(names[k]); idx >= 0 && a.props[idx].type == PropType::F64)
      vel[k] = a.f64(idx);
  for (std::size_t i = 0; i < a.n; ++i) {
    double p[3], v[3] = {0, 0, 0};
    pos.at(i, p);
    in.velocity(p, t, v);
    for (int k = 0; k < 3; ++k)
      if (vel[k]) vel[k][i] = v[k];
  }
}

double largest_h(const std::vector<ParticleArray*>& arrays) {
  double h = 0.0;
  for (const ParticleArray* a : arrays) {
    const int k = a->find("h");
    if (k < 0 || a->props[k].type != PropType::F64) continue;
    for (std::size_t i = 0; i < a->n; ++i) h = std::fmax(h, a->f64(k)[i]);
  }
  return h;
}

void init_inlet_outlet(InletOutlet& io, const std::vector<ParticleArray*>& all, double support,
                       double t) {
  for (auto& in : io.inlets) check_zone(in.zone, support);
  for (auto& out : io.outlets) check_zone(out.zone, support);
  io.ids = GlobalIds{};
  assign_global_ids(all, io.ids);
  for (auto& in : io.inlets) {
    in.map = make_copy_map(*in.feeds, *in.inlet, in.copy);
    set_inlet_velocity(in, t);
  }
  for (auto& out : io.outlets) {
    out.in = make_copy_map(*out.outlet, *out.from, out.copy);
    out.back = make_copy_map(*out.from, *out.outlet, out.copy);
    out.support = support;
    out.mirrored = CopyMap{};
    for (std::size_t k = 0; k < out.in.to.size(); ++k) {
      const Property& p = out.outlet->props[out.in.to[k]];
      if (p.type != PropType::F64 || p.stride != 1 || p.name == "x" || p.name == "y" || p.name == "z" ||
          p.name == "m" || p.name == "h" || p.name == "gid")
        continue;
      out.mirrored.to.push_back(out.in.to[k]);
      out.mirrored.from.push_back(out.in.from[k]);
    }
  }
}

ImageBand image_band(const OutletZone& out) {
  const ParticleArray& src = *out.from;
  const Zone& z = out.zone;
  ImageBand band;
  band.np = out.mirrored.to.size();
  if (!(out.support > 0.0) || band.np == 0) return band;
  const int g = src.find("gid");
  const Positions sp(src);
  for (std::size_t j = 0; j < src.n; ++j) {
    double q[3];
    sp.at(j, q);
    const double s = z.depth(q);
    if (!(s <= 0.0 && s >= -(2.0 * z.length + out.support))) continue;
    band.pos.insert(band.pos.end(), q, q + 3);
    for (std::size_t k = 0; k < band.np; ++k)
      band.vals.push_back(src.props[out.mirrored.from[k]].f64[j]);
    band.gid.push_back(g >= 0 ? src.props[static_cast<std::size_t>(g)].u32[j]
                              : static_cast<std::uint32_t>(j));
  }
  return band;
}

void sort_band(ImageBand& band) {
  const std::size_t n = band.size(), np = band.np;
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return band.gid[a] < band.gid[b]; });
  ImageBand s;
  s.np = np;
  s.pos.reserve(band.pos.size());
  s.vals.reserve(band.vals.size());
  s.gid.reserve(n);
  for (std::size_t i : order) {
    s.pos.insert(s.pos.end(), band.pos.begin() + 3 * i, band.pos.begin() + 3 * i + 3);
    s.vals.insert(s.vals.end(), band.vals.begin() + np * i, band.vals.begin() + np * (i + 1));
    s.gid.push_back(band.gid[i]);
  }
  band = std::move(s);
}

ImageValues interpolate_images(const OutletZone& out, const ImageBand& band) {
  const ParticleArray& o = *out.outlet;
  const Zone& z = out.zone;
  const double R = out.support;
  const std::size_t np = out.mirrored.to.size();
  ImageValues iv;
  iv.vals.assign(o.n * np, 0.0);
  iv.found.assign(o.n, 0);
  if (!(R > 0.0) || np == 0) return iv;
  const Positions op(o);
  for (std::size_t i = 0; i < o.n; ++i) {
    double p[3];
    op.at(i, p);
    const double s = z.depth(p);
    double img[3];
    for (int k = 0; k < 3; ++k) img[k] = p[k] - 2.0 * s * z.normal[k];
    double wsum = 0.0;
    double* acc = iv.vals.data() + i * np;
    for (std::size_t j = 0; j < band.size(); ++j) {
      const double* q = band.pos.data() + 3 * j;
      double r2 = 0.0;
      for (int k = 0; k < z.dim; ++k) r2 += (q[k] - img[k]) * (q[k] - img[k]);
      if (r2 >= R * R) continue;
      const double x = std::sqrt(r2) / R, a = 1.0 - x;
      const double w = a * a * a * a * (1.0 + 4.0 * x);  // Wendland C2 (unnormalised)
      wsum += w;
      const double* v = band.vals.data() + np * j;
      for (std::size_t k = 0; k < np; ++k) acc[k] += w * v[k];
    }
    if (!(wsum > 0.0)) {
      ++iv.lonely;
      continue;
    }
    iv.found[i] = 1;
    for (std::size_t k = 0; k < np; ++k) acc[k] /= wsum;
  }
  return iv;
}

namespace {
// Tangential coordinates of p on the face (2D: one, 3D: two; orthonormal to the normal).
void tangential(const Zone& z, const double p[3], double t[2]) {
  double d[3];
  for (int k = 0; k < 3; ++k) d[k] = k < z.dim ? p[k] - z.point[k] : 0.0;
  const double* n = z.normal;
  if (z.dim == 2) {
    t[0] = -d[0] * n[1] + d[1] * n[0];
    t[1] = 0.0;
    return;
  }
  // a = the unit vector of the axis least aligned with n, made orthogonal to n; b = n x a.
  int m = 0;
  for (int k = 1; k < 3; ++k)
    if (std::fabs(n[k]) < std::fabs(n[m])) m = k;
  double a[3] = {0, 0, 0};
  a[m] = 1.0;
  double an = a[0] * n[0] + a[1] * n[1] + a[2] * n[2], al = 0.0;
  for (int k = 0; k < 3; ++k) a[k] -= an * n[k], al += a[k] * a[k];
  for (int k = 0; k < 3; ++k) a[k] /= std::sqrt(al);
  const double b[3] = {n[1] * a[2] - n[2] * a[1], n[2] * a[0] - n[0] * a[2],
                       n[0] * a[1] - n[1] * a[0]};
  t[0] = d[0] * a[0] + d[1] * a[1] + d[2] * a[2];
  t[1] = d[0] * b[0] + d[1] * b[1] + d[2] * b[2];
}
}  // namespace

void apply_mirror(OutletZone& out, const ImageValues& iv) {
  ParticleArray& o = *out.outlet;
  const std::size_t np = out.mirrored.to.size();
  for (std::size_t i = 0; i < o.n; ++i)
    if (iv.found[i])
      for (std::size_t k = 0; k < np; ++k)
        o.props[out.mirrored.to[k]].f64[i] = iv.vals[i * np + k];
}

std::size_t mirror_outlet(OutletZone& out) {
  ImageBand band = image_band(out);
  sort_band(band);
  const ImageValues iv = interpolate_images(out, band);
  apply_mirror(out, iv);
  return iv.lonely;
}

namespace {
// Where p, rho and the velocity components sit among the interpolated values (the
// characteristic condition's needs checked).
struct Slots {
  int p = -1, rho = -1, v[3] = {-1, -1, -1};
};
Slots characteristic_slots(const OutletZone& out) {
  const ParticleArray& o = *out.outlet;
  const Zone& z = out.zone;
  const std::string what =
      out.kind == OutletKind::Hybrid ? "the hybrid outlet" : "the characteristic outlet";
  if (!(out.c > 0.0))
    throw std::invalid_argument(z.name + ": " + what + " needs the sound speed "
                                "c > 0 (got " + num(out.c) + ")");
  const std::size_t np = out.mirrored.to.size();
  auto slot = [&](const char* name) {
    for (std::size_t k = 0; k < np; ++k)
      if (o.props[out.mirrored.to[k]].name == name) return static_cast<int>(k);
    return -1;
  };
  Slots s;
  s.p = slot("p");
  s.rho = slot("rho");
  s.v[0] = slot("u");
  s.v[1] = slot("v");
  s.v[2] = slot("w");
  if (s.p < 0) throw std::invalid_argument(z.name + ": " + what + " needs 'p' "
                                           "in both arrays (and copied)");
  for (int k = 0; k < z.dim; ++k)
    if (s.v[k] < 0)
      throw std::invalid_argument(z.name + ": " + what + " needs the velocity "
                                  "'" + std::string(1, "uvw"[k]) + "' in both arrays (and copied)");
  return s;
}
}  // namespace

namespace {
// Bins across the face (width support / 2) for the running means: how many per tangential
// axis, and the bin of a position.
struct FaceBins {
  double bw = 0.0;
  int nb1 = 1, nb2 = 1;
  explicit FaceBins(const OutletZone& out) : bw(0.5 * out.support) {
    const Zone& z = out.zone;
    nb1 = z.dim > 1 ? std::max(1, static_cast<int>(std::ceil(z.width / bw))) : 1;
    nb2 = z.dim > 2 ? nb1 : 1;
  }
  std::size_t size() const {
    return static_cast<std::size_t>(nb1) * static_cast<std::size_t>(nb2);
  }
  std::size_t of(const Zone& z, const double p[3]) const {
    double tc[2];
    tangential(z, p, tc);
    auto idx = [&](double c) {
      const int k = static_cast<int>(std::floor((c + 0.5 * z.width) / bw));
      return std::min(std::max(k, 0), nb1 - 1);
    };
    return static_cast<std::size_t>(idx(tc[0])) +
           (z.dim > 2 ? static_cast<std::size_t>(idx(tc[1])) * static_cast<std::size_t>(nb1) : 0);
  }
};
}  // namespace

NormalBins normal_bins(const OutletZone& out, const ImageValues& iv) {
  const ParticleArray& o = *out.outlet;
  const Zone& z = out.zone;
  const Slots sl = characteristic_slots(out);
  const std::size_t np = out.mirrored.to.size();
  const FaceBins fb(out);
  const std::size_t nb = fb.size();
  NormalBins b;
  b.bin.assign(o.n, 0);
  b.un.assign(o.n, 0.0);
  b.sum.assign(nb, 0.0);
  b.count.assign(nb, 0.0);
  const Positions op(o);
  for (std::size_t i = 0; i < o.n; ++i) {
    double p[3];
    op.at(i, p);
    b.bin[i] = fb.of(z, p);
    if (!iv.found[i]) continue;
    for (int k = 0; k < z.dim; ++k) b.un[i] += iv.vals[i * np + sl.v[k]] * z.normal[k];
    b.sum[b.bin[i]] += b.un[i];
    b.count[b.bin[i]] += 1.0;
  }
  return b;
}

void face_sums(const OutletZone& out, const ImageBand& band, NormalBins& b) {
  const Zone& z = out.zone;
  const Slots sl = characteristic_slots(out);
  const std::size_t np = band.np;
  const FaceBins fb(out);
  const std::size_t nb = fb.size();
  b.sum.assign(nb, 0.0);
  b.count.assign(nb, 0.0);
  b.psum.assign(nb, 0.0);
  b.rsum.assign(nb, 0.0);
  for (std::size_t j = 0; j < band.size(); ++j) {  // gid order: the same sums on every rank
    const double* q = band.pos.data() + 3 * j;
    if (!(z.depth(q) >= -out.support) || !z.across(q)) continue;
    const double* v = band.vals.data() + np * j;
    double un = 0.0;
    for (int k = 0; k < z.dim; ++k) un += v[sl.v[k]] * z.normal[k];
    const std::size_t k = fb.of(z, q);
    b.sum[k] += un;
    b.psum[k] += v[sl.p];
    b.rsum[k] += sl.rho >= 0 ? v[sl.rho] : 1.0;
    b.count[k] += 1.0;
  }
}

void advance_reference(OutletZone& out, const NormalBins& b, double t) {
  const std::size_t nb = b.sum.size();
  const bool hybrid = !b.psum.empty();  // the mean pressure too
  if (out.uref.size() != nb) {
    out.uref.assign(nb, 0.0);
    out.uref_set.assign(nb, 0);
  }
  if (hybrid && out.pref.size() != nb) out.pref.assign(nb, 0.0);
  const double tau = out.tau > 0.0 ? out.tau : 20.0 * out.zone.length / out.c;
  const double f = out.started ? std::min(1.0, std::max(0.0, t - out.t_last) / tau) : 1.0;
  // Hybrid: a bin's pressure sample counts only while quiet, its acoustic intensity
  // (p - p_ref)^2 / (2 rho c) below I_min = (rho U^2 / 2)^2 / (2 rho c), i.e.
  // |p - p_ref| < rho U^2 / 2, with U and rho the face's mean normal velocity and density now.
  double quiet = 0.0;
  if (hybrid) {
    double su = 0.0, sr = 0.0, n = 0.0;
    for (std::size_t k = 0; k < nb; ++k) su += b.sum[k], sr += b.rsum[k], n += b.count[k];
    if (n > 0.0) quiet = 0.5 * (sr / n) * (su / n) * (su / n);
  }
  for (std::size_t k = 0; k < nb; ++k) {
    if (!(b.count[k] > 0.0)) continue;
    const double mean = b.sum[k] / b.count[k];
    const double pmean = hybrid ? b.psum[k] / b.count[k] : 0.0;
    if (!out.uref_set[k]) {
      out.uref[k] = mean;
      if (hybrid) out.pref[k] = pmean;
      out.uref_set[k] = 1;
    } else {
      out.uref[k] += f * (mean - out.uref[k]);
      if (hybrid && std::fabs(pmean - out.p_ref) < quiet) out.pref[k] += f * (pmean - out.pref[k]);
    }
  }
  out.started = true;
  out.t_last = t;
}

void apply_characteristic(OutletZone& out, ImageValues& iv, const NormalBins& b) {
  ParticleArray& o = *out.outlet;
  const Zone& z = out.zone;
  const Slots sl = characteristic_slots(out);
  const std::size_t np = out.mirrored.to.size();
  for (std::size_t i = 0; i < o.n; ++i) {
    if (!iv.found[i]) continue;
    double* v = iv.vals.data() + i * np;
    const double rho = sl.rho >= 0 && v[sl.rho] > 0.0 ? v[sl.rho] : 1.0;
    const double ur = out.uref[b.bin[i]];
    // The reference pressure: p_ref, or (hybrid) the bin's mean pressure p_ta.
    const double pr = out.kind == OutletKind::Hybrid ? out.pref[b.bin[i]] : out.p_ref;
    const double j2 = rho * out.c * (b.un[i] - ur) + (v[sl.p] - pr);
    v[sl.p] = pr + 0.5 * j2;
    const double dn = ur + 0.5 * j2 / (rho * out.c) - b.un[i];  // new minus image normal velocity
    for (int k = 0; k < z.dim; ++k) v[sl.v[k]] += dn * z.normal[k];
    for (std::size_t k = 0; k < np; ++k) o.props[out.mirrored.to[k]].f64[i] = v[k];
  }
}

std::size_t characteristic_outlet(OutletZone& out, double t) {
  characteristic_slots(out);  // the checks, before anything changes
  ImageBand band = image_band(out);
  sort_band(band);
  ImageValues iv = interpolate_images(out, band);
  const NormalBins b = normal_bins(out, iv);
  advance_reference(out, b, t);
  apply_characteristic(out, iv, b);
  return iv.lonely;
}

std::size_t hybrid_outlet(OutletZone& out, double t) {
  characteristic_slots(out);  // the checks, before anything changes
  ImageBand band = image_band(out);
  sort_band(band);
  ImageValues iv = interpolate_images(out, band);
  NormalBins b = normal_bins(out, iv);
  face_sums(out, band, b);  // the means from the fluid at the face
  advance_reference(out, b, t);
  apply_characteristic(out, iv, b);
  return iv.lonely;
}

std::vector<std::size_t> enter_fluid(InletZone& in) {
  ParticleArray& a = *in.inlet;
  std::vector<std::size_t> crossed;
  for (std::size_t i = 0; i < a.n; ++i) {
    double p[3];
    Positions(a).at(i, p);
    // A particle may have come more than a zone length (not with a stable time step): it
    // enters once, and moves back as often as needed.
    if (in.zone.depth(p) >= 0.0) continue;
    append_particle(*in.feeds, a, i, in.map);
    crossed.push_back(i);
    while (in.zone.depth(p) < 0.0) {
      shift(a, i, in.zone.normal, in.zone.length);
      Positions(a).at(i, p);
    }
  }
  return crossed;
}

std::vector<std::uint32_t> old_ids(const InletZone& in, const std::vector<std::size_t>& crossed) {
  std::vector<std::uint32_t> ids;
  const int gid = in.inlet->find("gid");
  if (gid < 0) return ids;
  ids.reserve(crossed.size());
  for (std::size_t i : crossed) ids.push_back(in.inlet->u32(gid)[i]);
  return ids;
}

void give_fresh_ids(InletZone& in, const std::vector<std::size_t>& crossed,
                    const std::vector<std::uint32_t>& entering, std::uint32_t first) {
  ParticleArray& a = *in.inlet;
  const int gid = a.find("gid");
  if (gid < 0) return;
  std::uint32_t* g = a.u32(gid);
  for (std::size_t i : crossed) {
    const auto it = std::lower_bound(entering.begin(), entering.end(), g[i]);
    if (it == entering.end() || *it != g[i])
      throw std::logic_error(in.zone.name + ": particle gid " + std::to_string(g[i]) +
                             " crossed the face but is not among the entering ids");
    g[i] = first + static_cast<std::uint32_t>(it - entering.begin());
  }
}

bool update_inlet(InletZone& in, GlobalIds& ids, double t) {
  const std::vector<std::size_t> crossed = enter_fluid(in);
  std::vector<std::uint32_t> entering = old_ids(in, crossed);
  std::sort(entering.begin(), entering.end());
  give_fresh_ids(in, crossed, entering, ids.take(crossed.size()));
  in.created += crossed.size();
  set_inlet_velocity(in, t);
  return !crossed.empty();
}

bool update_outlet(OutletZone& out) {
  ParticleArray& src = *out.from;
  ParticleArray& o = *out.outlet;
  // Outlet particles flowing back, or gone past the zone.
  std::vector<std::uint8_t> drop(o.n, 0);
  const std::size_t n_outlet = o.n;
  {
    const Positions pos(o);
    for (std::size_t i = 0; i < n_outlet; ++i) {
      double p[3];
      pos.at(i, p);
      const double s = out.zone.depth(p);
      if (s > out.zone.length || !std::isfinite(s)) {
        drop[i] = 1;
        ++out.removed;
      } else if (s < 0.0) {
        drop[i] = 2;
      }
    }
  }
  // Source particles entering the zone (decided before any return, so a returning particle
  // does not bounce straight back).
  std::vector<std::uint8_t> leave(src.n, 0);
  {
    const Positions pos(src);
    for (std::size_t i = 0; i < src.n; ++i) {
      double p[3];
      pos.at(i, p);
      leave[i] = out.zone.depth(p) >= 0.0 && out.zone.across(p);
    }
  }
  const std::size_t n_src = src.n;
  const std::size_t moved = out.returned + out.entered;
  for (std::size_t i = 0; i < n_outlet; ++i)
    if (drop[i] == 2) {
      append_particle(src, o, i, out.back);
      ++out.returned;
    }
  for (std::size_t i = 0; i < n_src; ++i)
    if (leave[i]) {
      append_particle(o, src, i, out.in);
      ++out.entered;
    }
  leave.resize(src.n, 0);  // returned particles stay
  drop.resize(o.n, 0);     // entered particles stay
  const std::size_t gone = src.remove_particles(leave) + o.remove_particles(drop);
  return gone > 0 || out.returned + out.entered != moved;
}

bool inlet_outlet_due(const InletOutlet& io) {
  double p[3];
  for (const auto& in : io.inlets) {
    const Positions pos(*in.inlet);
    for (std::size_t i = 0; i < in.inlet->n; ++i) {
      pos.at(i, p);
      if (in.zone.depth(p) < 0.0) return true;
    }
  }
  for (const auto& out : io.outlets) {
    if (out.kind != OutletKind::DoNothing) return true;  // sets the outlet every step
    const Positions pos(*out.outlet);
    for (std::size_t i = 0; i < out.outlet->n; ++i) {
      pos.at(i, p);
      const double s = out.zone.depth(p);
      if (!(s >= 0.0 && s <= out.zone.length)) return true;
    }
    const Positions from(*out.from);
    for (std::size_t i = 0; i < out.from->n; ++i) {
      from.at(i, p);
      if (out.zone.depth(p) >= 0.0 && out.zone.across(p)) return true;
    }
  }
  return false;
}

void set_inlet_velocities(InletOutlet& io, double t) {
  for (auto& in : io.inlets) set_inlet_velocity(in, t);
}

bool update_inlet_outlet(InletOutlet& io, double t) {
  bool changed = false;
  for (auto& in : io.inlets) changed |= update_inlet(in, io.ids, t);
  for (auto& out : io.outlets) {
    changed |= update_outlet(out);
    if (out.kind == OutletKind::Mirror) mirror_outlet(out);
    if (out.kind == OutletKind::Characteristic) characteristic_outlet(out, t);
    if (out.kind == OutletKind::Hybrid) hybrid_outlet(out, t);
  }
  return changed;
}

}  // namespace sphc
