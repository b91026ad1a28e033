// Unit tests of the SPH kernels (runtime/include/sphc/kernels.h).
//
// Every property is checked for each kernel in 1, 2 and 3 dimensions through AnyKernel, which
// calls the templates; one test checks that AnyKernel and the templates agree.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <random>
#include <string>
#include <vector>

#include "sphc/kernels.h"

namespace {

using sphc::AnyKernel;
using sphc::KernelKind;

std::vector<AnyKernel> all_kernels() {
  std::vector<AnyKernel> out;
  for (KernelKind k : {KernelKind::CubicSpline, KernelKind::QuinticSpline,
                       KernelKind::WendlandQuintic, KernelKind::Gaussian}) {
    for (int d = 1; d <= 3; ++d) out.push_back(AnyKernel{k, d});
  }
  return out;
}

std::string label(const AnyKernel& k) { return std::string(k.name()) + "<" + std::to_string(k.dim) + ">"; }

// The exact integral of the kernel over its support. 1 except for the Gaussian, whose
// truncation at 3h is not renormalised (see kernels.h).
double exact_mass(const AnyKernel& k) {
  if (k.kind != KernelKind::Gaussian) return 1.0;
  const double e9 = std::exp(-9.0);
  switch (k.dim) {
    case 1: return std::erf(3.0);
    case 2: return 1.0 - e9;
    default: return std::erf(3.0) - 6.0 / std::sqrt(M_PI) * e9;
  }
}

// Surface of the unit sphere in d dimensions (2 points in 1D, circumference in 2D).
double unit_sphere_surface(int d) { return d == 1 ? 2.0 : d == 2 ? 2.0 * M_PI : 4.0 * M_PI; }

TEST(Kernels, IntegratesToOne) {
  // Midpoint rule for the radial integral S_d * int_0^R r^(d-1) W(r) dr with 200000 intervals.
  // The integrands are at least C2 inside the support (the Gaussian jumps only at the end
  // point 3h, which is an interval boundary), so the error is below
  // R * dr^2 / 24 * max|g''| ~ 3 * (1.5e-5)^2 / 24 * O(10) ~ 1e-9: tolerance 1e-8.
  for (const AnyKernel& k : all_kernels()) {
    for (double h : {1.0, 0.37}) {
      SCOPED_TRACE(label(k) + " h=" + std::to_string(h));
      const double R = k.radius_scale() * h;
      const int n = 200000;
      const double dr = R / n;
      double sum = 0.0;
      for (int i = 0; i < n; ++i) {
        const double r = (i + 0.5) * dr;
        sum += std::pow(r, k.dim - 1) * k.w(r, h);
      }
      EXPECT_NEAR(unit_sphere_surface(k.dim) * sum * dr, exact_mass(k), 1e-8);
    }
  }
}

TEST(Kernels, NormalisationValuesAtZero) {
  // W(0, h=1) = sigma_d * f(0), from the formulas in kernels.h; relative 1e-14 (rounding).
  struct Case {
    KernelKind kind;
    int dim;
    double w0;
  };
  const Case cases[] = {
      {KernelKind::CubicSpline, 1, 2.0 / 3.0},
      {KernelKind::CubicSpline, 2, 10.0 / (7.0 * M_PI)},
      {KernelKind::CubicSpline, 3, 1.0 / M_PI},
      // f(0) = 3^5 - 6 * 2^5 + 15 = 66
      {KernelKind::QuinticSpline, 1, 66.0 / 120.0},
      {KernelKind::QuinticSpline, 2, 66.0 * 7.0 / (478.0 * M_PI)},
      {KernelKind::QuinticSpline, 3, 66.0 / (120.0 * M_PI)},
      {KernelKind::WendlandQuintic, 1, 5.0 / 8.0},
      {KernelKind::WendlandQuintic, 2, 7.0 / (4.0 * M_PI)},
      {KernelKind::WendlandQuintic, 3, 21.0 / (16.0 * M_PI)},
      {KernelKind::Gaussian, 1, 1.0 / std::sqrt(M_PI)},
      {KernelKind::Gaussian, 2, 1.0 / M_PI},
      {KernelKind::Gaussian, 3, std::pow(M_PI, -1.5)},
  };
  for (const Case& c : cases) {
    const AnyKernel k{c.kind, c.dim};
    SCOPED_TRACE(label(k));
    EXPECT_NEAR(k.w(0.0, 1.0), c.w0, 1e-14 * c.w0);
    // Scaling with h: W(0, h) = W(0, 1) / h^d.
    EXPECT_NEAR(k.w(0.0, 0.5), c.w0 * std::pow(2.0, c.dim), 1e-13 * c.w0);
  }
}

TEST(Kernels, GradientSumsToZeroOnLattice) {
  // sum_j grad W(x_i - x_j) dx^d over a lattice is the midpoint rule for int grad W = 0.
  // The point x_i is off the lattice so the sum is not zero by symmetry alone. The lattice
  // sum of a function whose k-th derivative jumps has an error O(dx^(k+1)); the gradients of
  // these C2 kernels have jumps in their second derivative (at r = 0 through the |x|^3 term,
  // and at the edge of the support), so the residual is O((dx/h)^3) times O(1), and O(dx)
  // for the truncated Gaussian, whose jump at 3h makes the lattice's approximation of the
  // support ball O(dx). With dx = h/32 the measured residuals (units 1/h) are at most
  // 2.3e-6 (WendlandQuintic<1>) and 5e-6 (Gaussian<1>); the others are below 3e-7.
  // Tolerance 1e-5. The same sum of W must give the (truncated) mass to 1e-6.
  const double h = 1.0, dx = h / 32.0;
  const double xi[3] = {0.31 * dx, 0.17 * dx, 0.73 * dx};
  for (const AnyKernel& k : all_kernels()) {
    SCOPED_TRACE(label(k));
    const int m = static_cast<int>(std::ceil(k.radius_scale() * h / dx)) + 1;
    const int my = k.dim >= 2 ? m : 0, mz = k.dim == 3 ? m : 0;
    double g[3] = {0, 0, 0}, wsum = 0.0;
    for (int c = -mz; c <= mz; ++c) {
      for (int b = -my; b <= my; ++b) {
        for (int a = -m; a <= m; ++a) {
          double xij[3] = {xi[0] - a * dx, k.dim >= 2 ? xi[1] - b * dx : 0.0,
                           k.dim == 3 ? xi[2] - c * dx : 0.0};
          const double r = std::sqrt(xij[0] * xij[0] + xij[1] * xij[1] + xij[2] * xij[2]);
          double gr[3];
          k.gradient(xij, r, h, gr);
          for (int d = 0; d < 3; ++d) g[d] += gr[d];
          wsum += k.w(r, h);
        }
      }
    }
    const double vol = std::pow(dx, k.dim);
    for (int d = 0; d < 3; ++d) EXPECT_NEAR(g[d] * vol * h, 0.0, 1e-5) << "component " << d;
    EXPECT_NEAR(wsum * vol, exact_mass(k), 1e-6);
  }
}

TEST(Kernels, GradientMatchesFiniteDifference) {
  // Central difference of w with step eps = 1e-5 h: truncation error eps^2 |W'''| / 6 and
  // rounding 1e-16 |W| / eps, both ~1e-10 relative, so 1e-6 relative to |grad W| is safe.
  // Points have q in [0.05, radius_scale - 0.01] so the step never straddles r = 0 or the
  // end of the support (where the truncated Gaussian jumps).
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const AnyKernel& k : all_kernels()) {
    SCOPED_TRACE(label(k));
    const double h = 0.8, eps = 1e-5 * h;
    int tested = 0;
    while (tested < 200) {
      double xij[3] = {unit(rng), k.dim >= 2 ? unit(rng) : 0.0, k.dim == 3 ? unit(rng) : 0.0};
      double r = std::sqrt(xij[0] * xij[0] + xij[1] * xij[1] + xij[2] * xij[2]);
      if (r < 1e-3) continue;
      // Scale to a random q in the allowed range.
      const double q = 0.05 + (k.radius_scale() - 0.06) * (0.5 + 0.5 * unit(rng));
      for (double& c : xij) c *= q * h / r;
      r = q * h;
      double g[3];
      k.gradient(xij, r, h, g);
      const double gnorm = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
      for (int d = 0; d < k.dim; ++d) {
        double xp[3] = {xij[0], xij[1], xij[2]}, xm[3] = {xij[0], xij[1], xij[2]};
        xp[d] += eps;
        xm[d] -= eps;
        const auto norm = [](const double* v) {
          return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        };
        const double fd = (k.w(norm(xp), h) - k.w(norm(xm), h)) / (2.0 * eps);
        EXPECT_NEAR(g[d], fd, 1e-6 * gnorm) << "q=" << q << " component " << d;
      }
      ++tested;
    }
  }
}

