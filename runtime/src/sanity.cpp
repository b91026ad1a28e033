// sphc runtime: physical sanity checks of a run. See sanity.h.
#include "sphc/sanity.h"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#include <fmt/format.h>

namespace sphc {
namespace {

const char* const kAxes[3] = {"x", "y", "z"};

// The value of a quantity for one particle: a property, or speed (|(u, v, w)|, the velocity
// components the array has among the first dim).
struct Quantity {
  const double* values = nullptr;    // a property
  const double* vel[3] = {nullptr, nullptr, nullptr};
  bool speed = false;
  double operator()(std::size_t i) const {
    if (!speed) return values[i];
    double s2 = 0;
    for (const double* c : vel)
      if (c) s2 += c[i] * c[i];
    return std::sqrt(s2);
  }
};

Quantity quantity_of(const Limit& limit, const ParticleArray& a, int dim) {
  const std::string from = limit.where.empty() ? "" : " (" + limit.where + ")";
  Quantity q;
  if (limit.quantity == "speed") {
    q.speed = true;
    const char* const names[3] = {"u", "v", "w"};
    bool any = false;
    for (int k = 0; k < dim && k < 3; ++k) {
      const int idx = a.find(names[k]);
      if (idx >= 0 && a.props[idx].type == PropType::F64 && a.props[idx].stride == 1) {
        q.vel[k] = a.f64(idx);
        any = true;
      }
    }
    if (!any)
      throw std::runtime_error(fmt::format("limit '{}'{}: array '{}' has no velocity (u, v, w)",
                                           limit.name(), from, a.name));
    return q;
  }
  const int idx = a.find(limit.quantity);
  if (idx < 0)
    throw std::runtime_error(fmt::format("limit '{}'{}: array '{}' has no property '{}'",
                                         limit.name(), from, a.name, limit.quantity));
  const Property& p = a.props[idx];
  if (p.type != PropType::F64 || p.stride != 1)
    throw std::runtime_error(fmt::format(
        "limit '{}'{}: property '{}' of array '{}' is not a scalar double property",
        limit.name(), from, limit.quantity, a.name));
  q.values = a.f64(idx);
  return q;
}

std::string number(double v) { return fmt::format("{:.6g}", v); }

double parse_end(const std::string& text, const std::string& setting, double empty) {
  if (text.empty()) return empty;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || std::isnan(v))
    throw std::invalid_argument(
        fmt::format("--limit {}: '{}' is not a number", setting, text));
  return v;
}

}  // namespace

std::string Bounds::text() const {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (has_lo && has_hi) return fmt::format("[{}, {}]", number(lo), number(hi));
  if (has_hi) return "<= " + number(hi);
  if (has_lo) return ">= " + number(lo);
  return "unbounded";
}

std::vector<Limit> bounding_box_limits(const std::vector<ParticleArray*>& arrays, int dim,
                                       double warn_margin, double stop_margin) {
  double lo[3], hi[3];
  std::fill(lo, lo + 3, std::numeric_limits<double>::infinity());
  std::fill(hi, hi + 3, -std::numeric_limits<double>::infinity());
  for (const ParticleArray* a : arrays) {
    for (int k = 0; k < dim && k < 3; ++k) {
      const int idx = a->find(kAxes[k]);
      if (idx < 0 || a->props[idx].type != PropType::F64) continue;
      const double* x = a->f64(idx);
      for (std::size_t i = 0; i < a->n; ++i) {
        if (!std::isfinite(x[i])) continue;
        lo[k] = std::min(lo[k], x[i]);
        hi[k] = std::max(hi[k], x[i]);
      }
    }
  }
  double side = 0;
  for (int k = 0; k < dim && k < 3; ++k)
    if (hi[k] >= lo[k]) side = std::max(side, hi[k] - lo[k]);
  std::vector<Limit> limits;
  if (!(side > 0)) return limits;  // no extent (one particle, or none): nothing to grow
  for (const ParticleArray* a : arrays) {
    if (a->n == 0) continue;
    for (int k = 0; k < dim && k < 3; ++k) {
      if (a->find(kAxes[k]) < 0 || !(hi[k] >= lo[k])) continue;
      Limit l;
      l.array = a->name;
      l.quantity = kAxes[k];
      l.warn = Bounds{lo[k] - warn_margin * side, hi[k] + warn_margin * side};
      l.stop = Bounds{lo[k] - stop_margin * side, hi[k] + stop_margin * side};
      limits.push_back(l);
    }
  }
  return limits;
}

