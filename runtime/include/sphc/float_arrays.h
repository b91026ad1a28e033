// sphc runtime: single-precision storage for --precision=single on the CPU backends.
//
// The host ParticleArray stays double (set-up, loading, output and the blow-up checks use
// it). A solver built with --precision=single keeps a FloatArray next to each array: a float
// copy of every double property and constant, and computes on it only (the equation and
// stepper bodies, the neighbour search, reductions), as the OpenCL backend does with its
// device buffers. upload() after set-up rounds the doubles to float; download() writes the
// floats back into the host doubles when the run loop needs them (SceneProgram::to_host),
// so every double of an output is a float value. Integer properties have no copy: they live
// in the host array, and permute() moves them together with the floats.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "sphc/particle_array.h"

namespace sphc {

struct FloatArray {
  // props[i] mirrors host property i (i * stride + k as there); empty for an integer one.
  std::vector<std::vector<float>> props;
  std::vector<std::vector<float>> constants;
  std::size_t n = 0;
  // The host indices of x, y, z and h (-1 where absent), set by upload(): the kept lists'
  // displacement checks read the float positions (sphc/verlet.h).
  int position[4] = {-1, -1, -1, -1};

  float* f(int i) { return props[i].data(); }
  const float* f(int i) const { return props[i].data(); }
  // Coordinate k (0 x, 1 y, 2 z) or h (3); nullptr where the array has none.
  const float* position_of(int k) const {
    return position[k] < 0 ? nullptr : props[position[k]].data();
  }
  float* constant(int c) { return constants[c].data(); }

  // Sizes the copies as `a` and rounds its doubles (properties and constants) to float.
  void upload(const ParticleArray& a);
  // Writes every float property and constant back into the doubles of `a` (exactly: a float
  // is a double). Throws std::invalid_argument if `a` does not have this shape.
  void download(ParticleArray& a) const;
  // Reorders the particles (as ParticleArray::permute): the floats here and the integer
  // properties of `host` (its doubles are stale until download() and are left alone).
  void permute(const std::vector<std::uint32_t>& order, ParticleArray& host);
};

}  // namespace sphc