TEST(Kernels, DwdqConsistentWithGradientAndW) {
  // grad W = dwdq / (h r) * xij (exact up to rounding: 1e-14 relative), and dwdq is h times
  // the r-derivative of w (central difference, same error budget as above: 1e-6).
  for (const AnyKernel& k : all_kernels()) {
    SCOPED_TRACE(label(k));
    const double h = 1.3;
    for (double q = 0.05; q < k.radius_scale() - 0.01; q += 0.037) {
      const double r = q * h;
      // |xij| = r in every dimension.
      const double xij[3] = {k.dim >= 2 ? 0.6 * r : r, k.dim >= 2 ? -0.8 * r : 0.0, 0.0};
      double g[3];
      k.gradient(xij, r, h, g);
      const double dq = k.dwdq(r, h);
      for (int d = 0; d < 3; ++d) {
        EXPECT_NEAR(g[d], dq / (h * r) * xij[d], 1e-14 * std::fabs(dq) / h);
      }
      const double eps = 1e-5 * h;
      const double fd = (k.w(r + eps, h) - k.w(r - eps, h)) / (2.0 * eps) * h;
      EXPECT_NEAR(k.dwdq(r, h), fd, 1e-6 * std::fabs(fd) + 1e-12 * k.w(0.0, h)) << "q=" << q;
    }
  }
}

