// sphc runtime: error metrics of a scene (sphc/metrics.h).
#include "sphc/metrics.h"

#include <algorithm>
#include <cmath>
#include <ctime>

#include <fmt/format.h>

namespace sphc {

void add(NormSums& s, double value, double exact) {
  const double err = std::fabs(value - exact);
  s.err_abs += err;
  s.err_sq += err * err;
  // NaN propagates: a NaN error makes the maximum NaN.
  s.err_max = std::isnan(err) || std::isnan(s.err_max) ? kNoValue : std::max(s.err_max, err);
  const double ref = std::fabs(exact);
  s.ref_abs += ref;
  s.ref_sq += ref * ref;
  s.ref_max = std::max(s.ref_max, ref);
  ++s.n;
}

double norm(const NormSums& s, NormKind kind, bool relative) {
  if (s.n == 0) return kNoValue;
  const double n = static_cast<double>(s.n);
  double err = 0, ref = 0;
  switch (kind) {
    case NormKind::L1: err = s.err_abs / n; ref = s.ref_abs / n; break;
    case NormKind::L2: err = std::sqrt(s.err_sq / n); ref = std::sqrt(s.ref_sq / n); break;
    case NormKind::Linf: err = s.err_max; ref = s.ref_max; break;
  }
  if (!relative) return err;
  return ref > 0 ? err / ref : kNoValue;
}

void add(ScalarSums& s, double v) {
  s.max = std::isnan(v) || std::isnan(s.max) ? kNoValue : std::max(s.max, v);
  s.min = std::isnan(v) || std::isnan(s.min) ? kNoValue : std::min(s.min, v);
  // Neumaier's compensated summation.
  const double t = s.sum + v;
  if (std::fabs(s.sum) >= std::fabs(v))
    s.compensation += (s.sum - t) + v;
  else
    s.compensation += (v - t) + s.sum;
  s.sum = t;
  ++s.n;
}

double reduce(const ScalarSums& s, ReduceKind kind) {
  if (s.n == 0) return kNoValue;
  switch (kind) {
    case ReduceKind::Max: return s.max;
    case ReduceKind::Min: return s.min;
    case ReduceKind::Sum: return s.sum + s.compensation;
    case ReduceKind::Mean: return (s.sum + s.compensation) / static_cast<double>(s.n);
  }
  return kNoValue;
}

double interpolate(const ReferenceTable& table, double at) {
  const auto& x = table.at;
  if (x.empty() || std::isnan(at) || at < x.front() || at > x.back()) return kNoValue;
  auto hi = std::lower_bound(x.begin(), x.end(), at);
  const std::size_t k = static_cast<std::size_t>(hi - x.begin());
  if (x[k] == at) return table.value[k];
  const double w = (at - x[k - 1]) / (x[k] - x[k - 1]);
  return table.value[k - 1] + w * (table.value[k] - table.value[k - 1]);
}

void ProfileFit::add_point(std::size_t table_row, double x, double y, double z) {
  row.push_back(table_row);
  px.push_back(x);
  py.push_back(y);
  pz.push_back(z);
  sums.resize(sums.size() + stride(), 0.0);
}

namespace {

// The quintic spline's shape (unnormalised: a least-squares fit does not need the constant).
double quintic_shape(double q) {
  double w = 0;
  if (q < 3.0) w += std::pow(3.0 - q, 5);
  if (q < 2.0) w -= 6.0 * std::pow(2.0 - q, 5);
  if (q < 1.0) w += 15.0 * std::pow(1.0 - q, 5);
  return w;
}

}  // namespace

void add(ProfileFit& f, double x, double y, double z, double value) {
  const int n = f.dim + 1;
  const std::size_t st = f.stride();
  for (std::size_t k = 0; k < f.px.size(); ++k) {
    const double d[3] = {x - f.px[k], f.dim > 1 ? y - f.py[k] : 0.0,
                         f.dim > 2 ? z - f.pz[k] : 0.0};
    const double r = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(r < f.radius)) continue;
    const double w = quintic_shape(3.0 * r / f.radius);
    double a[4] = {1.0, d[0], d[1], d[2]};
    double* s = f.sums.data() + k * st;
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) s[i * n + j] += w * a[i] * a[j];
      s[n * n + i] += w * a[i] * value;
    }
    s[n * n + n] += 1.0;
  }
}

