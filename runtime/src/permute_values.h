// sphc runtime, internal: one property's values put in a new particle order, shared by
// ParticleArray::permute (particle_array.cpp) and FloatArray::permute (float_arrays.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace sphc {

// v (stride values per particle) reordered so that particle i takes the values of particle
// order[i]; scratch is the buffer it swaps with (kept, so that a caller permuting many
// properties allocates once).
template <class T>
void permute_values(std::vector<T>& v, const std::vector<std::uint32_t>& order, int stride,
                    std::vector<T>& scratch) {
  const std::size_t s = static_cast<std::size_t>(stride);
  const std::size_t n = order.size();
  scratch.resize(v.size());
  T* out = scratch.data();
  const T* in = v.data();
  const std::uint32_t* o = order.data();
  // Each i writes its own slots: parallel in the OpenMP runtime, same result.
  if (s == 1) {
#pragma omp parallel for schedule(static) if (n > 16384)
    for (std::size_t i = 0; i < n; ++i) out[i] = in[o[i]];
  } else {
#pragma omp parallel for schedule(static) if (n > 16384)
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t k = 0; k < s; ++k) out[i * s + k] = in[o[i] * s + k];
  }
  v.swap(scratch);
}

}  // namespace sphc