TEST(Kernels, SymmetryAndAntisymmetry) {
  // W depends on |xij| only and grad W(-xij) = -grad W(xij): exact (same floating operations
  // on negated inputs).
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const AnyKernel& k : all_kernels()) {
    SCOPED_TRACE(label(k));
    for (int t = 0; t < 100; ++t) {
      const double xij[3] = {unit(rng), unit(rng), unit(rng)};
      const double xji[3] = {-xij[0], -xij[1], -xij[2]};
      const double r = std::sqrt(xij[0] * xij[0] + xij[1] * xij[1] + xij[2] * xij[2]);
      const double rji = std::sqrt(xji[0] * xji[0] + xji[1] * xji[1] + xji[2] * xji[2]);
      EXPECT_EQ(r, rji);
      EXPECT_EQ(k.w(r, 0.6), k.w(rji, 0.6));
      double gi[3], gj[3];
      k.gradient(xij, r, 0.6, gi);
      k.gradient(xji, rji, 0.6, gj);
      for (int d = 0; d < 3; ++d) EXPECT_EQ(gi[d], -gj[d]);
    }
  }
}

TEST(Kernels, ZeroBeyondSupportAndGradientZeroAtOrigin) {
  for (const AnyKernel& k : all_kernels()) {
    SCOPED_TRACE(label(k));
    const double h = 0.9, R = k.radius_scale() * h;
    for (double r : {R * (1.0 + 1e-12), R + 0.1, 10.0 * R, 1e300}) {
      EXPECT_EQ(k.w(r, h), 0.0) << "r=" << r;
      EXPECT_EQ(k.dwdq(r, h), 0.0) << "r=" << r;
      const double xij[3] = {r, 0.0, 0.0};
      double g[3];
      k.gradient(xij, r, h, g);
      EXPECT_EQ(g[0], 0.0);
      EXPECT_EQ(g[1], 0.0);
      EXPECT_EQ(g[2], 0.0);
    }
    // Inside the support W > 0 (all these kernels are positive).
    EXPECT_GT(k.w(0.999 * R, h), 0.0);
    // At (and below 1e-12 of) the origin the gradient is exactly zero, never NaN.
    for (double r : {0.0, 1e-13}) {
      const double xij[3] = {r, 0.0, 0.0};
      double g[3] = {1, 1, 1};
      k.gradient(xij, r, h, g);
      EXPECT_EQ(g[0], 0.0);
      EXPECT_EQ(g[1], 0.0);
      EXPECT_EQ(g[2], 0.0);
    }
  }
}

