// Checks of sphc::find_non_finite (particle_array.h) shared by the serial runtime's tests
// (test_particle_array.cpp) and the OpenMP runtime's (omp/test_omp_runtime.cpp): against a
// plain loop with std::isfinite, for bad values at block edges, in strided properties, in a
// later array, several at once, and none.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include "sphc/particle_array.h"

namespace sphc_test {

// The first non-finite value by the obvious loop.
inline std::optional<sphc::NonFiniteValue> naive_non_finite(
    const std::vector<sphc::ParticleArray*>& arrays) {
  for (std::size_t a = 0; a < arrays.size(); ++a) {
    for (std::size_t k = 0; k < arrays[a]->props.size(); ++k) {
      const sphc::Property& p = arrays[a]->props[k];
      if (p.type != sphc::PropType::F64) continue;
      for (std::size_t i = 0; i < p.f64.size(); ++i) {
        if (!std::isfinite(p.f64[i])) return sphc::NonFiniteValue{a, k, i};
      }
    }
  }
  return std::nullopt;
}

inline void expect_same_non_finite(const std::vector<sphc::ParticleArray*>& arrays) {
  const auto want = naive_non_finite(arrays);
  const auto got = sphc::find_non_finite(arrays);
  ASSERT_EQ(got.has_value(), want.has_value());
  if (!want) return;
  EXPECT_EQ(got->array, want->array);
  EXPECT_EQ(got->prop, want->prop);
  EXPECT_EQ(got->index, want->index);
}

// Two arrays, n particles each (big enough for the parallel scan when n >= ~10000): a
// scalar, an int, a 3-vector and a 9-tensor property with finite values of every kind
// (huge, tiny, subnormal, zero, negative), then bad values planted at the edges of the scan's
// blocks and at `random_places` random places, one at a time, then `random_sets` times
// three at once.
inline void check_find_non_finite(std::size_t n, int random_places = 6, int random_sets = 20) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double finite[] = {0.0, -0.0, 1.0, -3.5, std::numeric_limits<double>::max(),
                           -std::numeric_limits<double>::max(),
                           std::numeric_limits<double>::min(),
                           std::numeric_limits<double>::denorm_min()};
  sphc::ParticleArray a, b;
  a.name = "fluid";
  b.name = "solid";
  for (sphc::ParticleArray* pa : {&a, &b}) {
    pa->resize(n);
    pa->add_property("x");
    pa->add_property("tag", sphc::PropType::I32);
    pa->add_property("v", sphc::PropType::F64, 3);
    pa->add_property("L", sphc::PropType::F64, 9);
    for (sphc::Property& p : pa->props) {
      for (std::size_t i = 0; i < p.f64.size(); ++i) p.f64[i] = finite[i % 8];
    }
  }
  const std::vector<sphc::ParticleArray*> arrays = {&a, &b};
  EXPECT_FALSE(sphc::find_non_finite(arrays).has_value());
  expect_same_non_finite(arrays);
  if (n == 0) return;

  // One bad value at a time, at the edges of the 4096-value blocks and elsewhere.
  std::mt19937_64 rng(7);
  std::vector<std::size_t> places = {0, 4095, 4096, 4097, 8191};
  for (int r = 0; r < random_places; ++r) places.push_back(rng());
  for (sphc::ParticleArray* pa : {&a, &b}) {
    for (int k : {0, 2, 3}) {
      std::vector<double>& v = pa->props[k].f64;
      for (std::size_t place : places) {
        const std::size_t i = place % v.size();
        for (double bad : {nan, inf, -inf}) {
          const double keep = v[i];
          v[i] = bad;
          SCOPED_TRACE(testing::Message() << pa->name << "." << pa->props[k].name << "[" << i
                                          << "] = " << bad);
          expect_same_non_finite(arrays);
          const auto got = sphc::find_non_finite(arrays);
          ASSERT_TRUE(got.has_value());
          EXPECT_EQ(arrays[got->array], pa);
          EXPECT_EQ(got->index, i);
          v[i] = keep;
        }
      }
    }
  }
  // Several at once: the first in scan order wins, wherever the others are.
  for (int r = 0; r < random_sets; ++r) {
    std::vector<std::pair<std::vector<double>*, std::size_t>> planted;
    for (int m = 0; m < 3; ++m) {
      sphc::ParticleArray* pa = rng() % 2 ? &a : &b;
      std::vector<double>& v = pa->props[std::vector<int>{0, 2, 3}[rng() % 3]].f64;
      const std::size_t i = rng() % v.size();
      planted.push_back({&v, i});
      v[i] = m % 2 ? nan : -inf;
    }
    expect_same_non_finite(arrays);
    for (auto& [v, i] : planted) (*v)[i] = 1.0;
  }
  EXPECT_FALSE(sphc::find_non_finite(arrays).has_value());
}

}  // namespace sphc_test
