// Shared by the unit tests of the neighbour search (test_nnps.cpp) and of the neighbour lists
// kept across steps (test_verlet.cpp): a particle array of random positions and smoothing
// lengths, the same for a given seed.
#pragma once

#include <cstddef>
#include <random>

#include "sphc/particle_array.h"

namespace sphc_test {

// n particles "fluid" uniform in [0, L]^dim (other coordinates 0) with h uniform in
// [h_lo, h_hi] * h0. Per particle the draws are x, y (dim >= 2), z (dim == 3), h.
inline sphc::ParticleArray random_array(std::size_t n, int dim, double L, double h0,
                                        unsigned seed, double h_lo = 0.5, double h_hi = 1.5) {
  sphc::ParticleArray pa;
  pa.name = "fluid";
  pa.resize(n);
  for (const char* p : {"x", "y", "z", "h"}) pa.add_property(p);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> pos(0.0, L), hs(h_lo * h0, h_hi * h0);
  for (std::size_t i = 0; i < n; ++i) {
    pa.f64("x")[i] = pos(rng);
    pa.f64("y")[i] = dim >= 2 ? pos(rng) : 0.0;
    pa.f64("z")[i] = dim == 3 ? pos(rng) : 0.0;
    pa.f64("h")[i] = hs(rng);
  }
  return pa;
}

}  // namespace sphc_test