LimitCheck check_limit(const Limit& limit, const ParticleArray& a, int dim) {
  const Quantity q = quantity_of(limit, a, dim);
  LimitCheck c;
  double worst_warn = 0, worst_stop = 0;
  std::size_t at_warn = 0, at_stop = 0;
  // Particle i against one bound: counted if outside, kept if the furthest outside so far.
  auto against = [](const std::optional<Bounds>& b, double v, std::size_t i,
                    std::size_t& outside, double& worst, std::size_t& at) {
    if (!b) return;
    const double e = b->excess(v);
    if (e > 0 && (outside++ == 0 || e > worst)) {
      worst = e;
      at = i;
    }
  };
  for (std::size_t i = 0; i < a.n; ++i) {
    const double v = q(i);
    against(limit.warn, v, i, c.outside_warn, worst_warn, at_warn);
    against(limit.stop, v, i, c.outside_stop, worst_stop, at_stop);
  }
  if (c.outside_stop > 0) {
    c.worst = at_stop;
    c.excess = worst_stop;
  } else if (c.outside_warn > 0) {
    c.worst = at_warn;
    c.excess = worst_warn;
  }
  if (c.outside_stop + c.outside_warn > 0) c.value = q(c.worst);
  return c;
}

std::string Limit::remove_text() const {
  if (!remove) return "";
  std::string where;
  if (!remove_where.empty()) {
    const bool has_lo = std::isfinite(where_bounds.lo), has_hi = std::isfinite(where_bounds.hi);
    where = " where " + remove_where + (has_lo && has_hi ? " in " : " ") + where_bounds.text();
  }
  return "outside " + remove->text() + where;
}

std::vector<std::uint8_t> removal_mask(const Limit& limit, const ParticleArray& a, int dim) {
  std::vector<std::uint8_t> mask;
  if (!limit.remove) return mask;
  const Quantity q = quantity_of(limit, a, dim);
  const double* c = nullptr;
  if (!limit.remove_where.empty()) {
    Limit cond = limit;
    cond.quantity = limit.remove_where;
    c = quantity_of(cond, a, dim).values;
  }
  for (std::size_t i = 0; i < a.n; ++i) {
    const double v = q(i);
    if (std::isnan(v) || limit.remove->contains(v)) continue;
    if (c && !limit.where_bounds.contains(c[i])) continue;  // NaN: not contained
    if (mask.empty()) mask.assign(a.n, 0);
    mask[i] = 1;
  }
  return mask;
}

std::string describe_particle(const ParticleArray& a, std::size_t i, int dim,
                              const std::string& quantity, double value) {
  std::string pos;
  for (int k = 0; k < dim && k < 3; ++k) {
    const int idx = a.find(kAxes[k]);
    // (i < n: an array may hold no particles, e.g. on one rank of a distributed run.)
    const double x =
        idx >= 0 && i < a.n && a.props[idx].type == PropType::F64 ? a.f64(idx)[i] : 0.0;
    pos += (k ? ", " : "") + number(x);
  }
  return fmt::format("particle {} of array '{}' at ({}) has {} = {}", i, a.name, pos, quantity,
                     number(value));
}

void apply_limit_setting(std::vector<Limit>& limits, const std::string& setting) {
  const std::size_t eq = setting.find('=');
  const std::string key = setting.substr(0, eq);
  const std::size_t d2 = key.rfind('.');
  const std::size_t d1 = d2 == std::string::npos || d2 == 0 ? std::string::npos
                                                             : key.rfind('.', d2 - 1);
  if (eq == std::string::npos || d1 == std::string::npos || d1 == 0 || d2 == d1 + 1)
    throw std::invalid_argument(fmt::format(
        "--limit expects ARRAY.QUANTITY.warn=LO:HI or ARRAY.QUANTITY.stop=LO:HI (an end may "
        "be empty; 'off' removes the bound), got '{}'",
        setting));
  const std::string array = key.substr(0, d1), quantity = key.substr(d1 + 1, d2 - d1 - 1);
  const std::string kind = key.substr(d2 + 1), value = setting.substr(eq + 1);
  if (kind != "warn" && kind != "stop")
    throw std::invalid_argument(fmt::format(
        "--limit {}: expected '.warn' or '.stop' after '{}.{}', got '.{}'", setting, array,
        quantity, kind));
  std::optional<Bounds> bounds;
  if (value != "off") {
    const std::size_t colon = value.find(':');
    if (colon == std::string::npos)
      throw std::invalid_argument(fmt::format(
          "--limit {}: expected LO:HI (either may be empty) or 'off', got '{}'", setting, value));
    Bounds b;
    b.lo = parse_end(value.substr(0, colon), setting, b.lo);
    b.hi = parse_end(value.substr(colon + 1), setting, b.hi);
    if (b.lo > b.hi)
      throw std::invalid_argument(fmt::format("--limit {}: empty interval", setting));
    bounds = b;
  }
  auto it = std::find_if(limits.begin(), limits.end(), [&](const Limit& l) {
    return l.array == array && l.quantity == quantity;
  });
  if (it == limits.end()) {
    limits.push_back(Limit{array, quantity, "", std::nullopt, std::nullopt});
    it = limits.end() - 1;
  }
  (kind == "warn" ? it->warn : it->stop) = bounds;
  it->where = "--limit";
}

}  // namespace sphc
