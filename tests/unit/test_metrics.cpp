// sphc/metrics.h: norms, scalars, reference interpolation, comparison and the CSV/text forms.
#include "sphc/metrics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace sphc {
namespace {

TEST(Metrics, NormsOfAKnownError) {
  // values 1, 2, 3, 4 against exact 1, 1, 1, 1: errors 0, 1, 2, 3.
  NormSums s;
  for (double v : {1.0, 2.0, 3.0, 4.0}) add(s, v, 1.0);
  EXPECT_DOUBLE_EQ(norm(s, NormKind::L1, false), 6.0 / 4.0);
  EXPECT_DOUBLE_EQ(norm(s, NormKind::L2, false), std::sqrt(14.0 / 4.0));
  EXPECT_DOUBLE_EQ(norm(s, NormKind::Linf, false), 3.0);
  // Relative: divided by the same norm of the exact values (1 each).
  EXPECT_DOUBLE_EQ(norm(s, NormKind::L1, true), 6.0 / 4.0);
  EXPECT_DOUBLE_EQ(norm(s, NormKind::L2, true), std::sqrt(14.0 / 4.0));
  EXPECT_DOUBLE_EQ(norm(s, NormKind::Linf, true), 3.0);
}

TEST(Metrics, RelativeNormsDivideByTheExactNorm) {
  NormSums s;
  add(s, 2.2, 2.0);   // error 0.2
  add(s, -3.7, -4.0); // error 0.3
  EXPECT_DOUBLE_EQ(norm(s, NormKind::L1, true), 0.5 / 6.0);
  EXPECT_DOUBLE_EQ(norm(s, NormKind::L2, true), std::sqrt((0.04 + 0.09) / 20.0));
  EXPECT_NEAR(norm(s, NormKind::Linf, true), 0.3 / 4.0, 1e-15);
}

TEST(Metrics, ExactFieldGivesZeroAndEmptyGivesNaN) {
  NormSums s;
  EXPECT_TRUE(std::isnan(norm(s, NormKind::L1, false)));
  for (double v : {0.5, -1.5, 2.0}) add(s, v, v);
  EXPECT_EQ(norm(s, NormKind::L1, false), 0.0);
  EXPECT_EQ(norm(s, NormKind::Linf, true), 0.0);
  NormSums zero;
  add(zero, 1.0, 0.0);
  EXPECT_TRUE(std::isnan(norm(zero, NormKind::L1, true)));  // relative to an exact 0
  EXPECT_EQ(norm(zero, NormKind::L1, false), 1.0);
}

TEST(Metrics, NaNPropagates) {
  NormSums s;
  add(s, 1.0, 0.0);
  add(s, std::nan(""), 0.0);
  add(s, 2.0, 0.0);
  EXPECT_TRUE(std::isnan(norm(s, NormKind::Linf, false)));
  EXPECT_TRUE(std::isnan(norm(s, NormKind::L1, false)));
  ScalarSums m;
  add(m, 1.0);
  add(m, std::nan(""));
  add(m, 3.0);
  EXPECT_TRUE(std::isnan(reduce(m, ReduceKind::Max)));
  EXPECT_TRUE(std::isnan(reduce(m, ReduceKind::Min)));
}

TEST(Metrics, Scalars) {
  ScalarSums s;
  EXPECT_TRUE(std::isnan(reduce(s, ReduceKind::Sum)));
  for (double v : {3.0, -1.0, 4.0, 1.5}) add(s, v);
  EXPECT_EQ(reduce(s, ReduceKind::Max), 4.0);
  EXPECT_EQ(reduce(s, ReduceKind::Min), -1.0);
  EXPECT_EQ(reduce(s, ReduceKind::Sum), 7.5);
  EXPECT_EQ(reduce(s, ReduceKind::Mean), 7.5 / 4.0);
}

TEST(Metrics, CompensatedSum) {
  // 1 + 1e-16 * 1000 - 1: naive summation loses every 1e-16.
  ScalarSums s;
  add(s, 1.0);
  for (int k = 0; k < 1000; ++k) add(s, 1e-16);
  add(s, -1.0);
  EXPECT_NEAR(reduce(s, ReduceKind::Sum), 1e-13, 1e-25);  // naive summation: 0
  // A sum of equal masses is the mass times the count, to the last bit here.
  ScalarSums m;
  const double mass = 1000.0 * 0.01 * 0.01;
  for (int k = 0; k < 10000; ++k) add(m, mass);
  EXPECT_DOUBLE_EQ(reduce(m, ReduceKind::Sum), 10000 * mass);
}

TEST(Metrics, InterpolateInsideOnlyAndExactAtNodes) {
  ReferenceTable t{{0.0, 1.0, 3.0}, {10.0, 20.0, 0.0}};
  EXPECT_EQ(interpolate(t, 0.0), 10.0);
  EXPECT_EQ(interpolate(t, 1.0), 20.0);
  EXPECT_EQ(interpolate(t, 3.0), 0.0);
  EXPECT_DOUBLE_EQ(interpolate(t, 0.25), 12.5);
  EXPECT_DOUBLE_EQ(interpolate(t, 2.5), 5.0);
  EXPECT_TRUE(std::isnan(interpolate(t, -0.1)));
  EXPECT_TRUE(std::isnan(interpolate(t, 3.1)));
  EXPECT_TRUE(std::isnan(interpolate(ReferenceTable{}, 0.0)));
}

TEST(Metrics, Compare) {
  MetricValue a = compare(2.2, 2.0, false);
  EXPECT_NEAR(a.error, 0.2, 1e-15);
  MetricValue r = compare(2.2, 2.0, true);
  EXPECT_NEAR(r.error, 0.1, 1e-15);
  EXPECT_EQ(r.value, 2.2);
  EXPECT_EQ(r.reference, 2.0);
  EXPECT_TRUE(std::isnan(compare(1.0, kNoValue, true).error));
}

TEST(Metrics, CsvAndText) {
  std::vector<MetricInfo> infos = {{"l1", false, false, "a.sph:3"},
                                   {"front", true, true, "a.sph:4"}};
  EXPECT_EQ(metrics_csv_header(infos), "step,t,dt,wall_s,cpu_s,l1,front,front_ref,front_err");
  MetricsRow row;
  row.step = 7;
  row.t = 0.5;
  row.dt = 0.001;
  row.wall_s = 1.25;
  row.cpu_s = 2.5;
  row.values = {MetricValue{0.125}, compare(2.2, 2.0, true)};
  EXPECT_EQ(metrics_csv_row(infos, row),
            "7,0.5,0.001,1.25,2.5,0.125,2.2000000000000002,2,0.10000000000000009");
  EXPECT_EQ(metrics_text(infos, row.values), "l1=0.125 front=2.2 (ref 2, err +10.00%)");
  EXPECT_EQ(metrics_text(infos, row.values, true),
            "l1=0.125 front=2.2 front_ref=2 front_err=0.1");
  row.values = {MetricValue{}, compare(1.0, kNoValue, false)};
  EXPECT_EQ(metrics_csv_row(infos, row), "7,0.5,0.001,1.25,2.5,nan,1,nan,nan");
}

TEST(Metrics, CpuSecondsAdvance) {
  const double a = cpu_seconds();
  volatile double x = 0;
  for (int k = 0; k < 20000000; ++k) x = x + 1e-9 * k;
  EXPECT_GT(cpu_seconds(), a);
}

}  // namespace
}  // namespace sphc