TEST(Kernels, TemplatesAndAnyKernelAgree) {
  static_assert(sphc::CubicSpline<2>::radius_scale == 2.0, "");
  static_assert(sphc::QuinticSpline<3>::radius_scale == 3.0, "");
  static_assert(sphc::WendlandQuintic<1>::radius_scale == 2.0, "");
  static_assert(sphc::Gaussian<2>::radius_scale == 3.0, "");
  EXPECT_STREQ(sphc::WendlandQuintic<3>::name, "WendlandQuintic");
  const AnyKernel k{KernelKind::QuinticSpline, 3};
  EXPECT_EQ(k.w(0.7, 0.5), sphc::QuinticSpline<3>::w(0.7, 0.5));
  EXPECT_EQ(k.dwdq(0.7, 0.5), sphc::QuinticSpline<3>::dwdq(0.7, 0.5));
  EXPECT_EQ(k.radius_scale(), 3.0);
  const double xij[3] = {0.3, -0.2, 0.1};
  const double r = std::sqrt(0.14);
  double a[3], b[3];
  k.gradient(xij, r, 0.5, a);
  sphc::QuinticSpline<3>::gradient(xij, r, 0.5, b);
  for (int d = 0; d < 3; ++d) EXPECT_EQ(a[d], b[d]);
}

TEST(Kernels, NamesAndErrors) {
  for (KernelKind kind : {KernelKind::CubicSpline, KernelKind::QuinticSpline,
                          KernelKind::WendlandQuintic, KernelKind::Gaussian}) {
    KernelKind parsed{};
    ASSERT_TRUE(sphc::parse_kernel_kind(sphc::kernel_name(kind), parsed));
    EXPECT_EQ(parsed, kind);
  }
  KernelKind parsed{};
  EXPECT_FALSE(sphc::parse_kernel_kind("Cubic", parsed));
  EXPECT_THROW((AnyKernel{KernelKind::Gaussian, 4}.w(0.1, 1.0)), std::invalid_argument);
  EXPECT_THROW((AnyKernel{KernelKind::Gaussian, 0}.radius_scale()), std::invalid_argument);
}

// --precision=single: the kernels called with floats compute in float (the result type is
// float) and agree with the double kernel within float rounding: a few operations, each
// rounding by at most u = 2^-24, so 16 u of the kernel's value at 0 is ample; the gradient
// likewise relative to its largest value on the sampled range. The quintic spline's three
// fifth powers (3^5 = 243, 6 * 2^5 = 192, 15) cancel to f(0) = 66 and f'(0) = 0, so its
// rounding is relative to terms ~16 times its result: cancel = 16 there.
template <class K>
void expect_float_close(double cancel = 1.0) {
  static_assert(std::is_same_v<decltype(K::w(0.5f, 1.0f)), float>);
  const double u = std::ldexp(1.0, -24);
  const double w0 = K::w(0.0, 1.0);
  double gmax = 0.0;
  for (int k = 1; k < 400; ++k) {
    const double x[3] = {k * 0.0075, 0.0, 0.0};
    double g[3];
    K::gradient(x, x[0], 1.0, g);
    gmax = std::max(gmax, std::fabs(g[0]));
  }
  for (int k = 0; k < 400; ++k) {
    const float r = static_cast<float>(k * 0.0075);
    EXPECT_NEAR(K::w(r, 1.0f), K::w(static_cast<double>(r), 1.0), 16 * cancel * u * w0) << K::name << " r=" << r;
    const float xf[3] = {r, 0.0f, 0.0f};
    const double xd[3] = {r, 0.0, 0.0};
    float gf[3];
    double gd[3];
    K::gradient(xf, r, 1.0f, gf);
    K::gradient(xd, static_cast<double>(r), 1.0, gd);
    EXPECT_NEAR(gf[0], gd[0], 16 * cancel * u * gmax) << K::name << " r=" << r;
  }
}

TEST(Kernels, FloatCallsComputeInFloatAndAgree) {
  expect_float_close<sphc::CubicSpline<2>>();
  expect_float_close<sphc::QuinticSpline<3>>(16.0);
  expect_float_close<sphc::WendlandQuintic<2>>();
  expect_float_close<sphc::WendlandQuintic<1>>();
  expect_float_close<sphc::Gaussian<3>>();
}

}  // namespace
