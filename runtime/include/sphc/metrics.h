// sphc runtime: error metrics of a scene (docs/language.md, Metrics).
//
// A scene's `metrics { }` declares quantities the solver evaluates at every output time and at
// the end, on the host (after the data of a device backend came back for the output):
//   - norms of the difference between a per-particle expression f and an exact one e,
//     accumulated in NormSums and finished by norm(): absolute L1 = sum|f - e| / N,
//     L2 = sqrt(sum (f - e)^2 / N), Linf = max|f - e|; relative: each divided by the same
//     norm of e (L1: sum|f - e| / sum|e|, L2: sqrt(sum (f - e)^2 / sum e^2),
//     Linf: max|f - e| / max|e|);
//   - scalars of an array (max, min, sum, mean of an expression) in ScalarSums, reduce();
//     compared, where the scene gives a reference (an exact expression of t, or a table
//     interpolated in t: ReferenceTable), by compare(): the error is value - reference, or
//     value / reference - 1 when relative;
//   - profiles: a norm over the rows of a table whose abscissa is a coordinate (Ghia's
//     centre lines of the cavity): the expression fitted at each row's point (ProfileFit),
//     averaged over a time window (ProfileHistory), against the row's value.
// The run loop (solver.cpp) prints them on the progress line and at the end, and writes one
// row per evaluation to a CSV file (metrics_csv_header, metrics_csv_row): the step, t, dt, the
// wall and CPU seconds of the time loop so far, then every metric.
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

namespace sphc {

constexpr double kNoValue = std::numeric_limits<double>::quiet_NaN();

enum class NormKind { L1, L2, Linf };

// The sums of one norm over particles: of the error f - e and of the exact value e.
struct NormSums {
  double err_abs = 0, err_sq = 0, err_max = 0;
  double ref_abs = 0, ref_sq = 0, ref_max = 0;
  long n = 0;
};
void add(NormSums& s, double value, double exact);
// The norm (see above); NaN without particles, or relative with an exact value that is 0
// everywhere.
double norm(const NormSums& s, NormKind kind, bool relative);

enum class ReduceKind { Max, Min, Sum, Mean };

// Max, min and a compensated (Neumaier) sum, so that a sum over particles does not depend on
// their order beyond the last bit.
struct ScalarSums {
  double max = -std::numeric_limits<double>::infinity();
  double min = std::numeric_limits<double>::infinity();
  double sum = 0, compensation = 0;
  long n = 0;
};
void add(ScalarSums& s, double v);
// NaN without particles.
double reduce(const ScalarSums& s, ReduceKind kind);

// A reference curve: values at increasing abscissae (times, usually).
struct ReferenceTable {
  std::vector<double> at, value;
};
// Linear interpolation; NaN outside [at.front(), at.back()] (a reference does not extrapolate).
double interpolate(const ReferenceTable& table, double at);

// A profile (a norm with a reference table whose abscissa is a coordinate, not t): the
// measured expression is sampled at one point per row of the table by a weighted
// least-squares fit of a linear field, value ~ a + b . (x_j - x_k), to the particles j within
// `radius` of the point x_k, weighted by the quintic spline's shape at q = 3 r / radius
// (first-order consistent: not biased next to a wall, where every neighbour lies on one
// side); the fitted a is the sample. A point with fewer than 2 (dim + 1) particles within the
// radius, or whose fit is singular, samples NaN.
struct ProfileFit {
  int dim = 2;
  double radius = 0;
  std::vector<double> px, py, pz;    // the points (unused coordinates 0)
  std::vector<std::size_t> row;      // the table row of each point
  std::vector<double> sums;          // per point: (dim+1)^2 normal matrix, dim+1 rhs, count
  ProfileFit(int dim_, double radius_) : dim(dim_), radius(radius_) {}
  void add_point(std::size_t table_row, double x, double y, double z);
  std::size_t stride() const { return static_cast<std::size_t>((dim + 1) * (dim + 2) + 1); }
};
void add(ProfileFit& f, double x, double y, double z, double value);
// The fitted value at every point.
std::vector<double> solve(const ProfileFit& f);

// The samples of a profile over the outputs of the last `window` time units: mean(t) is the
// mean of the samples of the outputs at t' >= t - window (a window of 0: the latest alone),
// which takes the acoustic oscillation of a weakly compressible steady flow out of the
// comparison. An evaluation at the time of the latest replaces it.
struct ProfileHistory {
  std::vector<double> t;
  std::vector<std::vector<double>> samples;
};
std::vector<double> average(ProfileHistory& h, double t, std::vector<double> samples,
                            double window);

// One metric as the run loop sees it.
struct MetricInfo {
  std::string name;
  bool compared = false;  // has a reference: the CSV has NAME, NAME_ref and NAME_err
  bool relative = false;  // the error of a compared scalar is value / reference - 1
  std::string where;      // its source location, file:line
};

struct MetricValue {
  double value = kNoValue;
  double reference = kNoValue;
  double error = kNoValue;
};

// A compared scalar: value - reference, or value / reference - 1 when relative.
MetricValue compare(double value, double reference, bool relative);

struct MetricsRow {
  long step = 0;
  double t = 0, dt = 0;
  double wall_s = 0, cpu_s = 0;  // of the time loop so far
  std::vector<MetricValue> values;
};

// "step,t,dt,wall_s,cpu_s,NAME[,NAME_ref,NAME_err]..." and one line per row (17 significant
// digits; NaN written as "nan").
std::string metrics_csv_header(const std::vector<MetricInfo>& infos);
std::string metrics_csv_row(const std::vector<MetricInfo>& infos, const MetricsRow& row);
// "NAME=V NAME=V (ref R, err E) ..." with 4 significant digits (the progress line), or with
// `precise` "NAME=V NAME_ref=R NAME_err=E ..." with 10 (the end-of-run line of --timing).
std::string metrics_text(const std::vector<MetricInfo>& infos,
                         const std::vector<MetricValue>& values, bool precise = false);

// CPU seconds of the process so far (all threads).
double cpu_seconds();

}  // namespace sphc