std::vector<double> solve(const ProfileFit& f) {
  const int n = f.dim + 1;
  const std::size_t st = f.stride();
  std::vector<double> out(f.px.size(), kNoValue);
  for (std::size_t k = 0; k < f.px.size(); ++k) {
    const double* s = f.sums.data() + k * st;
    if (s[n * n + n] < 2.0 * n) continue;  // too few particles within the radius
    // Gaussian elimination with partial pivoting on [M | b].
    double M[4][5];
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) M[i][j] = s[i * n + j];
      M[i][n] = s[n * n + i];
    }
    bool singular = false;
    for (int c = 0; c < n && !singular; ++c) {
      int p = c;
      for (int i = c + 1; i < n; ++i)
        if (std::fabs(M[i][c]) > std::fabs(M[p][c])) p = i;
      if (!(std::fabs(M[p][c]) > 1e-12 * std::fabs(M[0][0]))) {
        singular = true;
        break;
      }
      if (p != c)
        for (int j = 0; j <= n; ++j) std::swap(M[c][j], M[p][j]);
      for (int i = c + 1; i < n; ++i) {
        const double l = M[i][c] / M[c][c];
        for (int j = c; j <= n; ++j) M[i][j] -= l * M[c][j];
      }
    }
    if (singular) continue;
    double x[4] = {0, 0, 0, 0};
    for (int i = n - 1; i >= 0; --i) {
      double v = M[i][n];
      for (int j = i + 1; j < n; ++j) v -= M[i][j] * x[j];
      x[i] = v / M[i][i];
    }
    out[k] = x[0];
  }
  return out;
}

std::vector<double> average(ProfileHistory& h, double t, std::vector<double> samples,
                            double window) {
  if (!h.t.empty() && h.t.back() == t) {
    h.samples.back() = std::move(samples);
  } else {
    h.t.push_back(t);
    h.samples.push_back(std::move(samples));
  }
  // Keep the outputs within the window (a relative tolerance for output times that are sums
  // of steps).
  const double from = t - window - 1e-9 * std::max(1.0, std::fabs(t));
  std::size_t first = 0;
  while (first + 1 < h.t.size() && h.t[first] < from) ++first;
  h.t.erase(h.t.begin(), h.t.begin() + static_cast<std::ptrdiff_t>(first));
  h.samples.erase(h.samples.begin(), h.samples.begin() + static_cast<std::ptrdiff_t>(first));
  std::vector<double> mean(h.samples.back().size(), 0.0);
  for (const auto& s : h.samples)
    for (std::size_t k = 0; k < mean.size() && k < s.size(); ++k) mean[k] += s[k];
  for (double& m : mean) m /= static_cast<double>(h.samples.size());
  return mean;
}

MetricValue compare(double value, double reference, bool relative) {
  MetricValue m;
  m.value = value;
  m.reference = reference;
  m.error = relative ? value / reference - 1.0 : value - reference;
  return m;
}

namespace {

std::string number(double v, int digits) {
  if (std::isnan(v)) return "nan";
  return fmt::format("{:.{}g}", v, digits);
}

}  // namespace

std::string metrics_csv_header(const std::vector<MetricInfo>& infos) {
  std::string h = "step,t,dt,wall_s,cpu_s";
  for (const MetricInfo& m : infos) {
    h += "," + m.name;
    if (m.compared) h += "," + m.name + "_ref," + m.name + "_err";
  }
  return h;
}

std::string metrics_csv_row(const std::vector<MetricInfo>& infos, const MetricsRow& row) {
  std::string r = fmt::format("{},{},{},{},{}", row.step, number(row.t, 17), number(row.dt, 17),
                              number(row.wall_s, 6), number(row.cpu_s, 6));
  for (std::size_t k = 0; k < infos.size(); ++k) {
    const MetricValue v = k < row.values.size() ? row.values[k] : MetricValue{};
    r += "," + number(v.value, 17);
    if (infos[k].compared) r += "," + number(v.reference, 17) + "," + number(v.error, 17);
  }
  return r;
}

std::string metrics_text(const std::vector<MetricInfo>& infos,
                         const std::vector<MetricValue>& values, bool precise) {
  std::string s;
  for (std::size_t k = 0; k < infos.size() && k < values.size(); ++k) {
    const MetricInfo& m = infos[k];
    const MetricValue& v = values[k];
    if (!s.empty()) s += " ";
    if (precise) {
      s += m.name + "=" + number(v.value, 10);
      if (m.compared)
        s += " " + m.name + "_ref=" + number(v.reference, 10) + " " + m.name +
             "_err=" + number(v.error, 10);
      continue;
    }
    s += m.name + "=" + number(v.value, 4);
    if (m.compared) {
      const std::string err = std::isnan(v.error) ? "nan"
                              : m.relative ? fmt::format("{:+.2f}%", 100.0 * v.error)
                                           : fmt::format("{:+.3g}", v.error);
      s += " (ref " + number(v.reference, 4) + ", err " + err + ")";
    }
  }
  return s;
}

double cpu_seconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

}  // namespace sphc
